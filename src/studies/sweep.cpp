#include "railcrash/studies/sweep.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>

#include "railcrash/core/error.hpp"
#include "railcrash/core/folder_lock.hpp"
#include "railcrash/core/table_text.hpp"
#include "railcrash/core/version.hpp"
#include "railcrash/core/whole_file.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/model/yaml_file.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/studies/batch.hpp"
#include "railcrash/studies/run_count.hpp"

namespace railcrash {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();


/// The shortest of %.15g, %.16g, %.17g that reads back as the same double.
std::string exact(double value) {
  char text[40];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  return text;
}

/// A level as the YAML text of a --set value: a scalar as written, a list in flow style.
std::string level_text(const std::string& path, const YAML::Node& node, const std::string& context) {
  if (node.IsScalar()) return node.Scalar();
  if (node.IsSequence()) {
    std::string text = "[";
    for (std::size_t i = 0; i < node.size(); ++i) text += (i ? ", " : "") + level_text(path, node[i], context);
    return text + "]";
  }
  yaml_error(path, node, context + ": a level is a number, a word or a list of them, not a map");
}

double plan_number(const std::string& path, const YAML::Node& node, const std::string& context) {
  try {
    return node.as<double>();
  } catch (const YAML::Exception&) {
    yaml_error(path, node, context + " must be a number");
  }
}

SweepDesignKind design_kind(const std::string& path, const YAML::Node& node) {
  const std::string name = node.IsScalar() ? node.Scalar() : "";
  if (name == "full_factorial") return SweepDesignKind::full_factorial;
  if (name == "one_at_a_time") return SweepDesignKind::one_at_a_time;
  if (name == "latin_hypercube") return SweepDesignKind::latin_hypercube;
  if (name == "monte_carlo") return SweepDesignKind::monte_carlo;
  if (name == "runs") return SweepDesignKind::runs;
  yaml_error(path, node, "design '" + name + "': use full_factorial, one_at_a_time, latin_hypercube, monte_carlo or runs");
}

bool sampled(SweepDesignKind kind) {
  return kind == SweepDesignKind::latin_hypercube || kind == SweepDesignKind::monte_carlo;
}

SweepDistribution load_distribution(const std::string& path, const YAML::Node& node, const std::string& context) {
  if (!node.IsMap() || node.size() != 1)
    yaml_error(path, node, context + ": write the distribution as {uniform: [lower, upper]} or {normal: [mean, sd]}");
  const std::string kind = node.begin()->first.as<std::string>();
  const YAML::Node values = node.begin()->second;
  if ((kind != "uniform" && kind != "normal") || !values.IsSequence() || values.size() != 2)
    yaml_error(path, node, context + ": write the distribution as {uniform: [lower, upper]} or {normal: [mean, sd]}");
  SweepDistribution d;
  d.kind = kind == "uniform" ? SweepDistribution::Kind::uniform : SweepDistribution::Kind::normal;
  d.first = plan_number(path, values[0], context + ": " + kind + "'s first value");
  d.second = plan_number(path, values[1], context + ": " + kind + "'s second value");
  if (d.kind == SweepDistribution::Kind::uniform && !(d.second > d.first))
    yaml_error(path, values, context + ": uniform needs lower < upper");
  if (d.kind == SweepDistribution::Kind::normal && !(d.second > 0.0))
    yaml_error(path, values, context + ": normal needs a positive standard deviation");
  return d;
}

/// The setting a factor at one level makes: KEY=LEVEL or KEY*=LEVEL. KEY[i] (an entry of a
/// list) is the model's own KEY[i] setting: each run starts from the model, takes the plan's
/// settings and then each factor's in turn, so two entries of one list and a plan's setting of
/// the list keep one another, and a scaled entry that is 0 is refused as a scaled key is.
std::string factor_setting(const SweepFactor& factor, const std::string& level) {
  return factor.key + (factor.scale ? "*=" : "=") + level;
}

std::uint64_t fnv1a(const std::string& text, std::uint64_t hash = 14695981039346656037ull) {
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  return hash;
}

/// A CSV field: as is, or quoted when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& text) {
  return text.find_first_of(",\"\n") == std::string::npos ? text : csv_text(text);
}

}  // namespace

// ---------------------------------------------------------------- generators

double SweepDistribution::value_at(double probability) const {
  if (kind == Kind::uniform) return first + (second - first) * probability;
  return first + second * normal_quantile(probability);
}

double normal_quantile(double probability) {
  RAILCRASH_DEMAND(probability > 0.0 && probability < 1.0);
  // Phi(x) = erfc(-x / sqrt 2) / 2 rises monotonically; bisection on [-40, 40] to 2^-60 of it.
  double low = -40.0, high = 40.0;
  for (int k = 0; k < 67; ++k) {
    const double middle = 0.5 * (low + high);
    if (0.5 * std::erfc(-middle / std::sqrt(2.0)) < probability) low = middle;
    else high = middle;
  }
  return 0.5 * (low + high);
}

double unit_uniform(std::mt19937_64& generator) {
  // 52 bits, so that k + 0.5 and the quotient are exact: u lies in [2^-53, 1 - 2^-53].
  const std::uint64_t top = generator() >> 12;
  return (static_cast<double>(top) + 0.5) / 4503599627370496.0;  // 2^52
}

std::vector<std::vector<std::size_t>> full_factorial(const std::vector<std::size_t>& level_counts) {
  std::size_t total = level_counts.empty() ? 0 : 1;
  for (std::size_t n : level_counts) total *= n;
  std::vector<std::vector<std::size_t>> rows(total, std::vector<std::size_t>(level_counts.size()));
  for (std::size_t r = 0; r < total; ++r) {
    std::size_t rest = r;
    for (std::size_t f = level_counts.size(); f-- > 0;) {  // the last factor changes fastest
      rows[r][f] = rest % level_counts[f];
      rest /= level_counts[f];
    }
  }
  return rows;
}

std::vector<std::vector<long>> one_at_a_time(const std::vector<std::size_t>& level_counts) {
  const std::vector<long> base(level_counts.size(), -1);
  std::vector<std::vector<long>> rows{base};
  for (std::size_t f = 0; f < level_counts.size(); ++f)
    for (std::size_t j = 0; j < level_counts[f]; ++j) {
      rows.push_back(base);
      rows.back()[f] = static_cast<long>(j);
    }
  return rows;
}

std::vector<std::vector<double>> latin_hypercube(std::size_t samples, std::size_t factors, std::uint64_t seed) {
  std::mt19937_64 generator(seed);
  std::vector<std::vector<double>> rows(samples, std::vector<double>(factors));
  std::vector<std::size_t> strata(samples);
  for (std::size_t f = 0; f < factors; ++f) {
    std::iota(strata.begin(), strata.end(), std::size_t{0});
    // Fisher-Yates with this file's own draws (std::shuffle's use of the generator is not specified).
    for (std::size_t i = samples; i > 1; --i) {
      const auto j = static_cast<std::size_t>(unit_uniform(generator) * static_cast<double>(i));
      std::swap(strata[i - 1], strata[std::min(j, i - 1)]);
    }
    // (k + u) / N can round up to 1 in the last stratum: keep it below.
    for (std::size_t s = 0; s < samples; ++s)
      rows[s][f] = std::min((static_cast<double>(strata[s]) + unit_uniform(generator)) / static_cast<double>(samples),
                            std::nextafter(1.0, 0.0));
  }
  return rows;
}

std::vector<std::vector<double>> monte_carlo(std::size_t samples, std::size_t factors, std::uint64_t seed) {
  std::mt19937_64 generator(seed);
  std::vector<std::vector<double>> rows(samples, std::vector<double>(factors));
  for (auto& row : rows)
    for (double& u : row) u = unit_uniform(generator);
  return rows;
}

// ---------------------------------------------------------------- plan

SweepPlan load_sweep_plan(const std::string& path, const std::string& model_path) {
  const YAML::Node root = load_yaml_file(path, "plan file");
  if (!root.IsMap() || !root["sweep"]) yaml_error(path, root, "a plan file starts with 'sweep: 1'");
  static const std::vector<std::string> kKeys{"sweep", "design", "samples", "seed", "set", "factors", "runs", "responses"};
  check_yaml_keys(path, root, kKeys, "plan");
  SweepPlan plan;
  plan.path = path;
  if (!root["design"]) yaml_error(path, root, "give a design: full_factorial, one_at_a_time, latin_hypercube, monte_carlo or runs");
  plan.design = design_kind(path, root["design"]);
  plan.design_line = yaml_line(root["design"]);
  if (sampled(plan.design)) {
    if (!root["samples"]) yaml_error(path, root["design"], "a sampled design needs 'samples: N' (N > 0)");
    const double samples = plan_number(path, root["samples"], "samples");
    if (!(samples >= 1.0) || samples != std::floor(samples))
      yaml_error(path, root["samples"], "samples must be a whole number of runs, at least 1 (the design is empty)");
    plan.samples = static_cast<std::size_t>(samples);
    if (root["seed"]) {
      const double seed = plan_number(path, root["seed"], "seed");
      if (!(seed >= 0.0) || seed != std::floor(seed) || seed > 9.0e15) yaml_error(path, root["seed"], "seed must be a whole number >= 0");
      plan.seed = static_cast<std::uint64_t>(seed);
    }
  }
  if (const YAML::Node set = root["set"]) {
    if (!set.IsSequence()) yaml_error(path, set, "set is a list of KEY=VALUE or KEY*=FACTOR settings");
    for (const YAML::Node& setting : set) {
      if (!setting.IsScalar()) yaml_error(path, setting, "set: write each setting as KEY=VALUE or KEY*=FACTOR");
      plan.settings.push_back(setting.Scalar());
    }
  }
  const YAML::Node factors = root["factors"];
  if (!factors || !factors.IsSequence() || factors.size() == 0)
    yaml_error(path, factors ? factors : root, "'factors' must list at least one factor: - {key: elements.NAME.KEY, levels: [...]}");
  for (const YAML::Node& f : factors) {
    if (!f.IsMap() || !f["key"] || !f["key"].IsScalar()) yaml_error(path, f, "each factor needs 'key' (a model key)");
    SweepFactor factor;
    factor.key = f["key"].Scalar();
    factor.line = yaml_line(f);
    const std::string context = "factor '" + factor.key + "'";
    check_yaml_keys(path, f, {"key", "scale", "levels", "distribution"}, context);
    for (const SweepFactor& other : plan.factors)
      if (other.key == factor.key) yaml_error(path, f["key"], context + " is listed twice");
    if (f["scale"]) {
      try {
        factor.scale = f["scale"].as<bool>();
      } catch (const YAML::Exception&) {
        yaml_error(path, f["scale"], context + ": scale is true or false");
      }
    }
    if (sampled(plan.design)) {
      if (!f["distribution"]) yaml_error(path, f, context + ": a " + root["design"].Scalar() + " design needs a distribution per factor");
      factor.distribution = load_distribution(path, f["distribution"], context);
    } else if (plan.design != SweepDesignKind::runs || f["levels"]) {
      const YAML::Node levels = f["levels"];
      if (!levels || !levels.IsSequence() || levels.size() == 0)
        yaml_error(path, levels ? levels : f, context + ": 'levels' must list at least one value (the design is empty)");
      for (const YAML::Node& level : levels) factor.levels.push_back(level_text(path, level, context));
    }
    plan.factors.push_back(std::move(factor));
  }
  if (plan.design == SweepDesignKind::runs) {
    const YAML::Node runs = root["runs"];
    if (!runs || !runs.IsSequence() || runs.size() == 0)
      yaml_error(path, runs ? runs : root["design"], "design 'runs' needs 'runs': a list of {key: level} maps (the design is empty)");
    for (const YAML::Node& r : runs) {
      if (!r.IsMap()) yaml_error(path, r, "each run is a map {factor key: level}");
      std::vector<std::string> levels(plan.factors.size());
      for (const auto& entry : r) {
        const std::string key = entry.first.as<std::string>();
        const auto it = std::find_if(plan.factors.begin(), plan.factors.end(), [&](const SweepFactor& x) { return x.key == key; });
        if (it == plan.factors.end()) yaml_error(path, entry.first, "run: '" + key + "' is not one of the factors (list it under 'factors')");
        levels[static_cast<std::size_t>(it - plan.factors.begin())] = level_text(path, entry.second, "run: " + key);
      }
      plan.runs.push_back(std::move(levels));
      plan.run_lines.push_back(yaml_line(r));
    }
  } else if (root["runs"]) {
    yaml_error(path, root["runs"], "'runs' is only read with design: runs");
  }
  if (const YAML::Node responses = root["responses"]) {
    if (!responses.IsSequence() || responses.size() == 0)
      yaml_error(path, responses, "responses is a list, e.g. [R1, car_crush.car1.max_crush, anticlimber.force@0.05]");
    for (const YAML::Node& r : responses) {
      if (!r.IsScalar()) yaml_error(path, r, "a response is a name such as R1, car_crush.car1.max_crush or anticlimber.force@0.05");
      const std::string name = r.Scalar();
      if (name == "status") continue;  // always a column
      if (name.empty()) yaml_error(path, r, "an empty response name");
      plan.responses.push_back(name);
    }
  }

  // Every key and level against the model, before any run.
  // Its YAML structure checked once for every load below (the same messages as load_model_text).
  const CheckedYamlText model_text = check_model_text(read_model_text(model_path), model_path);
  (void)load_model_text(model_text, model_path, {});  // the model's own mistakes first, as they are
  const auto check = [&](const SweepFactor& factor, const std::string& level, int line) {
    std::vector<std::string> settings = plan.settings;
    try {
      settings.push_back(factor_setting(factor, level));
      (void)load_model_text(model_text, model_path, settings);
    } catch (const InputError& e) {
      throw InputError(SourceLocation{path, line}.prefix() + "factor '" + factor.key + "' at level '" + level + "': " + e.what());
    }
  };
  try {
    (void)load_model_text(model_text, model_path, plan.settings);
  } catch (const InputError& e) {
    yaml_error(path, root["set"], std::string("set: ") + e.what());
  }
  for (const SweepFactor& factor : plan.factors) {
    for (const std::string& level : factor.levels) check(factor, level, factor.line);
    if (factor.distribution) check(factor, exact(factor.distribution->value_at(0.5)), factor.line);
  }
  for (std::size_t r = 0; r < plan.runs.size(); ++r)
    for (std::size_t f = 0; f < plan.factors.size(); ++f)
      if (!plan.runs[r][f].empty()) check(plan.factors[f], plan.runs[r][f], plan.run_lines[r]);
  if (plan.responses.empty()) {
    const LoadedModel loaded = load_model_text(model_text, model_path, plan.settings);
    if (loaded.run_spec.responses.defined()) plan.responses = {"R1", "R2", "R3"};
    plan.responses.push_back("energy.relative_balance_error");
  }
  return plan;
}

// ---------------------------------------------------------------- runs

std::optional<std::size_t> sweep_run_count(const SweepPlan& plan) {
  std::vector<std::size_t> counts;
  for (const SweepFactor& f : plan.factors) counts.push_back(f.levels.size());
  switch (plan.design) {
    case SweepDesignKind::full_factorial: return factorial_count(counts);
    case SweepDesignKind::one_at_a_time: {
      std::optional<std::size_t> total = 1;  // the model's own run, then each level of each factor
      for (std::size_t n : counts) total = add_counts(total, n);
      return total;
    }
    case SweepDesignKind::latin_hypercube:
    case SweepDesignKind::monte_carlo: return plan.samples;
    case SweepDesignKind::runs: return plan.runs.size();
  }
  return std::nullopt;
}

void require_sweep_run_count(const SweepPlan& plan, std::size_t max_runs) {
  require_run_count(sweep_run_count(plan), max_runs, plan.path + ": the sweep's plan");
}

SweepRunGenerator::SweepRunGenerator(const SweepPlan& plan, const std::string& model_path, const std::string& model_text)
    : plan_(plan) {
  const std::optional<std::size_t> count = sweep_run_count(plan);
  if (!count)
    throw InputError(plan.path + ": the sweep's plan has more runs than " +
                     std::to_string(std::numeric_limits<std::size_t>::max()) + "; make it smaller");
  count_ = *count;
  const std::size_t n = plan.factors.size();
  if (plan.design == SweepDesignKind::latin_hypercube) {
    const auto rows = latin_hypercube(plan.samples, n, plan.seed);  // (rows freed below: the flat copy is kept)
    hypercube_.reserve(plan.samples * n);
    for (const auto& row : rows) hypercube_.insert(hypercube_.end(), row.begin(), row.end());
  }
  // What every run reads besides its settings: the program (with the libraries' versions) and
  // every model file (a variant and its base), each text after its length.
  inputs_hash_ = fnv1a(version_text());
  for (const std::string& text : model_input_texts(model_text, model_path))
    inputs_hash_ = fnv1a(text, fnv1a(std::string(1, '\0') + std::to_string(text.size()) + std::string(1, '\0'), inputs_hash_));
}

std::vector<std::string> SweepRunGenerator::levels(std::size_t k) const {
  RAILCRASH_DEMAND(k < count_);
  const std::size_t n = plan_.factors.size();
  std::vector<std::string> levels(n);
  switch (plan_.design) {
    case SweepDesignKind::full_factorial: {
      std::size_t rest = k;  // mixed-radix digits, the last factor changing fastest (as full_factorial)
      for (std::size_t f = n; f-- > 0;) {
        const std::size_t count = plan_.factors[f].levels.size();
        levels[f] = plan_.factors[f].levels[rest % count];
        rest /= count;
      }
      break;
    }
    case SweepDesignKind::one_at_a_time: {
      if (k == 0) break;  // every factor at the model's value
      std::size_t rest = k - 1;
      for (std::size_t f = 0; f < n; ++f) {
        const std::size_t count = plan_.factors[f].levels.size();
        if (rest < count) {
          levels[f] = plan_.factors[f].levels[rest];
          break;
        }
        rest -= count;
      }
      break;
    }
    case SweepDesignKind::latin_hypercube:
      for (std::size_t f = 0; f < n; ++f) levels[f] = exact(plan_.factors[f].distribution->value_at(hypercube_[k * n + f]));
      break;
    case SweepDesignKind::monte_carlo: {
      // monte_carlo's draws: run k's are draws k n ... k n + n - 1 of the seed's sequence.
      std::vector<double> probabilities(n);
      {
        const std::lock_guard<std::mutex> lock(generator_mutex_);
        if (k != generator_next_run_ || k == 0) {
          generator_.seed(plan_.seed);
          generator_.discard(static_cast<unsigned long long>(k) * n);
        }
        for (double& u : probabilities) u = unit_uniform(generator_);
        generator_next_run_ = k + 1;
      }
      for (std::size_t f = 0; f < n; ++f) levels[f] = exact(plan_.factors[f].distribution->value_at(probabilities[f]));
      break;
    }
    case SweepDesignKind::runs:
      levels = plan_.runs[k];
      break;
  }
  return levels;
}

SweepRunSpec SweepRunGenerator::spec(std::size_t k) const {
  SweepRunSpec spec;
  spec.levels = levels(k);
  spec.settings = plan_.settings;
  for (std::size_t f = 0; f < plan_.factors.size(); ++f)
    if (!spec.levels[f].empty()) spec.settings.push_back(factor_setting(plan_.factors[f], spec.levels[f]));
  std::uint64_t hash = inputs_hash_;
  for (const std::string& s : spec.settings) hash = fnv1a(s, fnv1a(std::string(1, '\0'), hash));
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  spec.hash = text;
  return spec;
}

std::vector<SweepRunSpec> sweep_runs(const SweepPlan& plan, const std::string& model_path, const std::string& model_text) {
  const SweepRunGenerator generator(plan, model_path, model_text);
  std::vector<SweepRunSpec> specs;
  specs.reserve(generator.count());
  for (std::size_t k = 0; k < generator.count(); ++k) specs.push_back(generator.spec(k));
  return specs;
}

std::string sweep_dry_run_text(const SweepPlan& plan, const SweepRunGenerator& generator, const std::vector<std::size_t>& runs) {
  std::string text = plan.path + ": " + std::to_string(generator.count()) + " runs\nrun,hash";
  for (const SweepFactor& f : plan.factors) text += "," + csv_field(f.column());
  text += '\n';
  for (const std::size_t k : runs) {
    if (k >= generator.count()) continue;
    const SweepRunSpec spec = generator.spec(k);
    text += std::to_string(k) + "," + spec.hash;
    for (const std::string& level : spec.levels) text += "," + csv_field(level);
    text += '\n';
  }
  return text;
}

namespace {

/// A summary.json value as a response: true 1, false 0, a number itself; a null (a time that
/// never came), a text, an object or a list: no value (NaN).
double scalar_value(const nlohmann::json& node) {
  if (node.is_boolean()) return node.get<bool>() ? 1.0 : 0.0;
  return node.is_number() ? node.get<double>() : kNaN;
}

/// A value in summary.json by its dotted path; keys may hold dots themselves
/// ("anticlimber.force"), so the longest key that matches is taken at each level.
double summary_value(const nlohmann::json& node, const std::string& path) {
  if (path.empty()) return scalar_value(node);
  if (!node.is_object()) return kNaN;
  const nlohmann::json* best = nullptr;
  std::size_t best_size = 0;
  for (const auto& entry : node.items()) {
    const std::string& key = entry.key();
    if ((path == key || path.rfind(key + ".", 0) == 0) && (best == nullptr || key.size() > best_size)) {
      best = &entry.value();
      best_size = key.size();
    }
  }
  if (best == nullptr) return kNaN;
  return summary_value(*best, path.size() == best_size ? "" : path.substr(best_size + 1));
}

/// COLUMN@TIME: the column interpolated linearly at TIME (NaN outside the samples).
double column_at(const RunReport& report, const std::string& column, double t) {
  const auto it = std::find(report.columns.begin(), report.columns.end(), column);
  if (it == report.columns.end() || report.columns.empty() || report.columns[0] != "t") return kNaN;
  const std::vector<double>& times = report.series[0];
  const std::vector<double>& values = report.series[static_cast<std::size_t>(it - report.columns.begin())];
  const auto upper = std::lower_bound(times.begin(), times.end(), t);
  if (upper == times.end()) return kNaN;
  const std::size_t k = static_cast<std::size_t>(upper - times.begin());
  if (times[k] == t || k == 0) return times[k] == t ? values[k] : kNaN;
  const double w = (t - times[k - 1]) / (times[k] - times[k - 1]);
  return values[k - 1] + w * (values[k] - values[k - 1]);
}

}  // namespace

SweepRow run_sweep_spec(const SweepPlan& plan, const std::string& model_path, const CheckedYamlText& model_text,
                        const SweepRunSpec& spec, const RunControl& control, const std::string& run_folder) {
  SweepRow row;
  row.responses.assign(plan.responses.size(), kNaN);
  const auto start = std::chrono::steady_clock::now();
  try {
    const LoadedModel loaded = load_model_text(model_text, model_path, spec.settings);
    const RunReport report = run_model(loaded.model, loaded.run_spec, run_folder, control.stop_flag(), false, true);
    row.status = report.outcome.ok ? "ok" : "failed";
    row.message = report.outcome.message;
    row.outcomes = report.outcomes.text();
    row.branch = report.outcomes.order();
    row.integrator = integrator_used(report);
    if (!report.outcome.ok && control.timed_out()) row.message = run_limit_message(control.run_time_limit(), report.outcome.t_reached);
    if (!report.outcome.ok && control.interrupted()) row.message = "interrupted";
    // railcrash's own summary, just written (JSON), read with nlohmann's parser: with yaml-cpp's
    // a sweep run of mu_3plus3_si under Euler cost 1.11 times as much CPU (bench/HISTORY.md,
    // "A sweep run's summary read back").
    // Without exceptions: a text that is not JSON (none is written) gives no values, as yaml-cpp
    // gave for an empty one, and the run keeps its own status and message.
    const nlohmann::json summary = nlohmann::json::parse(report.summary_json, nullptr, /*allow_exceptions=*/false);
    for (std::size_t k = 0; k < plan.responses.size(); ++k) {
      const std::string& name = plan.responses[k];
      if (const auto at = name.rfind('@'); at != std::string::npos) {
        try {
          row.responses[k] = column_at(report, name.substr(0, at), std::stod(name.substr(at + 1)));
        } catch (const std::exception&) {
          row.responses[k] = kNaN;
        }
      } else {
        const bool short_name = name == "R1" || name == "R2" || name == "R3";
        row.responses[k] = summary_value(summary, short_name ? "responses." + name : name);
      }
    }
  } catch (const std::exception& e) {
    row.status = "failed";
    row.message = e.what();
  }
  row.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return row;
}

/// Fields of a runs.csv row: run, hash, the factors, status, the responses, wall_seconds,
/// message, outcomes, branch, integrator_used, euler_from_t (sweep_csv_header's columns).
namespace {
constexpr std::size_t kColumnsAfterResponses = 6;  // wall_seconds, message, outcomes, branch, integrator_used, euler_from_t
/// The columns a runs.csv written before integrator_used and euler_from_t has no field for.
constexpr const char* kIntegratorColumns = ",integrator_used,euler_from_t";
std::size_t runs_csv_fields(const SweepPlan& plan) {
  return 2 + plan.factors.size() + 1 + plan.responses.size() + kColumnsAfterResponses;
}
std::size_t wall_seconds_field(const SweepPlan& plan) { return 3 + plan.factors.size() + plan.responses.size(); }
std::size_t branch_field(const SweepPlan& plan) { return wall_seconds_field(plan) + 3; }
}  // namespace

std::string sweep_csv_header(const SweepPlan& plan) {
  std::string header = "run,hash";
  for (const SweepFactor& f : plan.factors) header += "," + csv_field(f.column());
  header += ",status";
  for (const std::string& r : plan.responses) header += "," + csv_field(r);
  return header + ",wall_seconds,message,outcomes,branch" + kIntegratorColumns;
}

std::string sweep_csv_line(const SweepPlan& plan, std::size_t number, const SweepRunSpec& spec, const SweepRow& row) {
  std::string line = std::to_string(number) + "," + spec.hash;
  for (const std::string& level : spec.levels) line += "," + csv_field(level);
  line += "," + row.status;
  for (double value : row.responses) line += "," + (std::isnan(value) ? std::string() : exact(value));
  (void)plan;
  char wall[32];
  std::snprintf(wall, sizeof wall, "%.3f", row.wall_seconds);
  return line + "," + wall + "," + csv_text(row.message) + "," + csv_text(row.outcomes) + "," + csv_text(row.branch) + "," +
         row.integrator.method + "," + row.integrator.euler_from_t_text();
}

namespace {

/// The run number a folder of DIR/runs is named by (NNNN), or nothing for any other name.
std::optional<std::size_t> run_folder_number(const std::filesystem::path& folder) {
  const std::string name = folder.filename().string();
  if (name.empty() || name.size() > 12 || name.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  return static_cast<std::size_t>(std::stoull(name));
}

std::string run_folder_name(std::size_t number) {
  char name[32];
  std::snprintf(name, sizeof name, "%04zu", number);
  return name;
}

/// Makes DIR/runs/ match runs.csv: the folder of a resumed row (`kept`: old run number -> new)
/// takes the row's new number, every other run folder is removed. Returns how many were removed.
std::size_t match_run_folders(const std::string& directory, const std::map<std::size_t, std::size_t>& kept) {
  namespace fs = std::filesystem;
  const fs::path runs = fs::path(directory) / "runs";
  std::error_code error;
  if (!fs::is_directory(runs, error)) return 0;
  std::size_t removed = 0;
  std::vector<std::pair<fs::path, std::size_t>> moving;  // renamed aside first: new numbers may be old ones
  for (const fs::directory_entry& entry : fs::directory_iterator(runs)) {
    const std::optional<std::size_t> number = run_folder_number(entry.path());
    if (!number || !entry.is_directory()) continue;
    const auto it = kept.find(*number);
    if (it == kept.end()) {
      fs::remove_all(entry.path());
      ++removed;
    } else if (it->second != *number) {
      const fs::path aside = runs / (".resumed-" + run_folder_name(*number));
      fs::rename(entry.path(), aside);
      moving.emplace_back(aside, it->second);
    }
  }
  for (const auto& [aside, number] : moving) fs::rename(aside, runs / run_folder_name(number));
  return removed;
}

}  // namespace

namespace {

/// One record of a CSV file: its fields, its raw text (without the line break that ends it) and
/// where it starts (1-based line).
struct CsvRecord {
  std::vector<std::string> fields;
  std::vector<std::size_t> field_columns;  // 1-based column of each field's first character
  std::string text;
  std::size_t line = 0;
  bool complete = false;  // ended by a line break (a record cut short by a kill or a full disk is not)
};

[[noreturn]] void csv_error(const std::string& path, std::size_t line, std::size_t column, const std::string& what) {
  throw InputError(path + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + what +
                   "; this is no runs.csv railcrash wrote: move it away, or write to another --out");
}

/// Splits text into CSV records (RFC 4180: a quoted field may hold commas, "" and line breaks).
/// A quote inside an unquoted field, or text after a closing quote, is refused with its line
/// and column. The last record is incomplete when the text does not end with a line break.
std::vector<CsvRecord> csv_records(const std::string& path, const std::string& text) {
  std::vector<CsvRecord> records;
  std::size_t line = 1, column = 1;
  std::size_t i = 0;
  while (i < text.size()) {
    CsvRecord record;
    record.line = line;
    const std::size_t record_start = i;
    bool end_of_record = false;
    while (!end_of_record) {
      record.fields.emplace_back();
      record.field_columns.push_back(column);
      std::string& field = record.fields.back();
      if (i < text.size() && text[i] == '"') {  // quoted
        ++i, ++column;
        bool closed = false;
        while (i < text.size()) {
          const char c = text[i];
          if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
            field += '"';
            i += 2, column += 2;
          } else if (c == '"') {
            ++i, ++column;
            closed = true;
            break;
          } else {
            field += c;
            ++i;
            if (c == '\n') ++line, column = 1;
            else ++column;
          }
        }
        if (!closed) {  // the file ends inside the quotes: a record cut short
          record.text = text.substr(record_start);
          records.push_back(std::move(record));
          return records;
        }
        if (i < text.size() && text[i] != ',' && text[i] != '\n')
          csv_error(path, line, column, std::string("'") + text[i] + "' after a closing quote (a field is quoted whole)");
      } else {
        while (i < text.size() && text[i] != ',' && text[i] != '\n') {
          if (text[i] == '"') csv_error(path, line, column, "a quote inside an unquoted field");
          field += text[i];
          ++i, ++column;
        }
      }
      if (i >= text.size()) {
        record.text = text.substr(record_start);
        records.push_back(std::move(record));
        return records;
      }
      if (text[i] == '\n') {
        record.text = text.substr(record_start, i - record_start);
        record.complete = true;
        end_of_record = true;
        ++line, column = 1;
      } else {
        ++column;
      }
      ++i;
    }
    records.push_back(std::move(record));
  }
  return records;
}

bool is_number(const std::string& text) {
  if (text.empty()) return false;
  char* end = nullptr;
  (void)std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size();
}

/// Checks a complete row of an earlier runs.csv field by field: a run number, a 16-digit hash,
/// ok or failed, numbers (or nothing) for the responses, a number for wall_seconds. InputError
/// with the line and column of the first field that is not.
void check_resumed_row(const std::string& path, const SweepPlan& plan, const CsvRecord& row, bool without_integrator) {
  const std::size_t expected = runs_csv_fields(plan) - (without_integrator ? 2 : 0);
  if (row.fields.size() != expected)
    csv_error(path, row.line, 1, std::to_string(row.fields.size()) + " fields where the header has " + std::to_string(expected));
  const auto at = [&](std::size_t k, const std::string& what) { csv_error(path, row.line, row.field_columns[k], what); };
  if (row.fields[0].empty() || row.fields[0].size() > 12 || row.fields[0].find_first_not_of("0123456789") != std::string::npos)
    at(0, "run '" + row.fields[0].substr(0, 40) + "' is not a run number");
  if (row.fields[1].size() != 16 || row.fields[1].find_first_not_of("0123456789abcdef") != std::string::npos)
    at(1, "hash '" + row.fields[1].substr(0, 40) + "' is not 16 hexadecimal digits");
  const std::size_t status = 2 + plan.factors.size();
  if (row.fields[status] != "ok" && row.fields[status] != "failed")
    at(status, "status '" + row.fields[status].substr(0, 40) + "' is neither ok nor failed");
  for (std::size_t r = 0; r < plan.responses.size(); ++r) {
    const std::string& value = row.fields[status + 1 + r];
    if (!value.empty() && !is_number(value))
      at(status + 1 + r, plan.responses[r] + " '" + value.substr(0, 40) + "' is not a number (nor empty)");
  }
  const std::size_t wall = wall_seconds_field(plan);
  if (!is_number(row.fields[wall])) at(wall, "wall_seconds '" + row.fields[wall].substr(0, 40) + "' is not a number");
}

}  // namespace

SweepResult start_sweep(const SweepPlan& plan, const SweepRunGenerator& generator, const std::string& directory, bool resume) {
  SweepResult result;
  result.total = generator.count();
  std::filesystem::create_directories(directory);
  const std::string csv_path = directory + "/runs.csv";
  const std::string header = sweep_csv_header(plan);
  std::map<std::size_t, std::size_t> kept_folders;  // a resumed row's run number in the old runs.csv -> in the new
  if (resume && std::filesystem::exists(csv_path)) {
    // The whole file is read and checked before any run: a row cut short at its end (a kill or
    // a full disk while it was written) is dropped and its run runs again; anything else that
    // is no row of this plan's runs.csv is refused with its line and column.
    std::ifstream in(csv_path, std::ios::binary);
    std::ostringstream content;
    content << in.rdbuf();
    if (in.bad()) throw InputError(csv_path + ": cannot read it to resume");
    std::vector<CsvRecord> records = csv_records(csv_path, content.str());
    // A runs.csv written before the columns integrator_used and euler_from_t: its rows are read
    // as they are and kept with those two fields empty (not recorded).
    const std::string header_without_integrator = header.substr(0, header.size() - std::strlen(kIntegratorColumns));
    const bool without_integrator = !records.empty() && records.front().text == header_without_integrator;
    // The last record is cut short when the file does not end with its line break, or (an
    // editor may have added one) when it has fewer fields than a row.
    const std::size_t row_fields = runs_csv_fields(plan) - (without_integrator ? 2 : 0);
    if (!records.empty() &&
        (!records.back().complete || (records.size() > 1 && records.back().fields.size() < row_fields))) {
      result.torn_row_line = records.back().line;
      records.pop_back();
    }
    if (!records.empty() && records.front().text != header && !without_integrator)
      throw InputError(csv_path + ": its columns are not this plan's (" + records.front().text.substr(0, 80) +
                       "...); resume with the same plan, or write to another --out");
    struct OldRow {
      std::string number, rest;  // rest: the fields after the hash
      bool matched = false;
    };
    std::map<std::string, OldRow> by_hash;
    std::vector<std::string> old_hashes;
    for (std::size_t r = 1; r < records.size(); ++r) {
      const CsvRecord& row = records[r];
      check_resumed_row(csv_path, plan, row, without_integrator);
      const std::size_t first = row.text.find(',');
      by_hash[row.fields[1]] = {row.fields[0], row.text.substr(row.text.find(',', first + 1) + 1) + (without_integrator ? ",," : "")};
      old_hashes.push_back(row.fields[1]);
    }
    const auto keep = [&](std::size_t k, const std::string& hash, OldRow& old) {
      result.lines[k] = std::to_string(k) + "," + hash + "," + old.rest;
      old.matched = true;
      if (const std::optional<std::size_t> number = run_folder_number(old.number)) kept_folders[*number] = k;
    };
    // Each row at its own run number first (the plan unchanged: no other run is generated) ...
    std::size_t unmatched = 0;
    for (auto& [hash, old] : by_hash) {
      const std::optional<std::size_t> k = run_folder_number(old.number);
      if (k && *k < result.total && !result.lines.count(*k) && generator.spec(*k).hash == hash) keep(*k, hash, old);
      else ++unmatched;
    }
    // ... and only when some row is not there, every run's hash, one run at a time.
    for (std::size_t k = 0; unmatched > 0 && k < result.total; ++k) {
      if (result.lines.count(k)) continue;
      const std::string hash = generator.spec(k).hash;
      const auto it = by_hash.find(hash);
      if (it == by_hash.end()) continue;
      if (!it->second.matched) --unmatched;
      keep(k, hash, it->second);
    }
    result.resumed = result.lines.size();
    result.stale_rows = static_cast<std::size_t>(std::count_if(
        old_hashes.begin(), old_hashes.end(), [&](const std::string& hash) { return !by_hash.at(hash).matched; }));
  }
  result.stale_folders = match_run_folders(directory, kept_folders);
  std::string text = header + '\n';
  for (const auto& [k, line] : result.lines) text += line + '\n';
  write_whole_file(csv_path, text);  // (FileWriteError names the file)
  return result;
}

std::string sweep_start_note(const SweepResult& result, const std::string& directory) {
  std::string note;
  if (result.stale_rows > 0)
    note += std::to_string(result.stale_rows) + " row" + (result.stale_rows == 1 ? "" : "s") + " of " + directory +
            "/runs.csv ran with other inputs (a model file, the plan or railcrash changed since) or are no run of "
            "this plan: dropped, and the plan's runs without a row run again\n";
  if (result.torn_row_line > 0)
    note += "the last row of " + directory + "/runs.csv (line " + std::to_string(result.torn_row_line) +
            ") was cut short (the sweep was killed or the disk was full while it was written): dropped, its run runs again\n";
  if (result.stale_folders > 0)
    note += std::to_string(result.stale_folders) + " folder" + (result.stale_folders == 1 ? "" : "s") + " of " + directory +
            "/runs/ belonged to no row of runs.csv kept with these inputs: removed\n";
  return note;
}

void append_sweep_line(const std::string& directory, const std::string& line) {
  const std::string path = directory + "/runs.csv";
  const int descriptor = ::open(path.c_str(), O_WRONLY | O_APPEND | O_NOFOLLOW | O_CLOEXEC);
  if (descriptor < 0) throw FileWriteError(path, errno);
  const std::string row = line + '\n';
  const int error_number = write_all(descriptor, row.data(), row.size());
  const int closed = ::close(descriptor);
  if (error_number != 0) throw FileWriteError(path, error_number);
  if (closed != 0 && errno != EINTR) throw FileWriteError(path, errno);
}

SweepResult run_sweep(const std::string& model_path, const SweepPlan& plan, const std::string& directory,
                      const SweepOptions& options) {
  require_sweep_run_count(plan, options.max_runs);  // before a run is generated
  const FolderLock folder_lock(directory);          // one sweep per folder (before anything there changes)
  if (const std::string note = folder_lock.removal_note(directory); !note.empty() && options.note) options.note(note + "\n");
  const CheckedYamlText model_text = check_model_text(read_model_text(model_path), model_path);
  const SweepRunGenerator generator(plan, model_path, model_text.text());
  SweepResult result = start_sweep(plan, generator, directory, options.resume);
  if (const std::string note = sweep_start_note(result, directory); !note.empty() && options.note) options.note(note);
  // The runs not done, in order, one at a time as threads take them: the run numbers resumed
  // are skipped, nothing is held for the others.
  std::vector<std::size_t> resumed_numbers;
  for (const auto& [k, line] : result.lines) resumed_numbers.push_back(k);
  auto next_resumed = resumed_numbers.begin();
  std::size_t next_run = 0;
  std::mutex rows_mutex;
  std::map<std::size_t, std::pair<SweepRunSpec, SweepRow>> finished;  // from a run's end to on_finished (at most --jobs)
  BatchOptions batch;
  batch.jobs = options.jobs;
  batch.run_time_limit = options.run_time_limit;
  batch.stop = options.stop;
  std::size_t done = result.done();
  // A row that cannot be appended ends the sweep: no run starts after it, no row is appended
  // after it (runs.csv ends at the failed row, which --resume drops), and the error is thrown.
  std::optional<FileWriteError> write_failure;
  std::atomic<bool> write_failed{false};
  run_batch_stream(
      result.total - result.done(),
      [&]() -> std::optional<std::size_t> {
        if (write_failed.load()) return std::nullopt;
        while (next_resumed != resumed_numbers.end() && *next_resumed == next_run) ++next_resumed, ++next_run;
        if (next_run >= result.total) return std::nullopt;
        return next_run++;
      },
      [&](std::size_t k, const RunControl& control) {
        if (write_failed.load()) return;
        char folder[32];
        std::snprintf(folder, sizeof folder, "/runs/%04zu", k);
        SweepRunSpec spec = generator.spec(k);
        SweepRow row = run_sweep_spec(plan, model_path, model_text, spec, control, options.keep_runs ? directory + folder : "");
        const std::lock_guard<std::mutex> lock(rows_mutex);
        finished[k] = {std::move(spec), std::move(row)};
      },
      batch,
      [&](std::size_t k, BatchRunState state) {
        std::pair<SweepRunSpec, SweepRow> run;
        {
          const std::lock_guard<std::mutex> lock(rows_mutex);
          const auto it = finished.find(k);
          if (it == finished.end()) return;  // (a write failed before the run)
          run = std::move(it->second);
          finished.erase(it);
        }
        if (state != BatchRunState::finished || write_failed.load()) return;  // an interrupted run is run again on --resume
        const std::string line = sweep_csv_line(plan, k, run.first, run.second);
        try {
          append_sweep_line(directory, line);
        } catch (const FileWriteError& e) {
          write_failure = e;
          write_failed = true;
          return;
        }
        result.lines[k] = line;
        if (options.progress) options.progress(k, run.second, ++done, result.total);
      });
  if (write_failure) throw *write_failure;
  write_sweep(plan, result, directory);
  return result;
}

// ---------------------------------------------------------------- summary

namespace {

double mean(const std::vector<double>& values) {
  return values.empty() ? kNaN : std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
}

/// Least-squares slope of y on x and the correlation coefficient (NaN with fewer than 2 points
/// or no spread).
std::pair<double, double> linear_trend(const std::vector<double>& x, const std::vector<double>& y) {
  const double mx = mean(x), my = mean(y);
  double sxx = 0.0, syy = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  if (x.size() < 2 || sxx == 0.0) return {kNaN, kNaN};
  return {sxy / sxx, syy > 0.0 ? sxy / std::sqrt(sxx * syy) : kNaN};
}

const char* design_name(SweepDesignKind kind) {
  switch (kind) {
    case SweepDesignKind::full_factorial: return "full factorial";
    case SweepDesignKind::one_at_a_time: return "one at a time";
    case SweepDesignKind::latin_hypercube: return "Latin hypercube";
    case SweepDesignKind::monte_carlo: return "Monte Carlo";
    case SweepDesignKind::runs: return "explicit runs";
  }
  return "";
}

}  // namespace

/// The runs whose discrete outcome differs from run 0's (issue 40): runs.csv's column branch.
std::string sweep_branches_markdown(const SweepPlan& plan, const SweepResult& result) {
  const std::size_t branch_column = branch_field(plan);
  std::vector<std::pair<std::size_t, std::string>> branches;  // run number, branch of ok runs
  for (const auto& [k, line] : result.lines) {
    const std::vector<std::string> fields = csv_fields(line);
    if (fields.size() > branch_column && fields[2 + plan.factors.size()] == "ok") branches.emplace_back(k, fields[branch_column]);
  }
  if (branches.empty() || branches.front().first != 0) return "";
  std::ostringstream md;
  std::string changed;
  std::size_t count = 0;
  for (const auto& [number, branch] : branches)
    if (branch != branches.front().second) {
      ++count;
      if (count <= 20) changed += (changed.empty() ? "" : ", ") + std::to_string(number);
    }
  md << "\nDiscrete outcome of run 0 (runs.csv, column branch): `" << branches.front().second << "`; " << count << " of "
     << branches.size() << " ok runs end on another branch" << (count ? " (runs " + changed + (count > 20 ? ", ..." : "") + ")" : "")
     << ": a response may jump between them.\n";
  return md.str();
}

std::size_t failed_sweep_runs(const SweepPlan& plan, const SweepResult& result) {
  std::size_t failed = 0;
  for (const auto& [k, line] : result.lines)
    if (csv_fields(line)[2 + plan.factors.size()] != "ok") ++failed;
  return failed;
}

std::string write_sweep(const SweepPlan& plan, const SweepResult& result, const std::string& directory) {
  std::filesystem::create_directories(directory);
  std::string csv = sweep_csv_header(plan) + '\n';
  for (const auto& [k, line] : result.lines) csv += line + '\n';
  write_whole_file(directory + "/runs.csv", csv);  // (FileWriteError names the file: the command fails)
  const std::size_t factor_count = plan.factors.size();
  // Per finished run: the levels and the responses of ok runs.
  std::vector<std::vector<std::string>> levels;
  std::vector<std::vector<double>> values;
  const std::size_t failed = failed_sweep_runs(plan, result);
  for (const auto& [k, line] : result.lines) {
    const std::vector<std::string> fields = csv_fields(line);
    if (fields[2 + factor_count] != "ok") continue;
    levels.emplace_back(fields.begin() + 2, fields.begin() + 2 + static_cast<std::ptrdiff_t>(factor_count));
    values.emplace_back();
    for (std::size_t r = 0; r < plan.responses.size(); ++r) {
      const std::string& text = fields[3 + factor_count + r];
      values.back().push_back(text.empty() ? kNaN : std::stod(text));
    }
  }
  std::ostringstream md;
  md << "# Sweep " << plan.path << "\n\n" << design_name(plan.design) << " design, " << result.total << " runs: "
     << result.done() << " done (" << result.resumed << " from an earlier runs.csv), " << failed << " failed, "
     << result.total - result.done() << " not run. Rows: runs.csv.\n";
  md << sweep_branches_markdown(plan, result);
  const bool trend = sampled(plan.design);
  md << "\n## Main effects\n\n"
     << (trend ? "Each response's least-squares slope on each factor over the ok runs, the slope times the factor's "
                 "sampled range (the effect), and the correlation coefficient r.\n"
               : "Each response's mean over the ok runs at each level of a factor (all other factors as the design "
                 "sets them); the effect is the largest mean minus the smallest. \"model\" is the model's own value.\n");
  for (std::size_t r = 0; r < plan.responses.size(); ++r) {
    md << "\n### " << plan.responses[r] << "\n\n";
    if (trend) md << "| Factor | slope | effect | r |\n|---|---|---|---|\n";
    else md << "| Factor | level: mean (runs) | effect |\n|---|---|---|\n";
    for (std::size_t f = 0; f < factor_count; ++f) {
      if (trend) {
        std::vector<double> x, y;
        for (std::size_t i = 0; i < values.size(); ++i)
          if (!std::isnan(values[i][r])) {
            x.push_back(std::stod(levels[i][f]));
            y.push_back(values[i][r]);
          }
        const auto [slope, correlation] = linear_trend(x, y);
        const double range = x.empty() ? kNaN : *std::max_element(x.begin(), x.end()) - *std::min_element(x.begin(), x.end());
        md << "| " << plan.factors[f].column() << " | " << table_number(slope, "%.4g") << " | "
           << table_number(slope * range, "%.4g") << " | " << table_number(correlation, "%.3f") << " |\n";
        continue;
      }
      std::vector<std::string> order;  // levels in the order the runs first use them
      std::map<std::string, std::vector<double>> by_level;
      for (std::size_t i = 0; i < values.size(); ++i) {
        if (std::isnan(values[i][r])) continue;
        const std::string level = levels[i][f].empty() ? "model" : levels[i][f];
        if (!by_level.count(level)) order.push_back(level);
        by_level[level].push_back(values[i][r]);
      }
      std::string cells;
      double low = kNaN, high = kNaN;
      for (const std::string& level : order) {
        const double m = mean(by_level[level]);
        cells += (cells.empty() ? "" : "; ") + level + ": " + table_number(m, "%.4g") + " (" +
                 std::to_string(by_level[level].size()) + ")";
        low = std::isnan(low) ? m : std::min(low, m);
        high = std::isnan(high) ? m : std::max(high, m);
      }
      md << "| " << plan.factors[f].column() << " | " << cells << " | " << table_number(high - low, "%.4g") << " |\n";
    }
  }
  write_whole_file(directory + "/summary.md", md.str());
  return md.str();
}

}  // namespace railcrash
