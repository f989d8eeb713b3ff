#include "railcrash/model/yaml_file.hpp"

#include <yaml-cpp/eventhandler.h>

#include <filesystem>
#include <fstream>
#include <algorithm>
#include <map>
#include <set>
#include <sstream>
#include <vector>

namespace railcrash {

namespace {

/// Walks the parser's events once (aliases are not followed) and counts what the document
/// becomes once every alias is expanded: the size of an anchored node is known when it ends,
/// so an alias adds that size without being walked again.
class StructureCheck : public YAML::EventHandler {
 public:
  /// `limit`: the most values the document may expand to.
  StructureCheck(const std::string& path, std::size_t limit) : path_(path), limit_(limit) {}

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t anchor) override { leaf(mark, anchor); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor, const std::string&) override {
    leaf(mark, anchor);
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    for (const Open& open : open_)
      if (open.anchor == anchor)
        fail(mark, "an alias refers to the node that contains it (a cycle through an anchor opened at line " +
                       std::to_string(open.line) + "); replace the alias by the values it stands for");
    const auto size = anchored_size_.find(anchor);
    add(mark, size == anchored_size_.end() ? 1 : size->second);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor, YAML::EmitterStyle::value) override {
    open(mark, anchor);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor, YAML::EmitterStyle::value) override {
    open(mark, anchor);
  }
  void OnMapEnd() override { close(); }

 private:
  struct Open {
    YAML::anchor_t anchor;
    int line;            // 1-based
    std::size_t nodes;   // expanded nodes inside, itself included
  };

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& message) const {
    throw InputError(SourceLocation{path_, mark.is_null() ? 0 : mark.line + 1}.prefix() + message);
  }
  void add(const YAML::Mark& mark, std::size_t nodes) {
    if (!open_.empty()) open_.back().nodes += nodes;
    expanded_ += nodes;
    if (expanded_ > limit_)
      fail(mark, "the document expands to more than " + std::to_string(limit_) +
                     " values once its aliases (*name) are replaced by what they refer to; a model needs far fewer: "
                     "remove the aliases that repeat other aliases");
  }
  void leaf(const YAML::Mark& mark, YAML::anchor_t anchor) {
    // yaml-cpp 0.7 meets a ',' at the start of a block document (",x") with empty values at
    // the same place, without end: a parser that stays put is stopped here.
    leaves_at_same_place_ = mark.pos == last_leaf_pos_ ? leaves_at_same_place_ + 1 : 0;
    last_leaf_pos_ = mark.pos;
    if (leaves_at_same_place_ > kMaxLeavesAtSamePlace)
      fail(mark, "not valid YAML: the parser makes no progress here (a ',' outside [ ] or { }?); check this line");
    if (anchor != YAML::NullAnchor) anchored_size_[anchor] = 1;
    add(mark, 1);
  }
  void open(const YAML::Mark& mark, YAML::anchor_t anchor) {
    if (open_.size() >= kYamlMaxDepth)
      fail(mark, "lists and maps are nested more than " + std::to_string(kYamlMaxDepth) +
                     " deep; a model needs far fewer levels: check the brackets");
    add(mark, 1);
    open_.push_back({anchor, mark.line + 1, 1});
  }
  void close() {
    const Open done = open_.back();
    open_.pop_back();
    if (done.anchor != YAML::NullAnchor) anchored_size_[done.anchor] = done.nodes;
    if (!open_.empty()) open_.back().nodes += done.nodes - 1;  // the 1 for the node itself was added at its start
  }

  const std::string& path_;
  std::vector<Open> open_;
  std::map<YAML::anchor_t, std::size_t> anchored_size_;
  const std::size_t limit_;
  std::size_t expanded_ = 0;
  static constexpr int kMaxLeavesAtSamePlace = 1000;  // a valid document has a few (empty values)
  int last_leaf_pos_ = -1;
  int leaves_at_same_place_ = 0;
};

}  // namespace

void check_yaml_structure(const std::string& text, const std::string& path) {
  std::istringstream stream(text);
  YAML::Parser parser(stream);
  // A value takes at least one byte of text, so a file without aliases never reaches the limit.
  StructureCheck check(path, kYamlMaxAliasedNodes + text.size());
  while (parser.HandleNextDocument(check)) {
  }
}

YAML::Node load_yaml_text(const std::string& text, const std::string& path) {
  check_yaml_structure(text, path);
  return YAML::Load(text);
}

std::string read_input_file(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  // A folder or a device (/dev/zero never ends) is not a file to read; a pipe is (<(command)).
  if (fs::exists(status) && !fs::is_regular_file(status) && !fs::is_fifo(status))
    throw InputError(path + ": the " + what + " is a " + (fs::is_directory(status) ? "folder" : "device or socket") +
                     ", not a file; give the path of a YAML file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the " + what + " (check the path)");
  std::string text;
  char block[65536];
  while (in.read(block, sizeof block) || in.gcount() > 0) {
    text.append(block, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kYamlMaxFileBytes)
      throw InputError(path + ": the " + what + " is larger than " + std::to_string(kYamlMaxFileBytes >> 20) +
                       " MiB; a model is far smaller: check that this is the right file");
  }
  return text;
}

YAML::Node load_yaml_file(const std::string& path, const std::string& what) {
  const std::string text = read_input_file(path, what);
  try {
    return load_yaml_text(text, path);
  } catch (const YAML::ParserException& e) {
    throw InputError(SourceLocation{path, e.mark.is_null() ? 0 : e.mark.line + 1}.prefix() + "not valid YAML: " + e.msg);
  }
}

namespace {

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> previous(b.size() + 1), current(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) previous[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(previous, current);
  }
  return previous[b.size()];
}

}  // namespace

std::string suggestion(const std::string& word, const std::vector<std::string>& known) {
  std::string best;
  std::size_t best_distance = 3;
  for (const auto& k : known) {
    const std::size_t d = edit_distance(word, k);
    if (d < best_distance) { best_distance = d; best = k; }
  }
  return best.empty() ? "" : " (did you mean '" + best + "'?)";
}

std::string join_words(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

std::optional<YamlKeyProblem> yaml_keys_problem(const YAML::Node& map, const std::vector<std::string>& allowed,
                                                const std::string& context) {
  const std::string prefix = context.empty() ? "" : context + ": ";
  std::set<std::string> seen;
  for (const auto& entry : map) {
    if (!entry.first.IsScalar()) return YamlKeyProblem{entry.first, prefix + "keys must be plain words; allowed keys: " + join_words(allowed)};
    const std::string key = entry.first.Scalar();
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
      return YamlKeyProblem{entry.first, prefix + "unknown key '" + key + "'" + suggestion(key, allowed) + "; allowed keys: " + join_words(allowed)};
    if (!seen.insert(key).second) return YamlKeyProblem{entry.first, prefix + "key '" + key + "' is given twice; keep only one"};
  }
  return std::nullopt;
}

void check_yaml_keys(const std::string& path, const YAML::Node& map, const std::vector<std::string>& allowed, const std::string& context) {
  if (const auto problem = yaml_keys_problem(map, allowed, context)) yaml_error(path, problem->where, problem->message);
}

}  // namespace railcrash
