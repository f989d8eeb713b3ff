#include "railcrash/studies/readings.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <numeric>
#include <set>
#include <sstream>

#include "railcrash/core/error.hpp"
#include "railcrash/core/table_text.hpp"
#include "railcrash/core/whole_file.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/model/yaml_file.hpp"
#include "railcrash/studies/batch.hpp"
#include "railcrash/studies/run_count.hpp"

namespace railcrash {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string scalar_text(const std::string& path, const YAML::Node& node, const std::string& context) {
  if (!node || !node.IsScalar() || node.Scalar().empty()) yaml_error(path, node, context + " must be a word");
  return node.Scalar();
}

std::string format(double value, const char* spec = "%.3f") { return table_number(value, spec); }
std::string csv_field(double value) { return csv_number(value, "%.8g"); }

std::vector<double> average_ranks(const std::vector<double>& values) {
  std::vector<std::size_t> order(values.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
  std::vector<double> ranks(values.size());
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    while (j + 1 < order.size() && values[order[j + 1]] == values[order[i]]) ++j;
    const double rank = 0.5 * static_cast<double>(i + j) + 1.0;
    for (std::size_t k = i; k <= j; ++k) ranks[order[k]] = rank;
    i = j + 1;
  }
  return ranks;
}

struct ChangeScores {
  int significant = 0, agree = 0;
  double spearman = kNaN, rms = kNaN;
};

ChangeScores score_changes(const std::vector<double>& ours, const std::vector<double>& published) {
  ChangeScores s;
  double sum = 0.0;
  for (std::size_t i = 0; i < ours.size(); ++i) {
    sum += (ours[i] - published[i]) * (ours[i] - published[i]);
    // The published changes are rounded to 3 decimals: compare with a hair of slack.
    if (std::abs(published[i]) < kSignificantChange - 1e-9) continue;
    ++s.significant;
    if (ours[i] * published[i] > 0.0) ++s.agree;
  }
  if (!ours.empty()) s.rms = std::sqrt(sum / static_cast<double>(ours.size()));
  s.spearman = spearman_correlation(ours, published);
  return s;
}

}  // namespace

double spearman_correlation(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size() || a.size() < 3) return kNaN;
  const std::vector<double> ra = average_ranks(a), rb = average_ranks(b);
  const double n = static_cast<double>(a.size());
  const double mean = (n + 1.0) / 2.0;  // the mean of average ranks is always (n + 1) / 2
  double sab = 0.0, saa = 0.0, sbb = 0.0;
  for (std::size_t i = 0; i < ra.size(); ++i) {
    sab += (ra[i] - mean) * (rb[i] - mean);
    saa += (ra[i] - mean) * (ra[i] - mean);
    sbb += (rb[i] - mean) * (rb[i] - mean);
  }
  if (saa <= 0.0 || sbb <= 0.0) return kNaN;
  return sab / std::sqrt(saa * sbb);
}

std::optional<std::size_t> ReadingsPlan::combination_count() const {
  if (one_at_a_time) {
    std::optional<std::size_t> count = 1;
    for (const Reading& r : readings) count = add_counts(count, r.levels.empty() ? 0 : r.levels.size() - 1);
    return count;
  }
  std::vector<std::size_t> level_counts;
  for (const Reading& r : readings) level_counts.push_back(r.levels.size());
  return readings.empty() ? std::optional<std::size_t>(1) : factorial_count(level_counts);
}

std::vector<int> ReadingsPlan::combination(std::size_t index) const {
  std::vector<int> c(readings.size(), 0);
  if (one_at_a_time) {
    if (index == 0) return c;
    std::size_t rest = index - 1;
    for (std::size_t r = 0; r < readings.size(); ++r) {
      const std::size_t others = readings[r].levels.size() - 1;  // the reading's levels after the first
      if (rest < others) {
        c[r] = static_cast<int>(rest + 1);
        return c;
      }
      rest -= others;
    }
    RAILCRASH_DEMAND(false);  // index beyond combination_count()
  }
  for (std::size_t r = readings.size(); r-- > 0;) {  // the last reading changes fastest
    const std::size_t levels = readings[r].levels.size();
    c[r] = static_cast<int>(index % levels);
    index /= levels;
  }
  return c;
}

std::vector<std::vector<int>> ReadingsPlan::combinations() const {
  const std::optional<std::size_t> count = combination_count();
  RAILCRASH_DEMAND(count.has_value());
  std::vector<std::vector<int>> list;
  for (std::size_t k = 0; k < *count; ++k) list.push_back(combination(k));
  return list;
}

std::vector<std::string> ReadingsPlan::settings(const std::vector<int>& combination) const {
  std::vector<std::string> all;
  for (std::size_t r = 0; r < readings.size(); ++r) {
    const auto& level = readings[r].levels[static_cast<std::size_t>(combination[r])];
    all.insert(all.end(), level.settings.begin(), level.settings.end());
  }
  return all;
}

std::string ReadingsPlan::label(const std::vector<int>& combination) const {
  std::string text;
  for (std::size_t r = 0; r < readings.size(); ++r)
    text += (text.empty() ? "" : ", ") + readings[r].name + "=" + readings[r].levels[static_cast<std::size_t>(combination[r])].name;
  return text;
}

SensitivityDesign ReadingsPlan::design_for(const std::vector<int>& combination, const SensitivityDesign& design) const {
  SensitivityDesign changed = design;
  for (std::size_t r = 0; r < readings.size(); ++r) {
    const ReadingLevel& level = readings[r].levels[static_cast<std::size_t>(combination[r])];
    for (const auto& [name, scales] : level.scales) {
      const auto it = std::find_if(changed.parameters.begin(), changed.parameters.end(),
                                   [&parameter = name](const SensitivityParameter& p) { return p.name == parameter; });
      if (it == changed.parameters.end())
        throw InputError(SourceLocation{path, level.line}.prefix() + "reading '" + readings[r].name + "', level '" + level.name +
                         "': the design has no parameter '" + name + "'");
      it->scales = scales;
      it->scale_sources.assign(scales.size(), SourceLocation{path, level.line});
    }
  }
  return changed;
}

ReadingsPlan load_readings(const std::string& path) {
  const YAML::Node root = load_yaml_file(path, "readings file");
  if (!root.IsMap() || !root["reading_study"])
    yaml_error(path, root, "a readings file starts with 'reading_study: 1' and lists 'readings:' (see `railcrash readings --help`)");
  check_yaml_keys(path, root, {"reading_study", "description", "combinations", "readings"}, "readings file");
  if (!root["reading_study"].IsScalar() || root["reading_study"].Scalar() != "1")
    yaml_error(path, root["reading_study"], "reading_study must be 1");
  ReadingsPlan plan;
  plan.path = path;
  if (root["combinations"]) {
    const std::string how = scalar_text(path, root["combinations"], "combinations");
    if (how != "factorial" && how != "one_at_a_time")
      yaml_error(path, root["combinations"], "combinations must be factorial or one_at_a_time");
    plan.one_at_a_time = how == "one_at_a_time";
  }
  const YAML::Node list = root["readings"];
  if (!list || !list.IsSequence() || list.size() == 0)
    yaml_error(path, list ? list : root, "'readings' must list at least one reading: - {name, levels: [{name, set: {KEY: VALUE}}]}");
  std::set<std::string> names;
  for (const YAML::Node& node : list) {
    if (!node.IsMap()) yaml_error(path, node, "each reading is a map with name, description and levels");
    check_yaml_keys(path, node, {"name", "description", "levels"}, "reading");
    Reading reading;
    reading.name = scalar_text(path, node["name"], "reading: name");
    reading.line = yaml_line(node);
    if (!names.insert(reading.name).second) yaml_error(path, node["name"], "reading '" + reading.name + "' is listed twice");
    if (node["description"]) reading.description = node["description"].as<std::string>();
    const std::string context = "reading '" + reading.name + "'";
    const YAML::Node levels = node["levels"];
    if (!levels || !levels.IsSequence() || levels.size() == 0)
      yaml_error(path, levels ? levels : node, context + ": 'levels' must list at least one level {name, set: {KEY: VALUE}}");
    std::set<std::string> level_names;
    for (const YAML::Node& l : levels) {
      if (!l.IsMap()) yaml_error(path, l, context + ": each level is a map {name, set}");
      check_yaml_keys(path, l, {"name", "set", "scale"}, context + " level");
      ReadingLevel level;
      level.name = scalar_text(path, l["name"], context + ": level name");
      level.line = yaml_line(l);
      if (!level_names.insert(level.name).second) yaml_error(path, l["name"], context + ": level '" + level.name + "' is listed twice");
      if (const YAML::Node set = l["set"]) {
        if (!set.IsMap()) yaml_error(path, set, context + ", level '" + level.name + "': 'set' must map model keys to values");
        for (const auto& entry : set) {
          const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : "";
          if (key.empty()) yaml_error(path, entry.first, context + ": a key must be a model key such as elements.x.stiffness");
          if (!entry.second.IsDefined() || entry.second.IsNull())
            yaml_error(path, entry.first, context + ", level '" + level.name + "': give a value for '" + key + "'");
          // "elements.x.stiffness*: 1.2" becomes KEY*=FACTOR (a scaling), anything else KEY=VALUE.
          level.settings.push_back(key + "=" + YAML::Dump(entry.second));
        }
      }
      if (const YAML::Node scale = l["scale"]) {
        const std::string where = context + ", level '" + level.name + "': scale";
        if (!scale.IsMap()) yaml_error(path, scale, where + " must map parameters to lists of {key, power}");
        for (const auto& entry : scale) {
          const std::string parameter = scalar_text(path, entry.first, where + ": a parameter name");
          if (!entry.second.IsSequence() || entry.second.size() == 0)
            yaml_error(path, entry.second, where + ": " + parameter + " needs a list of {key, power}");
          std::vector<std::pair<std::string, double>> scales;
          for (const YAML::Node& item : entry.second) {
            if (!item.IsMap() || !item["key"]) yaml_error(path, item, where + ": each entry is {key: MODEL.KEY, power: P}");
            check_yaml_keys(path, item, {"key", "power"}, where);
            double power = 1.0;
            if (item["power"]) {
              try {
                power = item["power"].as<double>();
              } catch (const YAML::Exception&) {
                yaml_error(path, item["power"], where + ": power must be a number");
              }
            }
            scales.emplace_back(scalar_text(path, item["key"], where + ": key"), power);
          }
          level.scales.emplace_back(parameter, std::move(scales));
        }
      }
      reading.levels.push_back(std::move(level));
    }
    plan.readings.push_back(std::move(reading));
  }
  return plan;
}

bool check_readings(const ReadingsPlan& plan, const std::string& model_path, const std::atomic<bool>* stop) {
  const std::string text = read_model_text(model_path);
  const auto stopped = [stop] { return stop && stop->load(); };
  const std::optional<std::size_t> count = plan.combination_count();
  // (run_readings holds the study to --max-runs first; here only a count beyond std::size_t is refused)
  require_run_count(count, std::numeric_limits<std::size_t>::max(), plan.path + ": the readings' combinations");
  for (const Reading& reading : plan.readings)
    for (const ReadingLevel& level : reading.levels) {
      if (stopped()) return false;
      try {
        (void)load_model_text(text, model_path, level.settings);
      } catch (const InputError& e) {
        throw InputError(SourceLocation{plan.path, level.line}.prefix() + "reading '" + reading.name + "', level '" + level.name +
                         "' does not fit the model: " + e.what());
      }
    }
  for (std::size_t k = 0; k < *count; ++k) {
    if (stopped()) return false;
    const std::vector<int> combination = plan.combination(k);
    try {
      (void)load_model_text(text, model_path, plan.settings(combination));
    } catch (const InputError& e) {
      throw InputError(plan.path + ": the combination " + plan.label(combination) + " does not fit the model: " + e.what());
    }
  }
  return true;
}

namespace {

double response_of(const Responses& r, int k) { return k == 0 ? r.r1 : (k == 1 ? r.r2 : r.r3); }

}  // namespace

Agreement score_agreement(const SensitivityResult& result, const SensitivityDesign& design) {
  RAILCRASH_DEMAND(design.reference.has_value());
  const PublishedResults& published = *design.reference;
  Agreement agreement;
  for (int k = 0; k < 3; ++k) {
    ResponseAgreement& a = agreement.responses[static_cast<std::size_t>(k)];
    a.published = published.base[static_cast<std::size_t>(k)];
    a.value = result.base.ok ? response_of(result.base.responses, k) : kNaN;
    a.relative_error = (a.value - a.published) / a.published;
    std::vector<double> ours, theirs;
    const auto add = [&](const SensitivityRun& run, double published_value) {
      if (!run.ok || !result.base.ok) return;
      ours.push_back(response_of(run.responses, k) - a.value);
      theirs.push_back(published_value - a.published);
    };
    if (!result.central)
      for (const SensitivityRun& run : result.runs)
        for (const auto& [name, values] : published.first_order)
          if (name == run.parameter) add(run, values[static_cast<std::size_t>(k)]);
    const ChangeScores first = score_changes(ours, theirs);
    a.significant_runs = first.significant;
    a.sign_agreements = first.agree;
    a.spearman = first.spearman;
    a.rms = first.rms;
    for (std::size_t j = 0; j < result.second_order_runs.size() && j < published.second_order.size(); ++j)
      add(result.second_order_runs[j], published.second_order[j][static_cast<std::size_t>(k)]);
    const ChangeScores all = score_changes(ours, theirs);
    a.significant_runs_all = all.significant;
    a.sign_agreements_all = all.agree;
    a.spearman_all = all.spearman;
    a.rms_all = all.rms;
    // Our top five by |first-order coefficient| (ties: design order).
    std::vector<std::size_t> order(result.derivatives.size());
    std::iota(order.begin(), order.end(), 0);
    const auto magnitude = [&](std::size_t i) {
      const double d = result.derivatives[i][static_cast<std::size_t>(k)];
      return std::isnan(d) ? -1.0 : std::abs(d);
    };
    std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return magnitude(x) > magnitude(y); });
    const std::size_t per_parameter = result.central ? 2 : 1;
    for (std::size_t i = 0; i < order.size() && a.top_five.size() < 5; ++i)
      a.top_five.push_back(result.runs[per_parameter * order[i]].parameter);
    const auto& ranking = published.ranking[static_cast<std::size_t>(k)];
    if (!ranking.empty()) {
      a.top_five_shared = 0;
      for (std::size_t i = 0; i < ranking.size() && i < 5; ++i)
        a.top_five_shared += std::count(a.top_five.begin(), a.top_five.end(), ranking[i]) > 0 ? 1 : 0;
    }
  }
  const auto goal = [&](bool met, const std::string& what) {
    if (met) ++agreement.goals_met;
    else agreement.goals_missed.push_back(what);
  };
  const auto& r = agreement.responses;
  goal(std::abs(r[1].relative_error) <= 0.10, "R2 run 0 within 10 %");
  goal(std::abs(r[2].relative_error) <= 0.05, "R3 run 0 within 5 %");
  for (int k = 0; k < 2; ++k) {
    const std::string name = "R" + std::to_string(k + 1);
    goal(r[static_cast<std::size_t>(k)].significant_runs > 0 && r[static_cast<std::size_t>(k)].sign_share() >= 0.8,
         name + " signs >= 80 %");
    goal(r[static_cast<std::size_t>(k)].spearman >= 0.7, name + " Spearman >= 0.7");
    goal(r[static_cast<std::size_t>(k)].top_five_shared >= 4, name + " top five >= 4 of 5");
  }
  double score = 0.0;
  for (int k = 0; k < 2; ++k) {
    const ResponseAgreement& a = r[static_cast<std::size_t>(k)];
    score += a.sign_share() + (std::isnan(a.spearman) ? 0.0 : a.spearman) + std::max(0, a.top_five_shared) / 5.0;
  }
  const double e2 = std::isnan(r[1].relative_error) ? 10.0 : std::abs(r[1].relative_error);
  const double e3 = std::isnan(r[2].relative_error) ? 10.0 : std::abs(r[2].relative_error);
  agreement.score = score - e2 / 0.10 - e3 / 0.05;
  return agreement;
}

namespace {

/// The first-order comparison split by branch (issue 40): the runs on run 0's branch, the runs
/// across a change of the discrete outcome, and all of them with the effect within run 0's
/// branch (from the bisection, scaled to the design's step) in place of the change across.
std::string branch_comparison_markdown(const SensitivityResult& result, const SensitivityDesign& design) {
  const PublishedResults& published = *design.reference;
  if (result.central || !result.base.ok) return "";
  const double step = design.factor - 1.0;
  std::array<std::vector<double>, 3> on_ours, on_theirs, across_ours, across_theirs, within_ours, within_theirs;
  std::string across_names;
  for (std::size_t i = 0; i < result.runs.size(); ++i) {
    const SensitivityRun& run = result.runs[i];
    if (!run.ok) continue;
    const std::array<double, 3>* theirs = nullptr;
    for (const auto& [name, values] : published.first_order)
      if (name == run.parameter) theirs = &values;
    if (!theirs) continue;
    const bool on = same_branch(run.outcomes, result.base.outcomes);
    const BranchChange* change = nullptr;
    for (const BranchChange& c : result.branch_changes)
      if (c.run == i) change = &c;
    if (!on) across_names += (across_names.empty() ? "" : ", ") + run.parameter;
    for (std::size_t k = 0; k < 3; ++k) {
      const double ours = response_of(run.responses, static_cast<int>(k)) - response_of(result.base.responses, static_cast<int>(k));
      const double their = (*theirs)[k] - published.base[k];
      (on ? on_ours : across_ours)[k].push_back(ours);
      (on ? on_theirs : across_theirs)[k].push_back(their);
      const double within = on ? ours : (change ? change->within_branch[k] * step : kNaN);
      if (!std::isnan(within)) {
        within_ours[k].push_back(within);
        within_theirs[k].push_back(their);
      }
    }
  }
  std::ostringstream md;
  md << "## By branch of the discrete outcome (issue 40)\n\n"
     << "Run 0's outcome: `" << result.base.outcomes.text() << "`. First-order runs across a change of it: "
     << (across_names.empty() ? std::string("none") : across_names) << " (" << across_ours[0].size() << " of "
     << across_ours[0].size() + on_ours[0].size()
     << " compared). The last rows put, for each run across a change, the effect within run 0's branch (the bisection's "
        "dR/dP times the step " << format(step, "%g") << ") in place of its change.\n\n"
     << "| | R1 | R2 | R3 |\n|---|---|---|---|\n";
  const auto rows = [&](const std::string& label, const std::array<std::vector<double>, 3>& ours,
                        const std::array<std::vector<double>, 3>& theirs) {
    std::array<ChangeScores, 3> scores;
    for (std::size_t k = 0; k < 3; ++k) scores[k] = score_changes(ours[k], theirs[k]);
    md << "| " << label << ": published sign kept (change >= 0.005)";
    for (const ChangeScores& c : scores) md << " | " << c.agree << " of " << c.significant;
    md << " |\n| " << label << ": Spearman rho (" << ours[0].size() << " runs)";
    for (const ChangeScores& c : scores) md << " | " << format(c.spearman, "%.2f");
    md << " |\n";
  };
  rows("on run 0's branch", on_ours, on_theirs);
  rows("across a change", across_ours, across_theirs);
  rows("all, within-branch effect", within_ours, within_theirs);
  md << "\n";
  return md.str();
}

}  // namespace

std::string comparison_markdown(const SensitivityResult& result, const SensitivityDesign& design) {
  RAILCRASH_DEMAND(design.reference.has_value());
  const PublishedResults& published = *design.reference;
  const Agreement agreement = score_agreement(result, design);
  std::ostringstream md;
  md << "## Agreement with the published study\n\n"
     << (published.source.empty() ? std::string() : "Published: " + published.source + ".\n\n")
     << "| | R1 | R2 | R3 |\n|---|---|---|---|\n";
  const auto row = [&](const std::string& label, const std::function<std::string(const ResponseAgreement&)>& cell) {
    md << "| " << label;
    for (const ResponseAgreement& a : agreement.responses) md << " | " << cell(a);
    md << " |\n";
  };
  row("run 0, ours", [](const ResponseAgreement& a) { return format(a.value); });
  row("run 0, published", [](const ResponseAgreement& a) { return format(a.published); });
  row("run 0, relative error", [](const ResponseAgreement& a) { return format(100.0 * a.relative_error, "%+.1f %%"); });
  row("first-order runs: published sign kept (change >= 0.005)",
      [](const ResponseAgreement& a) { return std::to_string(a.sign_agreements) + " of " + std::to_string(a.significant_runs); });
  row("first-order runs: Spearman rho of the changes", [](const ResponseAgreement& a) { return format(a.spearman, "%.2f"); });
  row("first-order runs: RMS of the change differences", [](const ResponseAgreement& a) { return format(a.rms, "%.4f"); });
  row("all runs: published sign kept",
      [](const ResponseAgreement& a) { return std::to_string(a.sign_agreements_all) + " of " + std::to_string(a.significant_runs_all); });
  row("all runs: Spearman rho", [](const ResponseAgreement& a) { return format(a.spearman_all, "%.2f"); });
  row("all runs: RMS", [](const ResponseAgreement& a) { return format(a.rms_all, "%.4f"); });
  row("our top five (by first-order coefficient)", [](const ResponseAgreement& a) {
    std::string top;
    for (const auto& p : a.top_five) top += (top.empty() ? "" : " ") + p;
    return top;
  });
  row("published top five in ours",
      [](const ResponseAgreement& a) { return a.top_five_shared < 0 ? std::string("-") : std::to_string(a.top_five_shared) + " of 5"; });
  std::string missed;
  for (const auto& g : agreement.goals_missed) missed += (missed.empty() ? "" : "; ") + g;
  md << "\nGoals met: " << agreement.goals_met << " of " << Agreement::kGoals << (missed.empty() ? "" : " (missed: " + missed + ")")
     << ".\n\n";
  md << branch_comparison_markdown(result, design);

  // Every run against the published one.
  md << "## Runs: ours against the published (changes against run 0)\n\n"
     << "| run | varied | R1 | published | R2 | published | R3 | published | dR1 | published | dR2 | published |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  const auto run_row = [&](const std::string& number, const SensitivityRun& run, const std::array<double, 3>& theirs) {
    std::string varied;
    for (const auto& [name, value] : run.variation) varied += (varied.empty() ? "" : ", ") + name + " = " + format(value, "%g");
    md << "| " << number << " | " << (varied.empty() ? "none" : varied);
    const std::array<double, 3> ours = {run.responses.r1, run.responses.r2, run.responses.r3};
    for (std::size_t k = 0; k < 3; ++k) md << " | " << (run.ok ? format(ours[k]) : "failed") << " | " << format(theirs[k]);
    for (std::size_t k = 0; k < 2; ++k) {
      const double mine = run.ok && result.base.ok ? ours[k] - agreement.responses[k].value : kNaN;
      const double their = theirs[k] - published.base[k];
      const bool significant = std::abs(their) >= kSignificantChange - 1e-9;
      md << " | " << format(mine, "%+.4f") << " | " << format(their, "%+.3f")
         << (significant ? (mine * their > 0.0 ? " (sign kept)" : " (**sign differs**)") : "");
    }
    md << " |\n";
  };
  run_row("0", result.base, published.base);
  int number = 0;
  for (const SensitivityRun& run : result.runs) {
    ++number;
    for (const auto& [name, values] : published.first_order)
      if (name == run.parameter && !result.central) run_row(std::to_string(number), run, values);
  }
  for (std::size_t j = 0; j < result.second_order_runs.size() && j < published.second_order.size(); ++j)
    run_row(std::to_string(++number), result.second_order_runs[j], published.second_order[j]);

  // Rankings.
  if (!result.central) {
    std::vector<std::array<double, 3>> theirs(result.runs.size(), {kNaN, kNaN, kNaN});
    for (std::size_t i = 0; i < result.runs.size(); ++i)
      for (const auto& [name, values] : published.first_order)
        if (name == result.runs[i].parameter)
          for (std::size_t k = 0; k < 3; ++k) theirs[i][k] = (values[k] - published.base[k]) / (design.factor - 1.0);
    for (std::size_t k = 0; k < 3; ++k) {
      const auto& ranking = published.ranking[k];
      if (ranking.empty()) continue;
      std::vector<std::size_t> order(result.runs.size());
      std::iota(order.begin(), order.end(), 0);
      const auto magnitude = [&](std::size_t i) { return std::isnan(result.derivatives[i][k]) ? -1.0 : std::abs(result.derivatives[i][k]); };
      std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return magnitude(a) > magnitude(b); });
      md << "\n## R" << k + 1 << ": the published ranking against ours\n\n"
         << "| published rank | parameter | published dR/dP | ours | our rank | sign |\n|---|---|---|---|---|---|\n";
      for (std::size_t rank = 0; rank < ranking.size(); ++rank) {
        std::size_t i = 0;
        while (i < result.runs.size() && result.runs[i].parameter != ranking[rank]) ++i;
        if (i == result.runs.size()) continue;
        const std::size_t our_rank = static_cast<std::size_t>(std::find(order.begin(), order.end(), i) - order.begin()) + 1;
        const double mine = result.derivatives[i][k], their = theirs[i][k];
        md << "| " << rank + 1 << " | " << ranking[rank] << " | " << format(their, "%+.3f") << " | " << format(mine, "%+.3f") << " | "
           << our_rank << " | " << (std::abs(mine) < 0.0005 ? "ours 0.000" : (mine * their > 0.0 ? "same" : "**differs**")) << " |\n";
      }
    }
  }

  // Second-order derivatives: ours and the published runs' through the same fit.
  if (!result.fit.terms.empty() && published.second_order.size() == design.second_order.runs.size()) {
    std::vector<SensitivitySample> samples{{"run 0", {}, published.base}};
    std::vector<std::string> term_parameters;
    for (const SensitivityTerm& t : result.fit.terms) {
      term_parameters.push_back(t.first);
      if (!t.linear()) term_parameters.push_back(t.second);
    }
    const auto in_form = [&](const std::string& name) {
      return std::find(term_parameters.begin(), term_parameters.end(), name) != term_parameters.end();
    };
    for (const auto& [name, values] : published.first_order)
      if (in_form(name)) samples.push_back({name, {{name, design.factor}}, values});
    for (std::size_t j = 0; j < published.second_order.size(); ++j) {
      const SensitivityPoint& point = design.second_order.runs[j];
      if (std::all_of(point.begin(), point.end(), [&](const auto& e) { return in_form(e.first); }))
        samples.push_back({"second order " + std::to_string(j + 1), point, published.second_order[j]});
    }
    const QuadraticFit theirs = fit_quadratic(result.fit.terms, samples);
    md << "\n## Derivatives at P = 1 of the second-order form: ours and the published runs' (same fit)\n\n"
       << "| derivative | R1 ours | R1 published | R2 ours | R2 published | R3 ours | R3 published |\n|---|---|---|---|---|---|---|\n";
    for (std::size_t d = 0; d < result.fit.derivatives.size() && d < theirs.derivatives.size(); ++d) {
      md << "| " << result.fit.derivatives[d].label();
      for (std::size_t k = 0; k < 3; ++k)
        md << " | " << format(result.fit.derivatives[d].value[k], "%+.3f") << " | " << format(theirs.derivatives[d].value[k], "%+.3f");
      md << " |\n";
    }
  }
  return md.str();
}

std::vector<ReadingsCombinationResult> run_readings(const std::string& model_path, const SensitivityDesign& design,
                                                    const ReadingsPlan& plan, const ReadingsOptions& options) {
  if (!design.reference)
    throw InputError("the design has no 'reference' section (the published results to score against); add one, as "
                     "models/report/sensitivity_design.yaml does");
  // The study's size before anything is generated: combinations x runs per combination (the
  // combinations change the parameters' scalings, never their number).
  const std::optional<std::size_t> combination_count = plan.combination_count();
  const std::size_t runs_each = sensitivity_run_count(design, options.study);
  require_run_count(multiply_counts(combination_count, runs_each), options.study.max_runs,
                    plan.path + ": " + (combination_count ? std::to_string(*combination_count) : "more than " + std::to_string(std::numeric_limits<std::size_t>::max())) +
                        " combinations of the readings x " + std::to_string(runs_each) + " runs each");
  const std::atomic<bool>* stop = options.study.stop;
  const auto stopped = [stop] { return stop && stop->load(); };
  if (!check_readings(plan, model_path, stop)) return {};  // interrupted while checking: no run started
  const std::size_t combinations = *combination_count;
  // Every combination's runs are checked before the first run starts (the first combination's
  // run by run, the others with all their factors at once: check_sensitivity_inputs), and the
  // checks stop when the study is interrupted.
  const CheckedYamlText model_text = check_model_text(read_model_text(model_path), model_path);
  for (std::size_t c = 0; c < combinations; ++c) {
    if (stopped()) return {};
    const std::vector<int> combination = plan.combination(c);
    SensitivityOptions study = options.study;
    study.settings = plan.settings(combination);
    try {
      check_sensitivity_inputs(model_text, model_path, plan.design_for(combination, design), study, c == 0);
    } catch (const InputError& e) {
      throw InputError(e.what() + std::string(" (readings ") + plan.path + ", combination " + plan.label(combination) + ")");
    }
  }
  std::vector<ReadingsCombinationResult> results;
  for (std::size_t c = 0; c < combinations; ++c) {
    if (stopped()) break;
    const auto start = std::chrono::steady_clock::now();
    ReadingsCombinationResult r;
    r.levels = plan.combination(c);
    SensitivityOptions study = options.study;
    study.settings = plan.settings(r.levels);
    study.branch_bisections = 0;  // many studies: runs off run 0's branch are flagged, not bisected (issue 40)
    const SensitivityDesign combination_design = plan.design_for(r.levels, design);
    r.study = run_sensitivity(model_path, combination_design, study);
    r.agreement = score_agreement(r.study, combination_design);
    r.failed_runs = r.study.base.ok || r.study.base.interrupted ? 0 : 1;
    for (const auto& run : r.study.runs) r.failed_runs += run.ok || run.interrupted ? 0 : 1;
    for (const auto& run : r.study.second_order_runs) r.failed_runs += run.ok || run.interrupted ? 0 : 1;
    r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (options.progress) options.progress(r, c, combinations);
    const bool interrupted = r.study.interrupted;
    results.push_back(std::move(r));
    if (interrupted) break;
  }
  return results;
}

namespace {

/// A combination's runs' methods for readings.csv: the methods its runs used ("ida", "euler",
/// "ida+euler", "ida+euler+ida" in that order, joined by spaces), the earliest hand-over to
/// Euler and how many runs were handed over (whether or not IDA took them back).
struct CombinationIntegrators {
  std::string methods;
  IntegratorUsed earliest;
  std::size_t handed_over_runs = 0;
};

CombinationIntegrators combination_integrators(const SensitivityResult& study) {
  CombinationIntegrators used;
  constexpr int kMethods = 4;
  const char* names[kMethods] = {integrator_name(IntegratorKind::Ida), integrator_name(IntegratorKind::Euler),
                                 kIdaThenEulerMethod, kIdaEulerIdaMethod};
  bool seen[kMethods] = {false, false, false, false};
  const auto add = [&](const SensitivityRun& run) {
    const std::string& method = run.integrator.method;
    for (int k = 0; k < kMethods; ++k) seen[k] = seen[k] || method == names[k];
    if (method != kIdaThenEulerMethod && method != kIdaEulerIdaMethod) return;
    ++used.handed_over_runs;
    if (std::isnan(used.earliest.euler_from_t) || run.integrator.euler_from_t < used.earliest.euler_from_t) used.earliest = run.integrator;
  };
  add(study.base);
  for (const SensitivityRun& run : study.runs) add(run);
  for (const SensitivityRun& run : study.second_order_runs) add(run);
  for (int k = 0; k < kMethods; ++k)
    if (seen[k]) used.methods += (used.methods.empty() ? "" : " ") + std::string(names[k]);
  return used;
}

}  // namespace

std::string write_readings(const std::vector<ReadingsCombinationResult>& results, const ReadingsPlan& plan,
                           const SensitivityDesign& design, const std::string& directory) {
  std::filesystem::create_directories(directory);
  std::vector<std::size_t> order(results.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const Agreement& x = results[a].agreement;
    const Agreement& y = results[b].agreement;
    return x.goals_met != y.goals_met ? x.goals_met > y.goals_met : x.score > y.score;
  });
  char folder[48];
  const auto folder_of = [&](std::size_t c) {
    std::snprintf(folder, sizeof folder, "combination_%03zu", c);
    return std::string(folder);
  };

  std::ostringstream csv;
  csv << "rank,combination";
  for (const Reading& r : plan.readings) csv << "," << csv_text(r.name);
  for (int k = 1; k <= 3; ++k)
    csv << ",R" << k << ",R" << k << "_error,R" << k << "_sign_runs,R" << k << "_sign_agree,R" << k << "_spearman,R" << k
        << "_rms,R" << k << "_sign_runs_all,R" << k << "_sign_agree_all,R" << k << "_spearman_all,R" << k << "_rms_all,R" << k
        << "_top5_shared,R" << k << "_top5";
  csv << ",goals_met,score,failed_runs,wall_seconds,integrator_used,euler_from_t,handed_over_runs\n";
  for (std::size_t rank = 0; rank < order.size(); ++rank) {
    const ReadingsCombinationResult& r = results[order[rank]];
    csv << rank + 1 << "," << order[rank];
    for (std::size_t i = 0; i < plan.readings.size(); ++i)
      csv << "," << csv_text(plan.readings[i].levels[static_cast<std::size_t>(r.levels[i])].name);
    for (const ResponseAgreement& a : r.agreement.responses) {
      std::string top;
      for (const auto& p : a.top_five) top += (top.empty() ? "" : " ") + p;
      csv << "," << csv_field(a.value) << "," << csv_field(a.relative_error) << "," << a.significant_runs << "," << a.sign_agreements
          << "," << csv_field(a.spearman) << "," << csv_field(a.rms) << "," << a.significant_runs_all << "," << a.sign_agreements_all
          << "," << csv_field(a.spearman_all) << "," << csv_field(a.rms_all) << "," << a.top_five_shared << "," << csv_text(top);
    }
    const CombinationIntegrators used = combination_integrators(r.study);
    csv << "," << r.agreement.goals_met << "," << csv_field(r.agreement.score) << "," << r.failed_runs << ","
        << format(r.wall_seconds, "%.1f") << "," << used.methods << "," << used.earliest.euler_from_t_text() << ","
        << used.handed_over_runs << "\n";
  }
  write_whole_file((std::filesystem::path(directory) / "readings.csv").string(), csv.str());

  std::ostringstream md;
  md << "# Reading study\n\n";
  const std::size_t planned = plan.combination_count().value_or(0);
  const std::size_t complete = static_cast<std::size_t>(std::count_if(
      results.begin(), results.end(), [](const ReadingsCombinationResult& r) { return !r.study.interrupted; }));
  if (complete < planned)
    md << "**Interrupted after " << complete << " of " << planned << " combinations** (SIGINT/SIGTERM)"
       << (complete < results.size() ? "; the last one listed is partial (its unfinished runs count as failed)" : "") << ".\n\n";
  md
     << "Readings file `" << plan.path << "`, " << results.size() << " combinations ("
     << (plan.one_at_a_time ? "one at a time" : "factorial") << "), each scored against the design's published results"
     << (design.reference && !design.reference->source.empty() ? " (" + design.reference->source + ")" : std::string()) << ".\n\n"
     << "Columns: run 0's R1-R3 (relative error against the published run 0); for R1 and R2 over the first-order runs: "
        "sign agreement among the runs whose published change is at least 0.005, Spearman's rho of the changes, and how many of "
        "the published top five (Tables 15-17) are in ours; goals met of "
     << Agreement::kGoals << " (R2 within 10 %, R3 within 5 %, signs >= 80 %, rho >= 0.7, top five >= 4). Ranked by goals met, "
        "then by the score (include/railcrash/studies/readings.hpp).\n\n";
  md << "| rank | #";
  for (const Reading& r : plan.readings) md << " | " << r.name;
  md << " | R1 | R2 | R3 | R1 signs | R1 rho | R1 top 5 | R2 signs | R2 rho | R2 top 5 | R3 rho | goals | score | failed |\n|";
  for (std::size_t i = 0; i < plan.readings.size() + 17; ++i) md << "---|";
  md << "\n";
  for (std::size_t rank = 0; rank < order.size(); ++rank) {
    const ReadingsCombinationResult& r = results[order[rank]];
    const auto& a = r.agreement.responses;
    md << "| " << rank + 1 << " | " << order[rank];
    for (std::size_t i = 0; i < plan.readings.size(); ++i) md << " | " << plan.readings[i].levels[static_cast<std::size_t>(r.levels[i])].name;
    for (int k = 0; k < 3; ++k)
      md << " | " << format(a[static_cast<std::size_t>(k)].value) << " (" << format(100.0 * a[static_cast<std::size_t>(k)].relative_error, "%+.1f")
         << " %)";
    for (int k = 0; k < 2; ++k) {
      const ResponseAgreement& x = a[static_cast<std::size_t>(k)];
      md << " | " << x.sign_agreements << "/" << x.significant_runs << " | " << format(x.spearman, "%.2f") << " | "
         << x.top_five_shared << "/5";
    }
    md << " | " << format(a[2].spearman, "%.2f") << " | " << r.agreement.goals_met << "/" << Agreement::kGoals << " | "
       << format(r.agreement.score, "%.2f") << " | " << r.failed_runs << " |\n";
  }
  // How much each reading decided: the best combination with each of its levels.
  if (!results.empty()) {
    md << "\nHow much each reading decided: the best combination with each level (goals met, score; "
          "with the R2 and R3 errors of run 0 and the rank correlations of that combination).\n\n"
       << "| reading | level | best combination | goals | score | R2 | R3 | R1 rho | R2 rho |\n|---|---|---|---|---|---|---|---|---|\n";
    for (std::size_t r = 0; r < plan.readings.size(); ++r)
      for (std::size_t l = 0; l < plan.readings[r].levels.size(); ++l) {
        const auto it = std::find_if(order.begin(), order.end(),
                                     [&](std::size_t c) { return results[c].levels[r] == static_cast<int>(l); });
        if (it == order.end()) continue;
        const ReadingsCombinationResult& best = results[*it];
        const auto& a = best.agreement.responses;
        md << "| " << plan.readings[r].name << " | " << plan.readings[r].levels[l].name << " | " << *it << " | "
           << best.agreement.goals_met << "/" << Agreement::kGoals << " | " << format(best.agreement.score, "%.2f") << " | "
           << format(100.0 * a[1].relative_error, "%+.1f %%") << " | " << format(100.0 * a[2].relative_error, "%+.1f %%") << " | "
           << format(a[0].spearman, "%.2f") << " | " << format(a[1].spearman, "%.2f") << " |\n";
      }
  }
  md << "\nReadings and levels:\n\n";
  for (const Reading& r : plan.readings) {
    md << "- **" << r.name << "**" << (r.description.empty() ? "" : ": " + r.description) << "\n";
    for (const ReadingLevel& l : r.levels) {
      std::string changes;
      for (const auto& s : l.settings) changes += (changes.empty() ? "" : ", ") + std::string("`") + s.substr(0, s.find_last_not_of("\n") + 1) + "`";
      for (const auto& [parameter, scales] : l.scales) {
        std::string how;
        for (const auto& [key, power] : scales) how += (how.empty() ? "" : " and ") + key + "^" + format(power, "%g");
        changes += (changes.empty() ? "" : ", ") + parameter + " scales " + how;
      }
      md << "  - " << l.name << ": " << (changes.empty() ? "the model as it is" : changes) << "\n";
    }
  }
  if (!results.empty()) {
    const ReadingsCombinationResult& best = results[order.front()];
    md << "\nBest combination (" << order.front() << "): " << plan.label(best.levels) << "; top five R1 ";
    for (const auto& p : best.agreement.responses[0].top_five) md << p << " ";
    md << "/ R2 ";
    for (const auto& p : best.agreement.responses[1].top_five) md << p << " ";
    md << "/ R3 ";
    for (const auto& p : best.agreement.responses[2].top_five) md << p << " ";
    md << "; goals missed: ";
    std::string missed;
    for (const auto& g : best.agreement.goals_missed) missed += (missed.empty() ? "" : "; ") + g;
    md << (missed.empty() ? "none" : missed) << ".\n";
  }
  const std::string text = md.str();
  write_whole_file((std::filesystem::path(directory) / "readings.md").string(), text);
  for (std::size_t c = 0; c < results.size(); ++c) {
    const SensitivityDesign combination_design = plan.design_for(results[c].levels, design);
    const std::filesystem::path run_folder = std::filesystem::path(directory) / folder_of(c);
    write_sensitivity(results[c].study, combination_design, run_folder.string());
    if (!results[c].study.base.ok || results[c].study.central) continue;
    write_whole_file((run_folder / "comparison.md").string(), "# " + plan.label(results[c].levels) +
                                                                ": the study against the published results\n\n" +
                                                                comparison_markdown(results[c].study, combination_design));
  }
  return text;
}

}  // namespace railcrash
