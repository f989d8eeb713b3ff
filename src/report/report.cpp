// The HTML run report (see the header): reads the run folder, filters and decimates the
// series, and fills the page template with the data as JSON.
#include "railcrash/report/report.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "railcrash/core/error.hpp"
#include "railcrash/core/table_text.hpp"
#include "railcrash/core/whole_file.hpp"
#include "railcrash/report/assets.hpp"
#include "railcrash/report/decimate.hpp"
#include "railcrash/report/folder_file.hpp"
#include "railcrash/report/pdf.hpp"
#include "railcrash/results/cfc_filter.hpp"
#include "railcrash/results/hdf5_file.hpp"
#include "railcrash/results/provenance.hpp"
#include "railcrash/results/results.hpp"

namespace railcrash::report {

namespace {

namespace fs = std::filesystem;

/// Text safe inside <script type="application/json">: no "<" (so no "</script>"), valid UTF-8.
std::string script_safe(const std::string& json) {
  std::string out;
  for (const char c : valid_utf8(json)) {
    if (c == '<') out += "\\u003c";
    else out += c;
  }
  return out;
}

std::string js(const std::string& text) { return json_string(text); }

std::string number(double value) {
  if (!std::isfinite(value)) return "null";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

std::string numbers(const std::vector<double>& values) {
  std::string out = "[";
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (k) out += ',';
    out += number(values[k]);
  }
  return out + "]";
}

/// What to do about a file above the report's limit (folder_file.hpp), by its kind.
const char* const kJsonAdvice =
    "railcrash writes such files well under that; it is not a file of a railcrash run: move it away, or run the model "
    "again into this folder";
const char* const kTableAdvice =
    "the report holds the file and its values in memory, and the limit is an eighth of this machine's memory; run again "
    "with a longer --output-interval (fewer rows), or read the file with other tools";

/// A JSON file of the folder (summary.json, model.json), size-limited; found false when there is none.
std::string read_json_file(const fs::path& path, bool* found) {
  FolderFile file = read_folder_file(path.string(), kMaxJsonBytes, kJsonAdvice);
  *found = file.found;
  return std::move(file.text);
}

/// A table or other file of the folder (CSV, Markdown, SVG), size-limited.
std::string read_file(const fs::path& path, bool* found) {
  FolderFile file = read_folder_file(path.string(), max_table_bytes(), kTableAdvice);
  *found = file.found;
  return std::move(file.text);
}

/// A JSON text parsed with nlohmann::json, which parses without recursion (the std::regex
/// matching it replaces recursed once per character and overflowed the stack on a
/// 100,000-character message, issue 36). Empty text: null. Text that is not JSON: null, and a
/// problem saying where it breaks.
nlohmann::json parse_json(const std::string& name, const std::string& text, std::vector<std::string>& problems) {
  if (text.empty()) return nullptr;
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    std::string reason = e.what();  // "[json.exception.parse_error.101] parse error at line 3, column 7: ..."
    const std::size_t tag_end = reason.find("] ");
    if (reason.rfind("[json.exception.", 0) == 0 && tag_end != std::string::npos) reason = reason.substr(tag_end + 2);
    problems.push_back(name + " is not valid JSON (" + reason.substr(0, 300) + "): the report shows what the other files hold");
    return nullptr;
  }
}

/// The string at key of a JSON object, "" when it is missing or not a string.
std::string string_at(const nlohmann::json& object, const char* key) {
  if (!object.is_object()) return "";
  const auto it = object.find(key);
  return it != object.end() && it->is_string() ? it->get<std::string>() : "";
}

/// The lines of a text, as std::getline reads them from a stream.
class Lines {
 public:
  explicit Lines(const std::string& text) : text_(text) {}
  /// The next line without its '\n'; false at the end. ended: whether a '\n' ended it.
  bool next(std::string& line, bool* ended = nullptr) {
    if (at_ >= text_.size()) return false;
    const std::size_t end = text_.find('\n', at_);
    const std::size_t stop = end == std::string::npos ? text_.size() : end;
    line.assign(text_, at_, stop - at_);
    at_ = end == std::string::npos ? text_.size() : end + 1;
    if (ended) *ended = end != std::string::npos;
    return true;
  }
  bool at_end() const { return at_ >= text_.size(); }

 private:
  const std::string& text_;
  std::size_t at_ = 0;
};


/// A numeric CSV file: header and complete rows; stops at the first broken row.
struct NumericTable {
  bool found = false;
  std::vector<std::string> columns;
  std::map<std::string, int> index;  // column by name
  std::vector<std::vector<double>> data;  // per column
  std::size_t rows = 0;
  std::string comment;  // the "# railcrash provenance {...}" line before the header ("" in older files)
};

/// Reads the lines before a CSV file's header that start with '#' (the provenance line,
/// results/provenance.hpp) into `comment`, and the header into `line`; false at the end of the file.
bool header_line(Lines& in, std::string& line, std::string& comment, std::size_t& line_number) {
  while (in.next(line)) {
    ++line_number;
    if (line.empty() || line[0] != '#') return true;
    if (comment.empty()) comment = line;
  }
  return false;
}

NumericTable read_numeric_csv(const fs::path& path, std::vector<std::string>& problems) {
  NumericTable table;
  const std::string text = read_file(path, &table.found);
  if (!table.found) return table;
  Lines in(text);
  std::string line;
  std::size_t line_number = 0;
  if (!header_line(in, line, table.comment, line_number)) return table;
  table.columns = csv_fields(line);
  for (std::size_t k = 0; k < table.columns.size(); ++k) table.index.emplace(table.columns[k], static_cast<int>(k));
  table.data.assign(table.columns.size(), {});
  bool ends_with_newline = false;  // the line stopped at a newline, not at the end
  while (in.next(line, &ends_with_newline)) {
    ++line_number;
    const bool last_line = !ends_with_newline || in.at_end();
    std::vector<double> row;
    std::string reason;
    const std::vector<std::string> fields = csv_fields(line);
    if (fields.size() != table.columns.size())
      reason = std::to_string(fields.size()) + " fields, the header has " + std::to_string(table.columns.size());
    for (std::size_t k = 0; reason.empty() && k < fields.size(); ++k) {
      char* end = nullptr;
      const double value = std::strtod(fields[k].c_str(), &end);
      if (fields[k].empty() || end == fields[k].c_str() || *end != '\0') reason = "'" + fields[k].substr(0, 20) + "' is not a number";
      row.push_back(value);
    }
    if (reason.empty() && last_line && !ends_with_newline && !line.empty()) reason = "the row has no end of line";
    if (!reason.empty()) {
      if (line.empty() && last_line) break;
      problems.push_back(path.filename().string() + " line " + std::to_string(line_number) + ": " + reason +
                         (last_line ? " (the file ends mid-row: the run was stopped or is still writing)" : "") +
                         "; the report uses the " + std::to_string(table.rows) + " complete rows before it");
      break;
    }
    for (std::size_t k = 0; k < row.size(); ++k) table.data[k].push_back(row[k]);
    ++table.rows;
  }
  return table;
}

/// Throws InputError when the run folder's files are not all of one run: the run id of
/// summary.json (if there is one) and of every data file the report reads (timeseries.csv's
/// provenance line or timeseries.h5's run_id attribute, model.json's "run_id", accelerations.csv's,
/// energy.csv's, events.csv's) must be the same; files without an id (an older railcrash) agree
/// only with each other.
void require_one_run(const fs::path& dir, const std::string& summary, bool summary_found, const std::string& timeseries_file,
                     const std::string& timeseries_run_id) {
  struct FileRun {
    std::string name, id;  // id "": the file carries none
  };
  std::vector<FileRun> files;
  if (summary_found) files.push_back({"summary.json", run_id_in(summary).value_or("")});
  files.push_back({timeseries_file, timeseries_run_id});
  for (const char* name : {"model.json", "accelerations.csv", "energy.csv", "events.csv"}) {
    // The id is near the top: model.json's third line, a CSV file's first.
    const FolderFile file = read_folder_file_head((dir / name).string(), 4096);
    if (!file.found) continue;
    const std::string& head = file.text;
    const bool csv = std::string(name).find(".csv") != std::string::npos;
    const std::string first_line = head.substr(0, head.find('\n'));
    files.push_back({name, run_id_in(csv ? (first_line.rfind("#", 0) == 0 ? first_line : std::string()) : head).value_or("")});
  }
  const FileRun& reference = files.front();
  const auto of_run = [](const std::string& id) { return id.empty() ? std::string("of no run id (written by an older railcrash)") : "of run " + id; };
  for (const FileRun& file : files)
    if (file.id != reference.id)
      throw InputError("'" + (dir / file.name).string() + "' is " + of_run(file.id) + " but '" + (dir / reference.name).string() +
                       "' is " + of_run(reference.id) + ": the folder holds the files of two runs, and the report would show "
                       "one run's results under the other's; run the model again into this folder (a run removes the files of "
                       "an earlier one) or into an empty folder");
}

/// A table of timeseries.h5 (results/hdf5_file.hpp) as the report holds a CSV file's.
NumericTable numeric_table(Hdf5Table&& read) {
  NumericTable table;
  table.found = read.found;
  table.columns = std::move(read.columns);
  for (std::size_t k = 0; k < table.columns.size(); ++k) table.index.emplace(table.columns[k], static_cast<int>(k));
  table.data = std::move(read.values);
  table.rows = read.rows;
  return table;
}

/// One row of events.csv or of timeseries.h5's events.
struct EventRow {
  double t = 0.0;  // [time]
  std::string element, event;
  double value = 0.0;
};

constexpr std::size_t kMaxEvents = 20000;  // shown in the page's event log

/// The rows of events.csv (t, element, event, value), at most kMaxEvents.
std::vector<EventRow> read_events_csv(const fs::path& path, bool* found) {
  std::vector<EventRow> rows;
  const std::string text = read_file(path, found);
  Lines in(text);
  std::string line, comment;
  std::size_t line_number = 0;
  header_line(in, line, comment, line_number);
  while (rows.size() < kMaxEvents && in.next(line)) {
    const std::vector<std::string> f = csv_fields(line);
    if (f.size() != 4) continue;
    rows.push_back({std::strtod(f[0].c_str(), nullptr), f[1], f[2], std::strtod(f[3].c_str(), nullptr)});
  }
  return rows;
}

int column_of(const NumericTable& table, const std::string& name) {
  const auto it = table.index.find(name);
  return it == table.index.end() ? -1 : it->second;
}

/// The elements of model.json (written by run_files.cpp), each an object with its name and type.
std::vector<const nlohmann::json*> model_elements(const nlohmann::json& model) {
  std::vector<const nlohmann::json*> out;
  if (!model.is_object()) return out;
  const auto elements = model.find("elements");
  if (elements == model.end() || !elements->is_array()) return out;
  for (const nlohmann::json& element : *elements)
    if (!string_at(element, "name").empty() && !string_at(element, "type").empty()) out.push_back(&element);
  return out;
}

/// Element names and types from model.json.
std::vector<std::pair<std::string, std::string>> element_types(const nlohmann::json& model) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const nlohmann::json* element : model_elements(model)) out.emplace_back(string_at(*element, "name"), string_at(*element, "type"));
  return out;
}

/// The number at object[outer][inner], if there is one.
std::optional<double> number_at(const nlohmann::json& object, const char* outer, const char* inner) {
  if (!object.is_object()) return std::nullopt;
  const auto a = object.find(outer);
  if (a == object.end() || !a->is_object()) return std::nullopt;
  const auto b = a->find(inner);
  if (b == a->end() || !b->is_number()) return std::nullopt;
  return b->get<double>();
}

/// The standard gravity of model.json's units, else of summary.json's peak accelerations, else 0.
double standard_gravity_of(const nlohmann::json& model, const nlohmann::json& summary) {
  if (const auto g = number_at(model, "units", "standard_gravity")) return *g;
  return number_at(summary, "peak_accelerations", "standard_gravity").value_or(0.0);
}

/// Roles of the element outputs from model.json: element name -> role name -> output
/// (element.hpp OutputRole).
std::map<std::string, std::map<std::string, std::string>> element_roles(const nlohmann::json& model) {
  std::map<std::string, std::map<std::string, std::string>> out;
  for (const nlohmann::json* element : model_elements(model)) {
    const auto roles = element->find("roles");
    if (roles == element->end() || !roles->is_object()) continue;
    for (const auto& [role, output] : roles->items())
      if (output.is_string()) out[string_at(*element, "name")][role] = output.get<std::string>();
  }
  return out;
}

struct PlotSeries {
  std::string name;
  std::vector<double> values;
  bool show = true;
};

/// The element forces of the report's force plot, filtered at a channel frequency class.
struct FilteredForces {
  std::vector<double> t;            // [s] uniform when filtered, else the rows' times
  std::vector<PlotSeries> series;
  std::string filter_name;          // "CFC 60" or "unfiltered"
  std::string note;
};

/// Resamples every force series to the rows' typical interval and filters it at class `cfc`
/// (SAE J211-1 / ISO 6487, two passes, as the accelerations); cfc 0 or too coarse rows leave
/// them unfiltered (the latter with a problem saying why).
FilteredForces filter_forces(const std::vector<double>& t, const std::vector<PlotSeries>& forces, double cfc,
                             std::vector<std::string>& problems) {
  FilteredForces out{t, forces, "unfiltered", ""};
  if (cfc <= 0.0 || t.size() < 3) return out;
  const double interval = cfc::typical_interval(t);
  if (!(interval > 0.0 && cfc::design_frequency(cfc) * interval < 0.5)) {
    problems.push_back("the output interval " + number(interval) + " s is too long for CFC " + number(cfc) +
                       ": the force plot is unfiltered (run with --output-interval below " + number(0.1 / cfc) +
                       " s, or give the report --force-cfc 0)");
    return out;
  }
  const std::vector<double> index(t.begin(), t.end());
  out.t = cfc::resample_uniform(t, index, interval);
  for (PlotSeries& s : out.series) s.values = cfc::filter(cfc::resample_uniform(t, s.values, interval), interval, cfc);
  out.filter_name = "CFC " + number(cfc);
  char zone_ms[32];
  std::snprintf(zone_ms, sizeof zone_ms, "%.2g", 1e3 * cfc::end_zone(cfc));
  out.note = "forces filtered at CFC " + number(cfc) + " (report --force-cfc; 0: unfiltered); the loops below are unfiltered; the last " +
             zone_ms + " ms follow the record's last row";
  return out;
}

std::string plot_json(const std::string& id, const std::string& title, const std::string& y_label, const std::vector<double>& t,
                      const std::vector<PlotSeries>& series, std::size_t max_points, const std::string& note = "") {
  std::vector<std::vector<double>> values;
  for (const PlotSeries& s : series) values.push_back(s.values);
  const Decimated d = decimate_minmax(t, values, max_points);
  std::string out = "{\"id\": " + js(id) + ", \"title\": " + js(title) + ", \"y_label\": " + js(y_label) +
                    ", \"note\": " + js(note) + ", \"decimated\": " + (d.x.size() < t.size() ? "true" : "false") +
                    ", \"t\": " + numbers(d.x) + ", \"series\": [";
  for (std::size_t k = 0; k < series.size(); ++k)
    out += std::string(k ? ", " : "") + "{\"name\": " + js(series[k].name) + ", \"show\": " + (series[k].show ? "true" : "false") +
           ", \"values\": " + numbers(d.series[k]) + "}";
  return out + "]}";
}

std::string joined(const char* const* chunks) {
  std::string out;
  for (const char* const* c = chunks; *c; ++c) out += *c;
  return out;
}

void replace_all(std::string& text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) text.replace(at, from.size(), to);
}

/// Replaces the next placeholder `key` after `cursor` by `value` and moves the cursor past it,
/// so that text inserted earlier is never searched for placeholders.
void fill(std::string& page, std::size_t& cursor, const std::string& key, const std::string& value) {
  const std::size_t at = page.find(key, cursor);
  if (at == std::string::npos) throw std::logic_error("report template lacks " + key);
  page.replace(at, key.size(), value);
  cursor = at + value.size();
}

std::string base64(const std::string& bytes) {
  static const char* const kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const unsigned a = static_cast<unsigned char>(bytes[i]);
    const unsigned b = i + 1 < bytes.size() ? static_cast<unsigned char>(bytes[i + 1]) : 0u;
    const unsigned c = i + 2 < bytes.size() ? static_cast<unsigned char>(bytes[i + 2]) : 0u;
    const unsigned triple = (a << 16) | (b << 8) | c;
    out += kDigits[(triple >> 18) & 63];
    out += kDigits[(triple >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(triple >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[triple & 63] : '=';
  }
  return out;
}

std::string html_text(const std::string& text) {
  std::string out;
  for (char c : valid_utf8(text)) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else out += c;
  }
  return out;
}

/// Writes DIR/report.html: the template filled with the title, the JSON blocks (summary.json,
/// model.json and the report's data, made safe for a script element) and the inlined script,
/// style and library. Placeholders are filled in page order, each once, so that nothing
/// inserted is searched again. Returns the path.
std::string write_page(const fs::path& dir, const std::string& title, const std::string& summary, const std::string& model,
                       const std::string& data, const std::string& file_name = "report.html") {
  std::string page = joined(assets::kTemplate);
  std::string library = joined(assets::kLibraryScript);
  replace_all(library, "</script", "<\\/script");
  std::string script = joined(assets::kScript);
  replace_all(script, "</script", "<\\/script");
  std::size_t cursor = 0;
  fill(page, cursor, "{{TITLE}}", html_text(title));
  fill(page, cursor, "{{LIBRARY_STYLE}}", joined(assets::kLibraryStyle));
  fill(page, cursor, "{{STYLE}}", joined(assets::kStyle));
  fill(page, cursor, "{{SUMMARY}}", script_safe(summary));
  fill(page, cursor, "{{MODEL}}", script_safe(model));
  fill(page, cursor, "{{DATA}}", script_safe(data));
  fill(page, cursor, "{{LIBRARY_SCRIPT}}", library);
  fill(page, cursor, "{{SCRIPT}}", script);
  // Whole or not at all, never through a link or into a FIFO named report.html (whole_file.hpp).
  const std::string path = (dir / file_name).string();
  write_whole_file(path, page);
  return path;
}

/// Files of a `converge`, `readings`, `sensitivity` or `sweep` folder, in the order shown.
const char* const kStudyFiles[] = {"converge.md", "converge.csv", "readings.md", "readings.csv", "sensitivity.md", "comparison.md",
                                   "sensitivity.csv", "sensitivity_first_order.csv", "sensitivity_second_order.csv",
                                   "sensitivity_derivatives.csv", "sensitivity_ranking.csv", "sensitivity_branches.csv", "summary.md", "runs.csv"};

/// A report of a study folder: its Markdown summary, its tables and its chart.
ReportResult write_study_report(const fs::path& dir) {
  ReportResult result;
  const bool converge = fs::exists(dir / "converge.csv") || fs::exists(dir / "converge.md");
  result.study = converge                              ? "converge"
                 : fs::exists(dir / "readings.csv")    ? "readings"
                 : fs::exists(dir / "sensitivity.csv") ? "sensitivity"
                                                       : "sweep";
  std::string files = "[";
  for (const char* name : kStudyFiles) {
    bool found = false;
    const std::string text = read_file(dir / name, &found);
    if (!found) continue;
    const bool markdown = std::string(name).size() > 3 && std::string(name).substr(std::string(name).size() - 3) == ".md";
    files += std::string(files.size() > 1 ? ",\n" : "") + "{\"name\": " + js(name) + ", \"kind\": " + js(markdown ? "markdown" : "csv") +
             ", \"text\": " + js(text) + "}";
    ++result.rows;
  }
  files += "]";
  bool svg_found = false;
  const std::string svg = read_file(dir / "converge.svg", &svg_found);
  const std::string data = "{\"study\": " + js(result.study) + ", \"run_dir\": " +
                           js(fs::absolute(dir).lexically_normal().string()) + ", \"problems\": [], \"files\": " + files +
                           ", \"chart\": " + (svg_found ? js("data:image/svg+xml;base64," + base64(svg)) : std::string("null")) + "}";
  result.path = write_page(dir, "railcrash " + result.study + " study: " + dir.filename().string(), "null", "null", data);
  return result;
}

ReportResult write_page_of_folder(const std::string& run_dir, const ReportOptions& options);

}  // namespace

bool have_plotting_library() { return assets::kHaveLibrary; }

ReportResult write_report(const std::string& run_dir, const ReportOptions& options) {
  ReportResult result = write_page_of_folder(run_dir, options);
  if (options.pdf) result.pdf_path = print_pdf(result.path);
  return result;
}

namespace {

ReportResult write_page_of_folder(const std::string& run_dir, const ReportOptions& options) {
  const fs::path dir(run_dir);
  std::error_code error;
  if (!fs::is_directory(dir, error))
    throw InputError("run folder '" + run_dir + "' does not exist; give the --out folder of a `railcrash run`");
  ReportResult result;
  std::vector<std::string>& problems = result.problems;
  NumericTable series = read_numeric_csv(dir / "timeseries.csv", problems);
  if (!series.found && (fs::exists(dir / "converge.csv") || fs::exists(dir / "sensitivity.csv") || fs::exists(dir / "readings.csv") ||
                        fs::exists(dir / "runs.csv")))
    return write_study_report(dir);
  // A run with --format hdf5: the per-row tables are the datasets of timeseries.h5 (results/hdf5_file.hpp).
  std::unique_ptr<Hdf5Reader> hdf5;
  std::string series_file = "timeseries.csv", series_run_id = run_id_in(series.comment).value_or("");
  if (!series.found && read_folder_file_head((dir / "timeseries.h5").string(), 8).found) {  // (refuses a link or a FIFO)
    hdf5 = std::make_unique<Hdf5Reader>((dir / "timeseries.h5").string());
    series_file = "timeseries.h5";
    series = numeric_table(hdf5->table("timeseries", max_table_bytes()));
    if (!series.found)
      throw InputError("'" + hdf5->path() + "' has no table timeseries: it is not the file of a `railcrash run --format hdf5`; run the "
                       "model again");
    series_run_id = hdf5->attribute("run_id");
  }
  if (!series.found)
    throw InputError("'" + run_dir + "' has no timeseries.csv: it is not a run folder (nor is there a timeseries.h5 of `run --format hdf5`; "
                     "write one with `railcrash run MODEL --out " + run_dir + "`)");
  if (series.rows == 0 || series.columns.empty() || series.columns[0] != "t")
    throw InputError("'" + (dir / series_file).string() + "' has no complete row of results" +
                     (problems.empty() ? std::string() : " (" + problems.front() + ")") + ": nothing to report");
  // A per-row table other than the timeseries: accelerations, energy.
  const auto read_table = [&](const std::string& name) {
    return hdf5 ? numeric_table(hdf5->table(name, max_table_bytes())) : read_numeric_csv(dir / (name + ".csv"), problems);
  };
  const std::string missing_table_reason = hdf5 ? " (timeseries.h5 has no such table)" : " (older run folder)";
  result.rows = series.rows;

  bool found = false, summary_found = false;
  const std::string summary = read_json_file(dir / "summary.json", &summary_found);
  if (!summary_found) problems.insert(problems.begin(), "no summary.json: the run did not finish (it was killed, crashed or is still running); "
                                                "the report shows the rows written so far");
  require_one_run(dir, summary, summary_found, series_file, series_run_id);
  const nlohmann::json summary_value = parse_json("summary.json", summary, problems);
  if (string_at(summary_value, "status") == "failed") {  // a failed run says so first
    const auto reached = summary_value.find("t_reached");
    const bool have_reached = reached != summary_value.end() && reached->is_number();
    problems.insert(problems.begin(), "The run FAILED" +
                                          (have_reached ? " at t = " + json_number(reached->get<double>()) + " s" : std::string()) +
                                          ": " + string_at(summary_value, "message") + "; the report shows the results up to then");
  }
  // The run's own accuracy warnings (results/accuracy_check.hpp), at the top as `run` printed them.
  if (const auto warnings = summary_value.is_object() ? summary_value.find("accuracy_warnings") : summary_value.end();
      warnings != summary_value.end() && warnings->is_array())
    for (const nlohmann::json& w : *warnings)
      if (w.is_string()) problems.push_back("Accuracy: " + w.get<std::string>());
  const std::string model_json = read_json_file(dir / "model.json", &found);
  if (!found) problems.push_back("no model.json (written by `railcrash run` since the report came in): no animation; run the model again");
  const nlohmann::json model_value = parse_json("model.json", model_json, problems);
  const auto types = element_types(model_value);
  const double g = standard_gravity_of(model_value, summary_value);

  // Bodies: groups of six columns <body>.x ... <body>.omega after t.
  std::vector<std::string> bodies;
  std::size_t column = 1;
  static const char* const kBodyQuantities[] = {".x", ".y", ".theta", ".vx", ".vy", ".omega"};
  const auto ends_with = [](const std::string& text, const std::string& tail) {
    return text.size() > tail.size() && text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
  };
  while (column + 5 < series.columns.size() && ends_with(series.columns[column], ".x")) {
    const std::string name = series.columns[column].substr(0, series.columns[column].size() - 2);
    bool all = true;
    for (int k = 0; k < 6; ++k) all = all && series.columns[column + static_cast<std::size_t>(k)] == name + kBodyQuantities[k];
    if (!all) break;
    bodies.push_back(name);
    column += 6;
  }
  const std::size_t first_output_column = column;
  const std::vector<double>& t = series.data[0];

  // Plotted bodies: car bodies, else all.
  std::vector<std::size_t> plotted;
  for (std::size_t b = 0; b < bodies.size(); ++b)
    if (bodies[b].find("body") != std::string::npos) plotted.push_back(b);
  if (plotted.empty())
    for (std::size_t b = 0; b < bodies.size(); ++b) plotted.push_back(b);
  std::string body_note;
  if (plotted.size() > 60) {
    body_note = "the first 60 of " + std::to_string(plotted.size()) + " bodies";
    plotted.resize(60);
  }

  std::vector<std::string> plots;
  {
    std::vector<PlotSeries> x, v;
    for (std::size_t b : plotted) {
      const std::vector<double>& position = series.data[1 + 6 * b];
      std::vector<double> displacement(position.size());
      for (std::size_t k = 0; k < position.size(); ++k) displacement[k] = position[k] - position[0];
      x.push_back({bodies[b], displacement, true});
      v.push_back({bodies[b], series.data[1 + 6 * b + 3], true});
    }
    plots.push_back(plot_json("displacement", "Longitudinal displacement x(t) - x(0)", "length", t, x, options.max_plot_points, body_note));
    plots.push_back(plot_json("velocity", "Longitudinal velocity", "length/time", t, v, options.max_plot_points, body_note));
  }

  // Accelerations, filtered.
  const NumericTable accelerations = read_table("accelerations");
  if (!accelerations.found) problems.push_back("no accelerations table" + missing_table_reason + ": no acceleration plots");
  if (accelerations.found && accelerations.rows >= 3) {
    const std::vector<double>& ta = accelerations.data[0];
    const double interval = cfc::typical_interval(ta);
    const bool can_filter = interval > 0.0 && cfc::design_frequency(options.cfc) * interval < 0.5;
    if (!can_filter)
      problems.push_back("the output interval " + number(interval) + " s is too long for CFC " + number(options.cfc) +
                         ": the acceleration plots are unfiltered (run with --output-interval below " +
                         number(0.1 / options.cfc) + " s)");
    else if (!cfc::adequately_sampled(options.cfc, interval))
      problems.push_back("the sample rate " + number(1.0 / interval) + " Hz is below 10 x CFC: filtered accelerations are rough");
    std::vector<double> uniform_t;
    if (can_filter) {
      const std::vector<double> index(ta.begin(), ta.end());
      uniform_t = cfc::resample_uniform(ta, index, interval);
    } else {
      uniform_t = ta;
    }
    const double scale = g > 0.0 ? 1.0 / g : 1.0;
    for (const char* axis : {"ax", "ay"}) {
      std::vector<PlotSeries> list;
      for (std::size_t b : plotted) {
        const int c = column_of(accelerations, bodies[b] + "." + axis);
        if (c < 0) continue;
        std::vector<double> a = accelerations.data[static_cast<std::size_t>(c)];
        if (can_filter) a = cfc::filter(cfc::resample_uniform(ta, a, interval), interval, options.cfc);
        for (double& value : a) value *= scale;
        list.push_back({bodies[b], a, true});
      }
      const std::string what = std::string(axis) == "ax" ? "Longitudinal" : "Vertical";
      const std::string filter_name = can_filter ? "CFC " + number(options.cfc) : "unfiltered";
      // The filtered curves' last cfc::end_zone seconds follow the record's last row
      // (results/cfc_filter.hpp "Ends"); the summary's peaks leave them out, the plot says so.
      std::string note = body_note;
      if (can_filter) {
        char zone_ms[32];
        std::snprintf(zone_ms, sizeof zone_ms, "%.2g", 1e3 * cfc::end_zone(options.cfc));
        note += std::string(note.empty() ? "" : "; ") + "the last " + zone_ms + " ms of each filtered curve follow the record's last row, not the pulse (the filter's end zone; "
                "summary.json's CFC peaks leave it out)";
      }
      plots.push_back(plot_json(std::string("acceleration_") + axis, what + " acceleration (" + filter_name + ")",
                                g > 0.0 ? "g" : "length/time^2", uniform_t, list, options.max_plot_points, note));
    }
  }

  // Element forces and force-deformation loops.
  std::map<std::string, std::string> type_of(types.begin(), types.end());
  std::vector<PlotSeries> forces;
  std::vector<std::string> loops;
  std::vector<std::string> element_force_column;  // per element of model.json: its force column
  static const char* const kForceNames[] = {"horizontal_force", "force", "normal_force"};
  // Crash elements (an output with the crash_force role) come first and are shown, with a
  // force-deformation loop when they also have a crash_deformation; others are listed hidden.
  const auto roles = element_roles(model_value);
  const auto role_column = [&](const std::string& name, const char* role) {
    const auto element = roles.find(name);
    if (element == roles.end()) return -1;
    const auto output = element->second.find(role);
    return output == element->second.end() ? -1 : column_of(series, name + "." + output->second);
  };
  if (!types.empty() && model_json.find("\"roles\": ") == std::string::npos)
    problems.push_back("model.json gives no output roles (older run folder): no element is shown as a crash element");
  std::vector<std::string> crash_first, others;
  for (const auto& [name, type] : types) (role_column(name, "crash_force") >= 0 ? crash_first : others).push_back(name);
  for (const auto* group : {&crash_first, &others})
    for (const std::string& name : *group) {
      const bool crash = group == &crash_first;
      int force = crash ? role_column(name, "crash_force") : -1;
      const int deformation = crash ? role_column(name, "crash_deformation") : -1;
      for (const char* f : kForceNames)
        if (force < 0) force = column_of(series, name + "." + f);
      if (force < 0) continue;
      forces.push_back({name, series.data[static_cast<std::size_t>(force)], crash});
      if (crash && deformation >= 0 && loops.size() < 40) {
        const std::vector<double>& a = series.data[static_cast<std::size_t>(deformation)];
        const std::vector<double>& b = series.data[static_cast<std::size_t>(force)];
        std::vector<double> da, db;
        for (std::size_t k : decimate_path(a, b, options.max_plot_points)) {
          da.push_back(a[k]);
          db.push_back(b[k]);
        }
        loops.push_back("{\"name\": " + js(name) + ", \"type\": " + js(type_of[name]) + ", \"x_label\": " +
                        js(series.columns[static_cast<std::size_t>(deformation)]) + ", \"y_label\": " +
                        js(series.columns[static_cast<std::size_t>(force)]) + ", \"x\": " + numbers(da) + ", \"y\": " + numbers(db) + "}");
      }
    }
  if (types.empty())  // no model.json: every force column, shown
    for (std::size_t c = first_output_column; c < series.columns.size(); ++c)
      if (ends_with(series.columns[c], ".force") || ends_with(series.columns[c], "_force"))
        forces.push_back({series.columns[c], series.data[c], true});
  if (forces.size() > 200) forces.resize(200);
  {  // The interface forces at the channel class asked (SAE J211-1: CFC 60 for barrier face forces).
    const FilteredForces filtered = filter_forces(t, forces, options.force_cfc, problems);
    plots.push_back(plot_json("forces", "Element forces (" + filtered.filter_name + "; crash elements shown; click a name to show others)",
                              "force", filtered.t, filtered.series, options.max_plot_points, filtered.note));
  }

  // Energy partition.
  const NumericTable energy = read_table("energy");
  std::string energy_json = "null";
  if (energy.found && energy.rows > 0) {
    std::vector<PlotSeries> list;
    for (std::size_t c = 1; c < energy.columns.size(); ++c) list.push_back({energy.columns[c], energy.data[c], true});
    energy_json = plot_json("energy", "Energy partition", "energy", energy.data[0], list, options.max_plot_points);
  } else if (!energy.found) {
    problems.push_back("no energy table" + missing_table_reason + ": no energy plot");
  }

  // Animation frames: uniform stride, bounded total size.
  const std::size_t per_frame = 3 * bodies.size() + types.size() + 1;
  const std::size_t frame_budget = std::max<std::size_t>(50, 3000000 / std::max<std::size_t>(per_frame, 1));
  const std::size_t frame_count = std::min({series.rows, options.max_frames, frame_budget});
  std::vector<std::size_t> frame_rows;
  for (std::size_t f = 0; f < frame_count; ++f)
    frame_rows.push_back(frame_count > 1 ? f * (series.rows - 1) / (frame_count - 1) : 0);
  std::string frames = "{\"t\": [";
  for (std::size_t f = 0; f < frame_rows.size(); ++f) frames += (f ? "," : "") + number(t[frame_rows[f]]);
  frames += "], \"bodies\": " + [&] {
    std::string out = "[";
    for (std::size_t b = 0; b < bodies.size(); ++b) out += (b ? ", " : "") + js(bodies[b]);
    return out + "]";
  }() + ", \"pose\": [";
  for (std::size_t f = 0; f < frame_rows.size(); ++f) {
    frames += f ? ",[" : "[";
    for (std::size_t b = 0; b < bodies.size(); ++b)
      for (int k = 0; k < 3; ++k)
        frames += (b || k ? "," : "") + number(series.data[1 + 6 * b + static_cast<std::size_t>(k)][frame_rows[f]]);
    frames += "]";
  }
  frames += "], \"force\": [";
  for (std::size_t e = 0; e < types.size(); ++e) {
    int force = -1;
    for (const char* f : kForceNames)
      if (force < 0) force = column_of(series, types[e].first + "." + f);
    if (force < 0) {
      frames += e ? ",null" : "null";
      continue;
    }
    std::vector<double> values;
    for (std::size_t row : frame_rows) values.push_back(series.data[static_cast<std::size_t>(force)][row]);
    frames += (e ? "," : "") + numbers(values);
  }
  frames += "]}";

  // Events.
  std::string events = "[";
  {
    bool events_found = false;
    std::vector<EventRow> rows;
    if (hdf5) {
      for (Hdf5Event& e : hdf5->events("events", kMaxEvents, &events_found))
        rows.push_back({e.t, std::move(e.element), std::move(e.event), e.value});
    } else {
      rows = read_events_csv(dir / "events.csv", &events_found);
    }
    if (!events_found) problems.push_back(hdf5 ? "no events table in timeseries.h5" : "no events.csv");
    for (std::size_t k = 0; k < rows.size(); ++k)
      events += std::string(k ? ",\n" : "") + "[" + number(rows[k].t) + "," + js(rows[k].element) + "," + js(rows[k].event) + "," +
                number(rows[k].value) + "]";
  }
  events += "]";

  std::string problems_json = "[";
  for (std::size_t k = 0; k < problems.size(); ++k) problems_json += (k ? ", " : "") + js(problems[k]);
  problems_json += "]";
  std::string plots_json = "[";
  for (std::size_t k = 0; k < plots.size(); ++k) plots_json += (k ? ",\n" : "") + plots[k];
  plots_json += "]";
  std::string loops_json = "[";
  for (std::size_t k = 0; k < loops.size(); ++k) loops_json += (k ? ",\n" : "") + loops[k];
  loops_json += "]";

  const std::string data = "{\"run_dir\": " + js(fs::absolute(dir).lexically_normal().string()) + ", \"problems\": " + problems_json +
                           ", \"cfc\": " + number(options.cfc) + ", \"standard_gravity\": " + number(g) +
                           ", \"rows\": " + std::to_string(series.rows) + ", \"library\": " + js(assets::kLibraryName) +
                           ",\n\"frames\": " + frames + ",\n\"plots\": " + plots_json + ",\n\"loops\": " + loops_json +
                           ",\n\"energy\": " + energy_json + ",\n\"events\": " + events + "}";

  // A file that is not JSON goes into the page as null (the page parses these blocks).
  result.path = write_page(dir, "railcrash report: " + dir.filename().string(), summary_value.is_null() ? "null" : summary,
                           model_value.is_null() ? "null" : model_json, data);
  return result;
}

}  // namespace

// ---------------------------------------------------------------- runs side by side (issue 39 item 5)

namespace {

/// A number of a JSON value, NaN when it is not one.
double number_or_nan(const nlohmann::json* value) {
  return value && value->is_number() ? value->get<double>() : std::nan("");
}

/// The JSON value at a path of keys, null when a key is missing.
const nlohmann::json* at_path(const nlohmann::json& root, std::initializer_list<const char*> keys) {
  const nlohmann::json* at = &root;
  for (const char* key : keys) {
    if (!at->is_object()) return nullptr;
    const auto it = at->find(key);
    if (it == at->end()) return nullptr;
    at = &*it;
  }
  return at;
}

/// One run folder as the side-by-side page reads it.
struct ComparedRun {
  fs::path dir;
  std::string label;          // the folder's name (with its position when two share one)
  std::string series_file;    // timeseries.csv or timeseries.h5
  NumericTable series, energy;
  nlohmann::json summary, model;
};

/// Reads a run folder's timeseries (CSV or HDF5), energy table, summary.json and model.json,
/// with the single-run page's checks (one run per folder, a complete row).
ComparedRun read_compared_run(const std::string& run_dir, std::vector<std::string>& problems) {
  ComparedRun run;
  run.dir = fs::path(run_dir);
  std::error_code error;
  if (!fs::is_directory(run.dir, error))
    throw InputError("run folder '" + run_dir + "' does not exist; give the --out folders of `railcrash run`s to compare");
  std::vector<std::string> own;
  run.series = read_numeric_csv(run.dir / "timeseries.csv", own);
  run.series_file = "timeseries.csv";
  std::string series_run_id = run_id_in(run.series.comment).value_or("");
  std::unique_ptr<Hdf5Reader> hdf5;
  if (!run.series.found && read_folder_file_head((run.dir / "timeseries.h5").string(), 8).found) {
    hdf5 = std::make_unique<Hdf5Reader>((run.dir / "timeseries.h5").string());
    run.series_file = "timeseries.h5";
    run.series = numeric_table(hdf5->table("timeseries", max_table_bytes()));
    series_run_id = hdf5->attribute("run_id");
  }
  if (!run.series.found)
    throw InputError("'" + run_dir + "' has no timeseries.csv nor timeseries.h5: it is not a run folder (a study folder or a "
                     "typing error?); give the --out folders of `railcrash run`s");
  if (run.series.rows == 0 || run.series.columns.empty() || run.series.columns[0] != "t")
    throw InputError("'" + (run.dir / run.series_file).string() + "' has no complete row of results: nothing to compare");
  bool summary_found = false, model_found = false;
  const std::string summary = read_json_file(run.dir / "summary.json", &summary_found);
  require_one_run(run.dir, summary, summary_found, run.series_file, series_run_id);
  if (!summary_found) own.push_back("no summary.json: the run did not finish; its summary quantities are left blank");
  run.summary = parse_json("summary.json", summary, own);
  if (string_at(run.summary, "status") == "failed")
    own.insert(own.begin(), "the run FAILED at t = " + number(number_or_nan(at_path(run.summary, {"t_reached"}))) + " s: " +
                                string_at(run.summary, "message"));
  run.model = parse_json("model.json", read_json_file(run.dir / "model.json", &model_found), own);
  run.energy = hdf5 ? numeric_table(hdf5->table("energy", max_table_bytes())) : read_numeric_csv(run.dir / "energy.csv", own);
  for (const std::string& p : own) problems.push_back(run_dir + ": " + p);
  return run;
}

/// A table of summary quantities, a row per quantity, a value per run; the differences to the
/// first run (absolute and in % of its magnitude) are computed here, so that the page shows
/// what the test checks.
class ComparisonTable {
 public:
  ComparisonTable(std::string id, std::string title, std::string unit, std::size_t runs)
      : id_(std::move(id)), title_(std::move(title)), unit_(std::move(unit)), runs_(runs) {}
  void set(const std::string& row, std::size_t run, double value) {
    auto it = index_.find(row);
    if (it == index_.end()) {
      it = index_.emplace(row, rows_.size()).first;
      rows_.push_back({row, std::vector<double>(runs_, std::nan(""))});
    }
    rows_[it->second].second[run] = value;
  }
  bool empty() const { return rows_.empty(); }
  std::string json() const {
    std::string out = "{\"id\": " + js(id_) + ", \"title\": " + js(title_) + ", \"unit\": " + js(unit_) + ", \"rows\": [";
    for (std::size_t r = 0; r < rows_.size(); ++r) {
      const std::vector<double>& v = rows_[r].second;
      std::vector<double> difference(v.size(), std::nan("")), percent(v.size(), std::nan(""));
      for (std::size_t k = 1; k < v.size(); ++k) {
        difference[k] = v[k] - v[0];  // NaN when either is missing
        if (std::isfinite(difference[k]) && v[0] != 0.0) percent[k] = 100.0 * difference[k] / std::fabs(v[0]);
      }
      out += std::string(r ? ",\n" : "") + "{\"name\": " + js(rows_[r].first) + ", \"values\": " + precise(v) +
             ", \"difference\": " + precise(difference) + ", \"percent\": " + precise(percent) + "}";
    }
    return out + "]}";
  }

 private:
  static std::string precise(const std::vector<double>& values) {
    std::string out = "[";
    for (std::size_t k = 0; k < values.size(); ++k) out += std::string(k ? "," : "") + (std::isfinite(values[k]) ? json_number(values[k]) : "null");
    return out + "]";
  }
  std::string id_, title_, unit_;
  std::size_t runs_;
  std::map<std::string, std::size_t> index_;
  std::vector<std::pair<std::string, std::vector<double>>> rows_;
};

/// The numeric leaves of a JSON object as "a.b.c" -> value (booleans as 0/1).
void numeric_leaves(const nlohmann::json& value, const std::string& prefix, std::vector<std::pair<std::string, double>>& out) {
  if (value.is_object()) {
    for (const auto& [key, item] : value.items()) numeric_leaves(item, prefix.empty() ? key : prefix + "." + key, out);
  } else if (value.is_number()) {
    out.emplace_back(prefix, value.get<double>());
  } else if (value.is_boolean()) {
    out.emplace_back(prefix + " (1: true)", value.get<bool>() ? 1.0 : 0.0);
  }
}

/// One chart per quantity and entity, a line per run: the union of the runs' (decimated) output
/// times, each run's values at its own times and null between (the page spans the gaps).
std::string overlay_json(const std::string& id, const std::string& title, const std::string& unit,
                         const std::vector<const std::vector<double>*>& times, const std::vector<const std::vector<double>*>& values,
                         const std::vector<std::string>& labels, std::size_t max_points) {
  std::map<double, std::vector<double>> merged;
  const std::size_t runs = times.size();
  for (std::size_t k = 0; k < runs; ++k) {
    if (!times[k] || !values[k]) continue;
    const Decimated d = decimate_minmax(*times[k], {*values[k]}, max_points);
    for (std::size_t i = 0; i < d.x.size(); ++i) {
      auto it = merged.find(d.x[i]);
      if (it == merged.end()) it = merged.emplace(d.x[i], std::vector<double>(runs, std::nan(""))).first;
      it->second[k] = d.series[0][i];
    }
  }
  std::vector<double> t;
  std::vector<std::vector<double>> columns(runs);
  for (const auto& [time, row] : merged) {
    t.push_back(time);
    for (std::size_t k = 0; k < runs; ++k) columns[k].push_back(row[k]);
  }
  std::string out = "{\"id\": " + js(id) + ", \"title\": " + js(title) + ", \"unit\": " + js(unit) + ", \"t\": " + numbers(t) + ", \"series\": [";
  for (std::size_t k = 0; k < runs; ++k) {
    out += std::string(k ? ", " : "") + "{\"name\": " + js(labels[k]) + ", \"present\": " + (times[k] && values[k] ? "true" : "false") +
           ", \"values\": " + numbers(columns[k]) + "}";
  }
  return out + "]}";
}

}  // namespace

ReportResult write_comparison(const std::vector<std::string>& run_dirs, const std::string& out_path, const ReportOptions& options) {
  if (run_dirs.size() < 2)
    throw InputError("a side-by-side report needs two run folders or more (`railcrash report RUN_A RUN_B`); for one run, "
                     "`railcrash report RUN_DIR` writes RUN_DIR/report.html");
  const fs::path out = out_path.empty() ? fs::path(default_comparison_path(run_dirs)) : fs::path(out_path);
  const fs::path out_dir = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  std::error_code out_error;
  if (!fs::is_directory(out_dir, out_error))
    throw InputError("the folder of the page '" + out.string() + "' does not exist: create it, or give --out a path in a folder that exists");
  ReportResult result;
  std::vector<std::string>& problems = result.problems;
  std::vector<ComparedRun> runs;
  for (const std::string& dir : run_dirs) runs.push_back(read_compared_run(dir, problems));
  const std::size_t n = runs.size();
  // Labels: the folders' names, with the position when two have the same name.
  for (std::size_t k = 0; k < n; ++k) {
    runs[k].label = fs::absolute(runs[k].dir).lexically_normal().filename().string();
    if (runs[k].label.empty()) runs[k].label = fs::absolute(runs[k].dir).lexically_normal().parent_path().filename().string();
  }
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t j = 0; j < n; ++j)
      if (j != k && runs[j].label == runs[k].label) {
        for (std::size_t m = 0; m < n; ++m) runs[m].label = std::to_string(m + 1) + ": " + runs[m].label;
        j = k = n;
      }

  // Columns: overlay those every run has; list the others. No shared column but t: refuse.
  std::set<std::string> shared(runs[0].series.columns.begin(), runs[0].series.columns.end());
  for (std::size_t k = 1; k < n; ++k) {
    std::set<std::string> both;
    for (const std::string& c : runs[k].series.columns)
      if (shared.count(c)) both.insert(c);
    shared = std::move(both);
  }
  std::vector<std::string> unshared;  // "column (only in a, b)"
  {
    std::map<std::string, std::vector<std::string>> holders;
    for (const ComparedRun& run : runs)
      for (const std::string& c : run.series.columns)
        if (!shared.count(c)) holders[c].push_back(run.label);
    for (const auto& [column, labels] : holders) {
      std::string who;
      for (const std::string& l : labels) who += (who.empty() ? "" : ", ") + l;
      unshared.push_back(column + " (only in " + who + ")");
    }
  }
  if (shared.size() <= 1) {
    const auto first_columns = [](const ComparedRun& run) {
      std::string names;
      for (std::size_t c = 1; c < run.series.columns.size() && c < 4; ++c) names += (c > 1 ? ", " : "") + run.series.columns[c];
      return names + (run.series.columns.size() > 4 ? ", ..." : "");
    };
    throw InputError("'" + (runs[0].dir / runs[0].series_file).string() + "' (" + first_columns(runs[0]) + ") and the other runs' " +
                     "timeseries share no column but t: they are runs of different models, whose time histories cannot be "
                     "overlaid; compare runs of one model (e.g. `railcrash run MODEL --set ... --out B`), or give the runs "
                     "that share bodies and elements");
  }
  if (!unshared.empty())
    problems.push_back(std::to_string(unshared.size()) + " timeseries columns are not in every run and are not overlaid (listed under "
                       "\"Columns not shared\")");

  // Units: the model's (summary.json "units": SI, or in-lbf-s for the report's models); runs of
  // two unit systems are not compared value by value.
  const auto unit_of = [](const ComparedRun& run, const char* quantity, const char* fallback) {
    const std::string unit = string_at(at_path(run.summary, {"units"}) ? *at_path(run.summary, {"units"}) : nlohmann::json(), quantity);
    return unit.empty() ? std::string(fallback) : unit;
  };
  for (std::size_t k = 1; k < n; ++k)
    if (unit_of(runs[k], "system", "SI") != unit_of(runs[0], "system", "SI"))
      throw InputError("'" + (runs[k].dir / "summary.json").string() + "' is in units " + unit_of(runs[k], "system", "SI") + " but '" +
                       (runs[0].dir / "summary.json").string() + "' in " + unit_of(runs[0], "system", "SI") +
                       ": their values cannot be compared as they stand; run both models in one unit system");
  const std::string length_unit = unit_of(runs[0], "length", "m"), energy_unit = unit_of(runs[0], "energy", "J"),
                    force_unit = unit_of(runs[0], "force", "N"), speed_unit = length_unit + "/" + unit_of(runs[0], "time", "s");

  // Runs ending at different times: the end-of-run quantities are of different instants.
  for (std::size_t k = 1; k < n; ++k) {
    const double a = number_or_nan(at_path(runs[0].summary, {"t_reached"})), b = number_or_nan(at_path(runs[k].summary, {"t_reached"}));
    if (std::isfinite(a) && std::isfinite(b) && std::fabs(a - b) > 1e-9 * std::max(std::fabs(a), std::fabs(b)))
      problems.push_back(runs[k].label + " ends at t = " + number(b) + " s and " + runs[0].label + " at t = " + number(a) +
                         " s: the energies at the end and the peaks are of different spans of time");
  }
  // Summary tables, the differences to the first run.
  std::vector<ComparisonTable> tables;
  ComparisonTable crush("car_crush", "Car crush: each car's largest shortening between its ends (summary.json car_crush)", length_unit, n);
  ComparisonTable zones("zone_energy", "Energy absorbed per crush zone (summary.json crush_zones, as energy_zones.csv)", energy_unit, n);
  ComparisonTable cars("car_energy", "Energy absorbed per car (crush zones' shares)", energy_unit, n);
  ComparisonTable energy("energy", "Energy at the end of the run (summary.json energy)", energy_unit, n);
  ComparisonTable accelerations("accelerations", "Peak longitudinal acceleration of the car bodies, CFC 60 (summary.json peak_accelerations x_cfc)", "g", n);
  ComparisonTable criteria("criteria", "Responses and criteria (summary.json responses R1-R3, scenario)", "", n);
  ComparisonTable peaks("peaks", "Peak values of every output (summary.json peaks: max and min)", "", n);
  std::string outcomes = "[";
  for (std::size_t k = 0; k < n; ++k) {
    const nlohmann::json& s = runs[k].summary;
    if (const nlohmann::json* cc = at_path(s, {"car_crush"}); cc && cc->is_object())
      for (const auto& [car, value] : cc->items()) crush.set(car, k, number_or_nan(at_path(value, {"max_crush"})));
    if (const nlohmann::json* list = at_path(s, {"crush_zones", "zones"}); list && list->is_array())
      for (const nlohmann::json& zone : *list) zones.set(string_at(zone, "element"), k, number_or_nan(at_path(zone, {"absorbed"})));
    if (const nlohmann::json* total = at_path(s, {"crush_zones", "total_absorbed"})) zones.set("total", k, number_or_nan(total));
    if (const nlohmann::json* by_car = at_path(s, {"crush_zones", "cars"}); by_car && by_car->is_object())
      for (const auto& [car, value] : by_car->items()) cars.set(car, k, number_or_nan(at_path(value, {"absorbed"})));
    for (const char* key : {"kinetic", "elastic", "dissipated", "external_work", "initial_total", "integration_drift"})
      if (const nlohmann::json* e = at_path(s, {"energy", key})) energy.set(key, k, number_or_nan(e));
    if (const nlohmann::json* bodies = at_path(s, {"peak_accelerations", "bodies"}); bodies && bodies->is_object())
      for (const auto& [body, value] : bodies->items())
        if (body.find("body") != std::string::npos) accelerations.set(body, k, number_or_nan(at_path(value, {"x_cfc", "g"})));
    for (const char* section : {"responses", "scenario"})
      if (const nlohmann::json* r = at_path(s, {section})) {
        std::vector<std::pair<std::string, double>> leaves;
        numeric_leaves(*r, section, leaves);
        for (const auto& [name, value] : leaves) criteria.set(name, k, value);
      }
    if (const nlohmann::json* p = at_path(s, {"peaks"}); p && p->is_object())
      for (const auto& [name, value] : p->items()) {
        peaks.set(name + " max", k, number_or_nan(at_path(value, {"max"})));
        peaks.set(name + " min", k, number_or_nan(at_path(value, {"min"})));
      }
    const nlohmann::json* o = at_path(s, {"outcomes"});
    outcomes += std::string(k ? ", " : "") + "{\"signature\": " + js(o ? string_at(*o, "signature") : "") +
                ", \"branch\": " + js(o ? string_at(*o, "branch") : "") + "}";
  }
  outcomes += "]";
  std::string tables_json = "[";
  for (const ComparisonTable* table : {&crush, &zones, &cars, &energy, &accelerations, &criteria, &peaks})
    if (!table->empty()) tables_json += std::string(tables_json.size() > 1 ? ",\n" : "") + table->json();
  tables_json += "]";

  // Identity of each run.
  std::string runs_json = "[";
  for (std::size_t k = 0; k < n; ++k) {
    const nlohmann::json& s = runs[k].summary;
    const nlohmann::json* reached = at_path(s, {"t_reached"});
    const nlohmann::json* settings = at_path(s, {"provenance", "settings"});
    std::string model_name = string_at(s, "model");
    if (model_name.empty()) model_name = string_at(runs[k].model, "name");
    runs_json += std::string(k ? ",\n" : "") + "{\"label\": " + js(runs[k].label) + ", \"folder\": " +
                 js(fs::absolute(runs[k].dir).lexically_normal().string()) + ", \"model\": " + js(model_name) +
                 ", \"integrator\": " + js(string_at(s, "integrator")) + ", \"status\": " +
                 js(s.is_null() ? "no summary.json" : string_at(s, "status")) + ", \"message\": " + js(string_at(s, "message")) +
                 ", \"t_reached\": " + (reached && reached->is_number() ? json_number(reached->get<double>()) : "null") +
                 ", \"run_id\": " + js(string_at(s, "run_id")) + ", \"file\": " + js(runs[k].series_file) +
                 ", \"rows\": " + std::to_string(runs[k].series.rows) +
                 ", \"settings\": " + (settings && settings->is_array() ? settings->dump() : "[]") + "}";
  }
  runs_json += "]";

  // Time histories: one chart per quantity and entity, a line per run.
  std::vector<std::string> labels;
  for (const ComparedRun& run : runs) labels.push_back(run.label);
  std::vector<std::string> charts;
  const auto column = [](const ComparedRun& run, const std::string& name) -> const std::vector<double>* {
    const int c = column_of(run.series, name);
    return c < 0 ? nullptr : &run.series.data[static_cast<std::size_t>(c)];
  };
  std::vector<const std::vector<double>*> times;
  for (const ComparedRun& run : runs) times.push_back(&run.series.data[0]);
  const std::size_t per_run = std::max<std::size_t>(200, options.max_plot_points / n);
  // Car bodies (names containing "body", else every body) shared by all runs.
  std::vector<std::string> bodies;
  for (const std::string& c : runs[0].series.columns)
    if (c.size() > 2 && c.compare(c.size() - 2, 2, ".x") == 0 && shared.count(c) && shared.count(c.substr(0, c.size() - 2) + ".vx"))
      bodies.push_back(c.substr(0, c.size() - 2));
  std::vector<std::string> car_bodies;
  for (const std::string& b : bodies)
    if (b.find("body") != std::string::npos) car_bodies.push_back(b);
  if (car_bodies.empty()) car_bodies = bodies;
  if (car_bodies.size() > 30) car_bodies.resize(30);
  std::vector<std::vector<double>> displacement_store(n * car_bodies.size());
  for (std::size_t b = 0; b < car_bodies.size(); ++b) {
    std::vector<const std::vector<double>*> x, v;
    for (std::size_t k = 0; k < n; ++k) {
      const std::vector<double>& position = *column(runs[k], car_bodies[b] + ".x");
      std::vector<double>& d = displacement_store[b * n + k];
      d.resize(position.size());
      for (std::size_t i = 0; i < position.size(); ++i) d[i] = position[i] - position[0];
      x.push_back(&d);
      v.push_back(column(runs[k], car_bodies[b] + ".vx"));
    }
    charts.push_back(overlay_json("displacement:" + car_bodies[b], car_bodies[b] + ": x(t) - x(0)", length_unit, times, x, labels, per_run));
    charts.push_back(overlay_json("velocity:" + car_bodies[b], car_bodies[b] + ": longitudinal velocity", speed_unit, times, v, labels, per_run));
  }
  // Crash elements (model.json roles crash_force, crash_deformation) of the first run shared by all.
  const auto roles = element_roles(runs[0].model);
  std::size_t crash_charts = 0;
  std::vector<std::vector<double>> force_store;
  force_store.reserve(2 * n * roles.size() + 1);
  for (const auto& [element, role_map] : roles) {
    const auto force_role = role_map.find("crash_force");
    if (force_role == role_map.end() || crash_charts >= 40) continue;
    const std::string force_column = element + "." + force_role->second;
    if (!shared.count(force_column)) continue;
    std::vector<const std::vector<double>*> f, d, ft;
    const auto deformation_role = role_map.find("crash_deformation");
    const std::string deformation_column = deformation_role == role_map.end() ? "" : element + "." + deformation_role->second;
    for (std::size_t k = 0; k < n; ++k) {
      // The forces at the channel class asked (as the single-run page: CFC 60 by default).
      std::vector<std::string> filter_problems;
      const FilteredForces filtered = filter_forces(runs[k].series.data[0], {{element, *column(runs[k], force_column), true}},
                                                    options.force_cfc, filter_problems);
      force_store.push_back(filtered.t);
      ft.push_back(&force_store.back());
      force_store.push_back(filtered.series[0].values);
      f.push_back(&force_store.back());
      d.push_back(shared.count(deformation_column) ? column(runs[k], deformation_column) : nullptr);
    }
    const std::string filter_name = options.force_cfc > 0 ? "CFC " + number(options.force_cfc) : "unfiltered";
    charts.push_back(overlay_json("force:" + element, element + ": " + force_role->second + " (" + filter_name + ")", force_unit, ft, f, labels, per_run));
    if (d[0]) charts.push_back(overlay_json("deformation:" + element, element + ": " + deformation_role->second, length_unit, times, d, labels, per_run));
    ++crash_charts;
  }
  // Energy partition: a chart per column every run's energy table has.
  if (runs[0].energy.found)
    for (std::size_t c = 1; c < runs[0].energy.columns.size(); ++c) {
      const std::string& name = runs[0].energy.columns[c];
      std::vector<const std::vector<double>*> et, ev;
      bool all = true;
      for (const ComparedRun& run : runs) {
        const int j = column_of(run.energy, name);
        all = all && j >= 0 && run.energy.rows > 0;
        if (!all) break;
        et.push_back(&run.energy.data[0]);
        ev.push_back(&run.energy.data[static_cast<std::size_t>(j)]);
      }
      if (all) charts.push_back(overlay_json("energy:" + name, "Energy: " + name, energy_unit, et, ev, labels, per_run));
    }
  std::string charts_json = "[";
  for (std::size_t k = 0; k < charts.size(); ++k) charts_json += (k ? ",\n" : "") + charts[k];
  charts_json += "]";
  std::string unshared_json = "[";
  for (std::size_t k = 0; k < unshared.size(); ++k) unshared_json += (k ? ", " : "") + js(unshared[k]);
  unshared_json += "]";
  std::string problems_json = "[";
  for (std::size_t k = 0; k < problems.size(); ++k) problems_json += (k ? ", " : "") + js(problems[k]);
  problems_json += "]";

  const std::string data = "{\"compare\": true, \"problems\": " + problems_json + ", \"library\": " + js(assets::kLibraryName) +
                           ",\n\"runs\": " + runs_json + ",\n\"tables\": " + tables_json + ",\n\"outcomes\": " + outcomes +
                           ",\n\"unshared\": " + unshared_json + ",\n\"charts\": " + charts_json + "}";
  std::string title = "railcrash runs side by side:";
  for (const ComparedRun& run : runs) title += " " + run.label;
  result.path = write_page(out_dir, title, "null", "null", data, out.filename().string());
  result.rows = n;
  if (options.pdf) result.pdf_path = print_pdf(result.path);
  return result;
}

std::string default_comparison_path(const std::vector<std::string>& run_dirs) {
  // Beside the first run folder: compare_<A>_<B>[...].html, the names cut to keep it short.
  const fs::path first = fs::absolute(fs::path(run_dirs.empty() ? "." : run_dirs[0])).lexically_normal();
  const fs::path first_dir = first.filename().empty() ? first.parent_path() : first;
  std::string name = "compare";
  for (const std::string& dir : run_dirs) {
    fs::path p = fs::absolute(fs::path(dir)).lexically_normal();
    if (p.filename().empty()) p = p.parent_path();
    std::string part = p.filename().string();
    for (char& c : part)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.') c = '_';
    name += "_" + part.substr(0, 40);
    if (name.size() > 150) break;
  }
  return (first_dir.parent_path() / (name + ".html")).string();
}

}  // namespace railcrash::report
