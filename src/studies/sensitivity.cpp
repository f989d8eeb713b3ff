#include "railcrash/studies/sensitivity.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "railcrash/core/error.hpp"
#include "railcrash/core/table_text.hpp"
#include "railcrash/core/whole_file.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/model/yaml_file.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/studies/batch.hpp"
#include "railcrash/studies/run_count.hpp"

namespace railcrash {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A singular value below this fraction of the largest counts as zero (the design matrix's
// entries are products of nondimensional values near 1, so round-off is near 1e-16).
constexpr double kRankTolerance = 1e-10;

/// A parameter's name heads CSV columns, Markdown tables and term labels (P6*P7, P6^2): letters,
/// digits, _ - and . only, starting with a letter or _.
std::string parameter_name(const std::string& path, const YAML::Node& node) {
  const std::string name = node.IsScalar() ? node.Scalar() : "";
  const bool first_ok = !name.empty() && (std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_');
  const bool rest_ok = std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
  if (!first_ok || !rest_ok)
    yaml_error(path, node, "parameter name '" + name + "': use letters, digits, _ - and . only, starting with a letter or _ (e.g. P7)");
  return name;
}

const SensitivityParameter* find_parameter(const SensitivityDesign& design, const std::string& name) {
  for (const SensitivityParameter& p : design.parameters)
    if (p.name == name) return &p;
  return nullptr;
}

std::string parameter_names(const SensitivityDesign& design) {
  std::string names;
  for (const SensitivityParameter& p : design.parameters) names += (names.empty() ? "" : ", ") + p.name;
  return names;
}

void require_parameter(const std::string& path, const YAML::Node& node, const SensitivityDesign& design,
                       const std::string& name, const std::string& context) {
  if (!find_parameter(design, name))
    yaml_error(path, node,
                 context + ": no parameter '" + name + "' in 'parameters' (use one of " + parameter_names(design) + ")");
}

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

// "P6" | "P6^2" | "P6*P7" (a product of a parameter with itself is its square).
SensitivityTerm parse_term(const std::string& path, const YAML::Node& node, const SensitivityDesign& design) {
  const std::string text = node.IsScalar() ? node.as<std::string>() : "";
  const std::string context = "second_order term '" + text + "'";
  SensitivityTerm term;
  if (const auto caret = text.find('^'); caret != std::string::npos) {
    if (trim(text.substr(caret + 1)) != "2") yaml_error(path, node, context + ": only squares are allowed (P6^2)");
    term.first = term.second = trim(text.substr(0, caret));
  } else if (const auto star = text.find('*'); star != std::string::npos) {
    term.first = trim(text.substr(0, star));
    term.second = trim(text.substr(star + 1));
  } else {
    term.first = trim(text);
  }
  if (term.first.empty() || (text.find('*') != std::string::npos && term.second.empty()))
    yaml_error(path, node, context + ": write a term as P6, P6^2 or P6*P7");
  require_parameter(path, node, design, term.first, context);
  if (!term.linear()) require_parameter(path, node, design, term.second, context);
  return term;
}

bool same_term(const SensitivityTerm& a, const SensitivityTerm& b) {
  return (a.first == b.first && a.second == b.second) ||
         (!a.linear() && !b.linear() && a.first == b.second && a.second == b.first);
}

void load_second_order(const std::string& path, const YAML::Node& node, SensitivityDesign& design) {
  if (!node.IsMap() || !node["terms"] || !node["terms"].IsSequence() || !node["runs"] || !node["runs"].IsSequence())
    yaml_error(path, node,
                 "'second_order' needs 'terms' (a list such as [P6, P6^2, P6*P7]) and 'runs' (a list of "
                 "{parameter: value} maps, e.g. - {P6: 0.8})");
  for (const YAML::Node& t : node["terms"]) {
    SensitivityTerm term = parse_term(path, t, design);
    for (const SensitivityTerm& other : design.second_order.terms)
      if (same_term(term, other)) yaml_error(path, t, "second_order term '" + term.label() + "' is listed twice");
    design.second_order.terms.push_back(std::move(term));
  }
  std::size_t number = 0;
  for (const YAML::Node& r : node["runs"]) {
    ++number;
    const std::string context = "second_order run " + std::to_string(number);
    if (!r.IsMap() || r.size() == 0)
      yaml_error(path, r, context + ": write a run as a map of parameter values, e.g. {P6: 1.2, P7: 1.2}");
    SensitivityPoint point;
    for (auto it = r.begin(); it != r.end(); ++it) {
      const std::string name = it->first.as<std::string>();
      require_parameter(path, it->first, design, name, context);
      double value = 0.0;
      try {
        value = it->second.as<double>();
      } catch (const YAML::Exception&) {
        yaml_error(path, it->second, context + ": the value of " + name + " must be a number (e.g. 0.8)");
      }
      if (!(value > 0.0)) yaml_error(path, it->second, context + ": the value of " + name + " must be positive");
      point.emplace_back(name, value);
    }
    design.second_order.runs.push_back(std::move(point));
  }
}

std::array<double, 3> response_triple(const std::string& path, const YAML::Node& node, const std::string& context) {
  if (!node.IsSequence() || node.size() != 3) yaml_error(path, node, context + ": give [R1, R2, R3], e.g. [1.255, 0.610, 1.865]");
  std::array<double, 3> values{};
  for (std::size_t k = 0; k < 3; ++k) {
    try {
      values[k] = node[k].as<double>();
    } catch (const YAML::Exception&) {
      yaml_error(path, node[k], context + ": R" + std::to_string(k + 1) + " must be a number");
    }
  }
  return values;
}

void load_reference(const std::string& path, const YAML::Node& node, SensitivityDesign& design) {
  if (!node.IsMap() || !node["base"])
    yaml_error(path, node, "'reference' needs at least 'base: [R1, R2, R3]' (the published run 0)");
  check_yaml_keys(path, node, {"source", "base", "first_order", "second_order", "ranking"}, "reference");
  PublishedResults reference;
  if (node["source"]) reference.source = node["source"].as<std::string>();
  reference.base = response_triple(path, node["base"], "reference: base");
  if (const YAML::Node first = node["first_order"]) {
    if (!first.IsMap()) yaml_error(path, first, "reference: first_order must map parameters to [R1, R2, R3]");
    for (const auto& entry : first) {
      const std::string name = entry.first.as<std::string>();
      require_parameter(path, entry.first, design, name, "reference: first_order");
      reference.first_order.emplace_back(name, response_triple(path, entry.second, "reference: first_order: " + name));
    }
  }
  if (const YAML::Node second = node["second_order"]) {
    if (!second.IsSequence() || second.size() != design.second_order.runs.size())
      yaml_error(path, second, "reference: second_order must list [R1, R2, R3] for each of the " +
                                     std::to_string(design.second_order.runs.size()) + " second_order runs, in their order");
    for (std::size_t i = 0; i < second.size(); ++i)
      reference.second_order.push_back(response_triple(path, second[i], "reference: second_order " + std::to_string(i + 1)));
  }
  if (const YAML::Node ranking = node["ranking"]) {
    if (!ranking.IsMap()) yaml_error(path, ranking, "reference: ranking must map R1, R2, R3 to lists of parameters");
    for (const auto& entry : ranking) {
      const std::string response = entry.first.as<std::string>();
      if (response != "R1" && response != "R2" && response != "R3")
        yaml_error(path, entry.first, "reference: ranking: keys are R1, R2 and R3");
      if (!entry.second.IsSequence()) yaml_error(path, entry.second, "reference: ranking: " + response + " must be a list");
      auto& list = reference.ranking[static_cast<std::size_t>(response[1] - '1')];
      for (const YAML::Node& p : entry.second) {
        const std::string name = p.as<std::string>();
        require_parameter(path, p, design, name, "reference: ranking: " + response);
        list.push_back(name);
      }
    }
  }
  design.reference = std::move(reference);
}

std::string parameter_value_text(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "P = %.6g", value);
  return text;
}

struct Job {
  SensitivityPoint variation;
  std::string parameter;  // SensitivityRun::parameter
  double factor = 1.0;
};

// model_text: the model file as read once at the start of the study, so that every run sees the
// same model even if the file is edited while the study runs.
/// The settings of a job's run: the study's own, then the job's parameter factors as KEY*=FACTOR.
std::vector<std::string> job_settings(const SensitivityDesign& design, const Job& job,
                                      const std::vector<std::string>& base_settings) {
  std::vector<std::string> settings = base_settings;
  for (const auto& [name, value] : job.variation) {
    const SensitivityParameter* parameter = find_parameter(design, name);
    RAILCRASH_DEMAND(parameter != nullptr);  // load_design and run_sensitivity checked the names
    for (const auto& [key, power] : parameter->scales) {
      char text[64];
      std::snprintf(text, sizeof text, "%.17g", std::pow(value, power));
      settings.push_back(key + "*=" + text);
    }
  }
  return settings;
}

void check_options(const SensitivityDesign& design, const SensitivityOptions& options) {
  if (options.central_step < 0.0 || options.central_step >= 1.0)
    throw InputError("--central H: H must be between 0 and 1 (e.g. 0.05 for runs at 0.95 and 1.05)");
  for (const std::string& name : options.only)
    if (!find_parameter(design, name))
      throw InputError("--only: the design has no parameter '" + name + "' (it has " + parameter_names(design) + ")");
}

bool is_chosen(const SensitivityOptions& options, const std::string& name) {
  return options.only.empty() || std::find(options.only.begin(), options.only.end(), name) != options.only.end();
}

/// The study's runs in order: the base run, the first-order runs (first_order_count of them),
/// then the second-order runs whose parameters are all chosen.
std::vector<Job> study_jobs(const SensitivityDesign& design, const SensitivityOptions& options, std::size_t& first_order_count) {
  check_options(design, options);
  const bool central = options.central_step > 0.0;
  std::vector<Job> jobs{Job{}};
  first_order_count = 0;
  for (const SensitivityParameter& p : design.parameters) {
    if (!is_chosen(options, p.name)) continue;
    const std::vector<double> values = central ? std::vector<double>{1.0 + options.central_step, 1.0 - options.central_step}
                                               : std::vector<double>{design.factor};
    for (double value : values) jobs.push_back(Job{{{p.name, value}}, p.name, value});
    first_order_count += values.size();
  }
  if (options.second_order)
    for (const SensitivityPoint& point : design.second_order.runs) {
      if (!std::all_of(point.begin(), point.end(), [&](const auto& entry) { return is_chosen(options, entry.first); })) continue;
      Job job{point, "", point.size() == 1 ? point[0].second : kNaN};
      for (const auto& entry : point) job.parameter += (job.parameter.empty() ? "" : "+") + entry.first;
      jobs.push_back(job);
    }
  return jobs;
}

/// The scale entry of a job's parameters that the model does not accept on its own, as
/// "design.yaml:12: design parameter 'P7', scale key 'K' does not fit the model: ...", or "".
std::string bad_scale_entry(const CheckedYamlText& model_text, const std::string& model_path, const SensitivityDesign& design,
                            const Job& job, const std::vector<std::string>& base_settings) {
  for (const auto& [name, value] : job.variation) {
    const SensitivityParameter* parameter = find_parameter(design, name);
    RAILCRASH_DEMAND(parameter != nullptr);
    for (std::size_t k = 0; k < parameter->scales.size(); ++k) {
      const auto& [key, power] = parameter->scales[k];
      const SensitivityParameter single{name, "", {{key, power}}, {}};
      const SensitivityDesign alone{1.2, {single}, {}, std::nullopt};
      try {
        (void)load_model_text(model_text, model_path, job_settings(alone, Job{{{name, value}}, name, value}, base_settings));
      } catch (const InputError& e) {
        const SourceLocation where = k < parameter->scale_sources.size() ? parameter->scale_sources[k] : SourceLocation{};
        return where.prefix() + "design parameter '" + name + "', scale key '" + key + "' does not fit the model: " + e.what();
      }
    }
  }
  return "";
}

/// A run the study's interruption stopped (or never started): failed, with no responses (a
/// partial run's would look like results).
void mark_interrupted(SensitivityRun& run) {
  run.ok = false;
  run.interrupted = true;
  run.responses.r1 = run.responses.r2 = run.responses.r3 = kNaN;
  if (run.message.empty()) run.message = "interrupted (SIGINT/SIGTERM)";
}

SensitivityRun run_one(const std::string& model_path, const CheckedYamlText& model_text, const SensitivityDesign& design,
                       const Job& job, const std::vector<std::string>& base_settings, double time_limit,
                       const RunControl& control) {
  SensitivityRun run;
  run.variation = job.variation;
  run.parameter = job.parameter;
  run.factor = job.factor;
  const auto start = std::chrono::steady_clock::now();
  try {
    const LoadedModel loaded = load_model_text(model_text, model_path, job_settings(design, job, base_settings));
    if (!loaded.run_spec.responses.defined())
      throw InputError(model_path + ": a parameter study needs a 'responses' section (R1-R3) in the model");
    const RunReport report = run_model(loaded.model, loaded.run_spec, "", control.stop_flag());
    run.ok = report.outcome.ok;  // a run that finished just as the limit passed still counts
    run.message = !run.ok && control.timed_out() ? run_limit_message(time_limit, report.outcome.t_reached) : report.outcome.message;
    run.responses = report.responses;
    run.outcomes = report.outcomes;
    run.integrator = integrator_used(report);
  } catch (const std::exception& e) {
    run.ok = false;
    run.message = e.what();
  }
  run.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

double response(const Responses& r, int k) { return k == 0 ? r.r1 : (k == 1 ? r.r2 : r.r3); }

std::array<double, 3> responses_of(const SensitivityRun& run) {
  return {run.responses.r1, run.responses.r2, run.responses.r3};
}

/// Bisects the step of a first-order run that is off run 0's branch (issue 40): the step
/// s = value - 1 is halved `levels` times, keeping the bracket [on, off] of the fractions of s
/// at which the run is on run 0's branch and off it. Each level is one run (sequential: each
/// depends on the last), so a flagged parameter costs `levels` extra runs.
BranchChange bisect_branch(const std::string& model_path, const CheckedYamlText& model_text, const SensitivityDesign& design,
                           const SensitivityOptions& options, const SensitivityRun& base, const SensitivityRun& flagged,
                           std::size_t run_index, double nominal_step, const RunControl& control) {
  BranchChange change;
  change.run = run_index;
  change.parameter = flagged.parameter;
  change.nominal_value = flagged.factor;
  const double step = flagged.factor - 1.0;
  double on = 0.0, off = 1.0;  // fractions of the step
  const SensitivityRun* on_run = &base;
  const SensitivityRun* off_run = &flagged;
  change.bisection_runs.reserve(static_cast<std::size_t>(std::max(0, options.branch_bisections)));
  for (int level = 0; level < options.branch_bisections; ++level) {
    if (options.stop && options.stop->load()) break;
    const double middle = 0.5 * (on + off);
    const double value = 1.0 + middle * step;
    const Job job{{{flagged.parameter, value}}, flagged.parameter, value};
    SensitivityRun run = run_one(model_path, model_text, design, job, options.settings, options.run_time_limit, control);
    run.outcomes.window = options.branch_window;
    change.bisection_runs.push_back(std::move(run));
    const SensitivityRun& made = change.bisection_runs.back();
    if (!made.ok) {
      change.note = "bisection run at " + parameter_value_text(value) + " failed: " + made.message;
      break;
    }
    if (same_branch(made.outcomes, base.outcomes)) {
      on = middle;
      on_run = &made;
    } else {
      off = middle;
      off_run = &made;
      if (made.outcomes.order() != flagged.outcomes.order() && change.note.empty())
        change.note = "at " + parameter_value_text(value) + " a third branch (" + made.outcomes.order() + ")";
    }
  }
  change.on_branch_value = 1.0 + on * step;
  change.off_branch_value = 1.0 + off * step;
  change.off_branch_signature = off_run->outcomes.text();
  for (int k = 0; k < 3; ++k) {
    const double r_base = response(base.responses, k), r_on = response(on_run->responses, k),
                 r_off = response(off_run->responses, k), r_nominal = response(flagged.responses, k);
    change.nominal_derivative[k] = (r_nominal - r_base) / nominal_step;
    change.within_branch[k] = on > 0.0 ? (r_on - r_base) / (on * step) : kNaN;
    const double trend = std::isnan(change.within_branch[k]) ? 0.0 : change.within_branch[k] * (off - on) * step;
    change.jump[k] = r_off - r_on - trend;
  }
  return change;
}

std::string point_text(const SensitivityPoint& point, const char* separator = " ") {
  std::string text;
  for (const auto& [name, value] : point) {
    char item[64];
    std::snprintf(item, sizeof item, "%s%s=%g", text.empty() ? "" : separator, name.c_str(), value);
    text += item;
  }
  return text.empty() ? "base" : text;
}

}  // namespace

std::string SensitivityTerm::label() const {
  if (linear()) return first;
  if (square()) return first + "^2";
  return first + "*" + second;
}

double SensitivityTerm::value(const SensitivityPoint& values) const {
  const auto of = [&](const std::string& name) {
    for (const auto& [n, v] : values)
      if (n == name) return v;
    return 1.0;
  };
  return linear() ? of(first) : of(first) * of(second);
}

std::string SensitivityDerivative::label() const {
  if (second.empty()) return "d/d" + first;
  if (second == first) return "d2/d" + first + "^2";
  return "d2/d" + first + "d" + second;
}

SensitivityDesign load_design(const std::string& path) {
  const YAML::Node root = load_yaml_file(path, "design file");
  if (!root.IsMap() || !root["sensitivity"]) yaml_error(path, root, "a design file starts with 'sensitivity: 1'");
  SensitivityDesign design;
  if (root["factor"]) {
    design.factor = root["factor"].as<double>();
    if (!(design.factor > 0.0) || design.factor == 1.0) yaml_error(path, root["factor"], "factor must be positive and not 1");
  }
  const YAML::Node parameters = root["parameters"];
  if (!parameters || !parameters.IsSequence() || parameters.size() == 0)
    yaml_error(path, root, "'parameters' must list the parameters: - {name, description, scale: [{key, power}]}");
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    const YAML::Node p = parameters[i];
    if (!p.IsMap() || !p["name"] || !p["scale"] || !p["scale"].IsSequence())
      yaml_error(path, p, "each parameter needs 'name' and a 'scale' list of {key, power}");
    SensitivityParameter parameter;
    parameter.name = parameter_name(path, p["name"]);
    if (find_parameter(design, parameter.name)) yaml_error(path, p["name"], "parameter '" + parameter.name + "' is listed twice");
    parameter.description = p["description"] ? p["description"].as<std::string>() : "";
    for (std::size_t k = 0; k < p["scale"].size(); ++k) {
      const YAML::Node s = p["scale"][k];
      if (!s.IsMap() || !s["key"]) yaml_error(path, s, "parameter '" + parameter.name + "': each scale entry needs 'key'");
      parameter.scales.emplace_back(s["key"].as<std::string>(), s["power"] ? s["power"].as<double>() : 1.0);
      parameter.scale_sources.push_back(SourceLocation{path, yaml_line(s)});
    }
    design.parameters.push_back(std::move(parameter));
  }
  if (root["second_order"]) load_second_order(path, root["second_order"], design);
  if (root["reference"]) load_reference(path, root["reference"], design);
  return design;
}

std::string default_design_path(const std::string& model_path) {
  const std::filesystem::path model(model_path);
  const std::filesystem::path design = model.parent_path() / "sensitivity_design.yaml";
  if (!std::filesystem::exists(design))
    throw InputError(model_path + ": the report's design is the file sensitivity_design.yaml beside the model, and " +
                     design.string() + " does not exist; pass --design FILE");
  return design.string();
}

QuadraticFit fit_quadratic(const std::vector<SensitivityTerm>& terms, const std::vector<SensitivitySample>& samples) {
  QuadraticFit fit;
  fit.terms = terms;
  const int n = static_cast<int>(terms.size()) + 1;  // + the constant
  const int m = static_cast<int>(samples.size());
  fit.unknowns = n;
  fit.equations = m;
  for (const SensitivitySample& s : samples) fit.samples.push_back(s.label);
  const auto term_label = [&](int column) { return column == 0 ? std::string("1") : terms[column - 1].label(); };

  Eigen::MatrixXd design_matrix(m, n);
  Eigen::MatrixXd right(m, 3);
  for (int i = 0; i < m; ++i) {
    design_matrix(i, 0) = 1.0;
    for (int k = 1; k < n; ++k) design_matrix(i, k) = terms[k - 1].value(samples[i].point);
    for (int r = 0; r < 3; ++r) right(i, r) = samples[i].responses[r];
  }
  Eigen::MatrixXd solution = Eigen::MatrixXd::Constant(n, 3, kNaN);
  if (m == 0) {
    fit.rank = 0;
    fit.condition_number = std::numeric_limits<double>::infinity();
    for (int k = 0; k < n; ++k) fit.undetermined.push_back(term_label(k));
  } else {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(design_matrix, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::VectorXd& sigma = svd.singularValues();
    int rank = 0;
    for (int k = 0; k < sigma.size(); ++k) rank += sigma(k) > kRankTolerance * sigma(0);
    fit.rank = rank;
    fit.condition_number = rank == n ? sigma(0) / sigma(n - 1) : std::numeric_limits<double>::infinity();
    if (rank == n) {
      if (m == n)
        solution = Eigen::FullPivLU<Eigen::MatrixXd>(design_matrix).solve(right);
      else
        solution = Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(design_matrix).solve(right);
      fit.largest_residual = (design_matrix * solution - right).cwiseAbs().maxCoeff();
    } else {
      // Minimum-norm solution; a constant with a component in the null space is not determined.
      Eigen::MatrixXd pseudo_solution = Eigen::MatrixXd::Zero(n, 3);
      const Eigen::MatrixXd& u = svd.matrixU();
      const Eigen::MatrixXd& v = svd.matrixV();
      for (int k = 0; k < rank; ++k) pseudo_solution += v.col(k) * (u.col(k).transpose() * right) / sigma(k);
      for (int j = 0; j < n; ++j) {
        const double in_null_space = v.row(j).tail(n - rank).norm();
        if (in_null_space > 1e-8) {
          fit.undetermined.push_back(term_label(j));
        } else {
          solution.row(j) = pseudo_solution.row(j);
        }
      }
    }
  }
  for (int r = 0; r < 3; ++r) fit.constant[r] = solution(0, r);
  for (int k = 1; k < n; ++k) fit.coefficients.push_back({solution(k, 0), solution(k, 1), solution(k, 2)});

  // Derivatives at P = 1: first by every parameter of the form, then 2 B_ii, then B_ij.
  std::vector<std::string> parameters;
  for (const SensitivityTerm& t : terms)
    for (const std::string& name : {t.first, t.second})
      if (!name.empty() && std::find(parameters.begin(), parameters.end(), name) == parameters.end())
        parameters.push_back(name);
  for (const std::string& p : parameters) {
    SensitivityDerivative d{p, "", {0.0, 0.0, 0.0}};
    for (std::size_t k = 0; k < terms.size(); ++k) {
      const SensitivityTerm& t = terms[k];
      const double slope = t.linear() ? (t.first == p ? 1.0 : 0.0)
                                      : (t.square() ? (t.first == p ? 2.0 : 0.0) : (t.first == p || t.second == p ? 1.0 : 0.0));
      if (slope != 0.0)
        for (int r = 0; r < 3; ++r) d.value[r] += slope * fit.coefficients[k][r];
    }
    fit.derivatives.push_back(d);
  }
  for (const bool squares : {true, false})
    for (std::size_t k = 0; k < terms.size(); ++k) {
      const SensitivityTerm& t = terms[k];
      if (t.linear() || t.square() != squares) continue;
      SensitivityDerivative d{t.first, t.second, {}};
      for (int r = 0; r < 3; ++r) d.value[r] = (squares ? 2.0 : 1.0) * fit.coefficients[k][r];
      fit.derivatives.push_back(d);
    }
  return fit;
}

void check_sensitivity_inputs(const CheckedYamlText& model_text, const std::string& model_path, const SensitivityDesign& design,
                              const SensitivityOptions& options, bool every_run) {
  std::size_t first_order_count = 0;
  const std::vector<Job> jobs = study_jobs(design, options, first_order_count);
  const auto check = [&](const std::vector<std::string>& settings, const Job& job) {
    try {
      (void)load_model_text(model_text, model_path, settings);
    } catch (const InputError& e) {
      const std::string entry = bad_scale_entry(model_text, model_path, design, job, options.settings);
      if (!entry.empty()) throw InputError(entry);
      throw InputError(std::string(e.what()) + (job.parameter.empty() ? " (the base run)" : " (design parameter " + job.parameter + ")"));
    }
  };
  if (!every_run) {
    // Every parameter's factors at once: one load finds a missing key or a zero value; the runs
    // are loaded one by one only to name the entry.
    std::vector<std::string> all = options.settings;
    for (std::size_t k = 1; k < jobs.size(); ++k) {
      const std::vector<std::string> settings = job_settings(design, jobs[k], {});
      all.insert(all.end(), settings.begin(), settings.end());
    }
    try {
      (void)load_model_text(model_text, model_path, all);
      return;
    } catch (const InputError&) {
    }
  }
  // Every run's model, as the run will load it: a scale key the model lacks, a bad value, or a
  // parameter whose model value is 0 (a factor would change nothing, and the study would call it
  // "no effect") stops the study before its first run.
  for (const Job& job : jobs) {
    if (options.stop && options.stop->load()) return;  // interrupted: run_sensitivity starts no run
    check(job_settings(design, job, options.settings), job);
  }
}

std::size_t sensitivity_run_count(const SensitivityDesign& design, const SensitivityOptions& options) {
  std::size_t first_order_count = 0;
  return study_jobs(design, options, first_order_count).size();
}

SensitivityResult run_sensitivity(const std::string& model_path, const SensitivityDesign& design,
                                  const SensitivityOptions& options) {
  const CheckedYamlText model_text = check_model_text(read_model_text(model_path), model_path);  // once for every run
  require_run_count(sensitivity_run_count(design, options), options.max_runs, "the sensitivity study");
  check_sensitivity_inputs(model_text, model_path, design, options, true);
  SensitivityResult result;
  result.central = options.central_step > 0.0;
  std::size_t first_order_count = 0;
  const std::vector<Job> jobs = study_jobs(design, options, first_order_count);
  std::vector<SensitivityTerm> terms;
  if (options.second_order)
    for (const SensitivityTerm& t : design.second_order.terms)
      if (is_chosen(options, t.first) && (t.linear() || is_chosen(options, t.second))) terms.push_back(t);

  std::vector<SensitivityRun> runs(jobs.size());
  std::size_t done = 0;
  BatchOptions batch;
  batch.jobs = options.jobs;
  batch.run_time_limit = options.run_time_limit;
  batch.stop = options.stop;
  const std::vector<BatchRunState> states = run_batch(
      jobs.size(),
      [&](std::size_t k, const RunControl& control) {
        runs[k] = run_one(model_path, model_text, design, jobs[k], options.settings, options.run_time_limit, control);
        runs[k].outcomes.window = options.branch_window;
      },
      batch,
      [&](std::size_t k, BatchRunState state) {
        if (state == BatchRunState::interrupted) mark_interrupted(runs[k]);
        if (options.progress) options.progress(runs[k], k, ++done, jobs.size());
      });
  result.runs_total = jobs.size();
  result.runs_finished = finished_runs(states);
  result.interrupted = result.runs_finished < result.runs_total;
  for (std::size_t k = 0; k < jobs.size(); ++k) {
    if (states[k] == BatchRunState::not_started) {
      runs[k].variation = jobs[k].variation;
      runs[k].parameter = jobs[k].parameter;
      runs[k].factor = jobs[k].factor;
      mark_interrupted(runs[k]);
      runs[k].message = "not run: the study was interrupted";
    }
  }

  result.base = runs[0];
  result.runs.assign(runs.begin() + 1, runs.begin() + 1 + static_cast<std::ptrdiff_t>(first_order_count));
  result.second_order_runs.assign(runs.begin() + 1 + static_cast<std::ptrdiff_t>(first_order_count), runs.end());

  // First order: A_i and A0 (equations 1-3).
  const std::size_t per_parameter = result.central ? 2 : 1;
  result.constant = result.base.ok ? responses_of(result.base) : std::array<double, 3>{kNaN, kNaN, kNaN};
  for (std::size_t i = 0; i < first_order_count / per_parameter; ++i) {
    std::array<double, 3> d{kNaN, kNaN, kNaN};
    for (int k = 0; k < 3; ++k) {
      if (result.central) {
        const SensitivityRun& plus = result.runs[2 * i];
        const SensitivityRun& minus = result.runs[2 * i + 1];
        if (plus.ok && minus.ok)
          d[k] = (response(plus.responses, k) - response(minus.responses, k)) / (2.0 * options.central_step);
      } else {
        const SensitivityRun& run = result.runs[i];
        if (run.ok && result.base.ok)
          d[k] = (response(run.responses, k) - response(result.base.responses, k)) / (design.factor - 1.0);
      }
      result.constant[k] -= d[k];
    }
    result.derivatives.push_back(d);
  }

  // Branch changes (issue 40): every first-order run off run 0's branch, bisected towards 1.
  if (result.base.ok && !result.interrupted) {
    std::vector<std::size_t> flagged;
    for (std::size_t i = 0; i < result.runs.size(); ++i)
      if (result.runs[i].ok && !same_branch(result.runs[i].outcomes, result.base.outcomes)) flagged.push_back(i);
    result.branch_changes.resize(flagged.size());
    const std::vector<BatchRunState> bisected = run_batch(
        flagged.size(),
        [&](std::size_t k, const RunControl& control) {
          const SensitivityRun& run = result.runs[flagged[k]];
          const double nominal_step = result.central ? run.factor - 1.0 : design.factor - 1.0;
          result.branch_changes[k] =
              bisect_branch(model_path, model_text, design, options, result.base, run, flagged[k], nominal_step, control);
        },
        batch);
    for (std::size_t k = 0; k < flagged.size(); ++k) {
      if (bisected[k] == BatchRunState::finished) {
        result.bisection_runs += result.branch_changes[k].bisection_runs.size();
        continue;
      }
      BranchChange& change = result.branch_changes[k];  // interrupted: the run is flagged, not bisected
      change = BranchChange{};
      change.run = flagged[k];
      change.parameter = result.runs[flagged[k]].parameter;
      change.nominal_value = change.off_branch_value = result.runs[flagged[k]].factor;
      change.off_branch_signature = result.runs[flagged[k]].outcomes.text();
      change.within_branch = change.jump = change.nominal_derivative = {kNaN, kNaN, kNaN};
      change.note = "not bisected: the study was interrupted";
    }
  }

  // Second order: every run that varies only parameters of the form.
  if (!terms.empty()) {
    std::vector<std::string> term_parameters;
    for (const SensitivityTerm& t : terms) {
      term_parameters.push_back(t.first);
      if (!t.linear()) term_parameters.push_back(t.second);
    }
    const auto in_form = [&](const SensitivityPoint& point) {
      return std::all_of(point.begin(), point.end(), [&](const auto& entry) {
        return std::find(term_parameters.begin(), term_parameters.end(), entry.first) != term_parameters.end();
      });
    };
    std::vector<SensitivitySample> samples;
    for (std::size_t k = 0; k < runs.size(); ++k) {
      if (!in_form(runs[k].variation)) continue;
      const std::string label = "run " + std::to_string(k) + " (" + point_text(runs[k].variation) + ")";
      if (!runs[k].ok) {
        result.fit_note += (result.fit_note.empty() ? "" : "; ") + label + " failed and is left out";
        continue;
      }
      samples.push_back(SensitivitySample{label, runs[k].variation, responses_of(runs[k])});
    }
    result.fit = fit_quadratic(terms, samples);
  }
  return result;
}

namespace {

std::string number(double value, const char* format = "%.3f") { return table_number(value, format); }

// "R1 = 1.980 - 0.005 P5 - 0.180 P6 ..." with terms that round to zero at 3 decimals left out.
std::string equation(int response_index, double constant, const std::vector<std::pair<std::string, double>>& terms) {
  std::string text = "R" + std::to_string(response_index + 1) + " = " + number(constant);
  for (const auto& [label, value] : terms) {
    if (!std::isnan(value) && std::abs(value) < 0.0005) continue;
    text += (value < 0.0 ? " - " : " + ") + number(std::abs(value)) + " " + label;
  }
  return text;
}

/// sensitivity.csv's branch column: "base" (run 0), "same" (run 0's branch), "changed", or ""
/// (a failed run has no outcome to compare).
std::string branch_label(const SensitivityRun& run, const SensitivityRun& base, bool is_base) {
  if (is_base) return base.ok ? "base" : "";
  if (!run.ok || !base.ok) return "";
  return same_branch(run.outcomes, base.outcomes) ? "same" : "changed";
}

/// The branch changes (issue 40): the Markdown section and sensitivity_branches.csv.
void write_branch_changes(const SensitivityResult& result, const std::string& directory, std::ostringstream& md) {
  if (!result.base.ok) return;
  std::ostringstream csv;  // sensitivity_branches.csv, written whole (whole_file.hpp)
  csv << "run,parameter,nominal_value,on_branch_value,off_branch_value,extra_runs,"
         "A_R1,A_R2,A_R3,within_R1,within_R2,within_R3,jump_R1,jump_R2,jump_R3,off_branch_outcomes,note\n";
  md << "\n## Discrete outcomes and branch changes\n\n"
     << "Run 0's outcome: `" << result.base.outcomes.text() << "` (branch `" << result.base.outcomes.order()
     << "`; " << (std::isinf(result.base.outcomes.window)
                        ? std::string("runs are compared by the set of outcomes, order between elements aside")
                        : "outcomes within " + number(1e3 * result.base.outcomes.window, "%g") +
                              " ms of each other form one group, compared as a set, and the groups in order")
     << ").\n\n";
  std::size_t changed = 0;
  for (const SensitivityRun& r : result.runs) changed += r.ok && !same_branch(r.outcomes, result.base.outcomes);
  std::size_t changed_second = 0;
  for (const SensitivityRun& r : result.second_order_runs) changed_second += r.ok && !same_branch(r.outcomes, result.base.outcomes);
  md << changed << " of " << result.runs.size() << " first-order runs";
  if (!result.second_order_runs.empty()) md << " and " << changed_second << " of " << result.second_order_runs.size() << " second-order runs";
  md << " end on another branch (sensitivity.csv, column branch). A finite difference across a branch change is not a "
        "sensitivity: for each first-order run off run 0's branch, the step is halved until the run stays on it ("
     << result.bisection_runs << " extra runs in all), and the effect within run 0's branch (dR/dP from run 0 to the "
        "largest step on it) and the jump where the branch changes (R beyond the change minus R before it, less the "
        "within-branch trend) are given apart. The change lies between the two values of P.\n\n";
  if (result.branch_changes.empty()) {
    write_whole_file(directory + "/sensitivity_branches.csv", csv.str());
    return;
  }
  md << "| Run | Parameter | P on branch | P off branch | A (nominal) R1 | R2 | R3 | within R1 | R2 | R3 | jump R1 | R2 | R3 | "
        "outcome off the branch |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const BranchChange& c : result.branch_changes) {
    csv << c.run + 1 << ',' << c.parameter << ',' << csv_number(c.nominal_value) << ',' << csv_number(c.on_branch_value) << ','
        << csv_number(c.off_branch_value) << ',' << c.bisection_runs.size();
    md << "| " << c.run + 1 << " | " << c.parameter << " | " << number(c.on_branch_value, "%.4g") << " | "
       << number(c.off_branch_value, "%.4g") << " |";
    for (const auto* values : {&c.nominal_derivative, &c.within_branch, &c.jump})
      for (int k = 0; k < 3; ++k) {
        csv << ',' << csv_number((*values)[static_cast<std::size_t>(k)]);
        md << ' ' << number((*values)[static_cast<std::size_t>(k)]) << " |";
      }
    csv << ',' << csv_text(c.off_branch_signature) << ',' << csv_text(c.note) << '\n';
    md << " `" << c.off_branch_signature << "`" << (c.note.empty() ? "" : " (" + c.note + ")") << " |\n";
  }
  write_whole_file(directory + "/sensitivity_branches.csv", csv.str());
}

std::string power_label(const SensitivityTerm& t) {
  if (t.linear()) return t.first;
  if (t.square()) return t.first + "^2";
  return t.first + " " + t.second;
}

}  // namespace

std::string write_sensitivity(const SensitivityResult& result, const SensitivityDesign& design, const std::string& directory) {
  std::filesystem::create_directories(directory);
  const auto description = [&](const std::string& name) {
    const SensitivityParameter* p = find_parameter(design, name);
    return p ? p->description : std::string();
  };
  const std::size_t per_parameter = result.central ? 2 : 1;
  const auto parameter_of = [&](std::size_t i) { return result.runs[per_parameter * i].parameter; };
  const auto percent = [&](double now, double base) { return base != 0.0 ? 100.0 * (now - base) / base : 0.0; };
  std::ostringstream md;
  if (result.interrupted)
    md << "**Interrupted after " << result.runs_finished << " of " << result.runs_total
       << " runs** (SIGINT/SIGTERM): the runs not finished are marked interrupted, and the fits use the finished runs only.\n\n";

  // Runs: sensitivity.csv, and Table 11 / Tables 12-13 in the Markdown.
  {
    std::ostringstream csv;
    csv << "run,order,parameters,values,status,R1,R2,R3,override,wall_seconds,message,branch,outcomes,integrator_used,euler_from_t\n";
    std::vector<const SensitivityRun*> all{&result.base};
    for (const SensitivityRun& r : result.runs) all.push_back(&r);
    for (const SensitivityRun& r : result.second_order_runs) all.push_back(&r);
    for (std::size_t k = 0; k < all.size(); ++k) {
      const SensitivityRun& r = *all[k];
      std::string names, values;
      for (const auto& [name, value] : r.variation) {
        names += (names.empty() ? "" : " ") + name;
        values += (values.empty() ? "" : " ") + number(value, "%g");
      }
      const int order = k == 0 ? 0 : (k <= result.runs.size() ? 1 : 2);
      csv << k << ',' << order << ',' << names << ',' << values << ',' << (r.ok ? "ok" : (r.interrupted ? "interrupted" : "failed")) << ','
          << csv_number(r.responses.r1) << ',' << csv_number(r.responses.r2) << ',' << csv_number(r.responses.r3) << ','
          << (r.responses.overridden ? 1 : 0) << ',' << number(r.wall_seconds, "%.2f") << ',' << csv_text(r.message) << ','
          << branch_label(r, result.base, k == 0) << ',' << csv_text(r.ok ? r.outcomes.text() : "") << ','
          << r.integrator.method << ',' << r.integrator.euler_from_t_text() << '\n';
    }
    write_whole_file(directory + "/sensitivity.csv", csv.str());
  }
  md << "## Runs, first order (report Table 11)\n\n"
     << "| Run | Parameter varied | Factor | R1 | R2 | R3 | dR1 % | dR2 % | dR3 % |\n|---|---|---|---|---|---|---|---|---|\n";
  const Responses& base = result.base.responses;
  const auto result_cells = [&](const SensitivityRun& r) {
    if (!r.ok) return "failed: " + r.message + " | | | | | |";
    char cells[256];
    std::snprintf(cells, sizeof cells, "%.3f | %.3f | %.3f | %+.2f | %+.2f | %+.2f |", r.responses.r1, r.responses.r2,
                  r.responses.r3, percent(r.responses.r1, base.r1), percent(r.responses.r2, base.r2),
                  percent(r.responses.r3, base.r3));
    return std::string(cells);
  };
  md << "| 0 | base | 1 | " << result_cells(result.base) << "\n";
  for (std::size_t k = 0; k < result.runs.size(); ++k)
    md << "| " << k + 1 << " | " << result.runs[k].parameter << " | " << number(result.runs[k].factor, "%g") << " | "
       << result_cells(result.runs[k]) << "\n";

  if (!result.second_order_runs.empty()) {
    std::vector<std::string> varied;  // design order
    for (const SensitivityParameter& p : design.parameters)
      for (const SensitivityRun& r : result.second_order_runs)
        if (std::any_of(r.variation.begin(), r.variation.end(), [&](const auto& e) { return e.first == p.name; }) &&
            std::find(varied.begin(), varied.end(), p.name) == varied.end())
          varied.push_back(p.name);
    md << "\n## Runs, second order (report Tables 12 and 13; parameters not shown are 1.0)\n\n| Run |";
    for (const std::string& name : varied) md << ' ' << name << " |";
    md << " R1 | R2 | R3 | dR1 % | dR2 % | dR3 % |\n|---|";
    for (std::size_t k = 0; k < varied.size() + 6; ++k) md << "---|";
    md << '\n';
    for (std::size_t k = 0; k < result.second_order_runs.size(); ++k) {
      const SensitivityRun& r = result.second_order_runs[k];
      md << "| " << k + 1 + result.runs.size() << " |";
      for (const std::string& name : varied) {
        double value = 1.0;
        for (const auto& [n, v] : r.variation)
          if (n == name) value = v;
        md << ' ' << number(value, "%.1f") << " |";
      }
      md << ' ' << result_cells(r) << '\n';
    }
  }

  write_branch_changes(result, directory, md);

  // First-order coefficients: equations (1)-(3) and sensitivity_first_order.csv.
  {
    std::ostringstream csv;
    csv << "term,description,R1,R2,R3\n1,constant A0," << csv_number(result.constant[0]) << ','
        << csv_number(result.constant[1]) << ',' << csv_number(result.constant[2]) << '\n';
    for (std::size_t i = 0; i < result.derivatives.size(); ++i)
      csv << parameter_of(i) << ',' << csv_text(description(parameter_of(i))) << ',' << csv_number(result.derivatives[i][0])
          << ',' << csv_number(result.derivatives[i][1]) << ',' << csv_number(result.derivatives[i][2]) << '\n';
    write_whole_file(directory + "/sensitivity_first_order.csv", csv.str());
    md << "\n## First-order fit (report equations 1-3)\n\n"
       << (result.central ? "A_i = (R(1+h) - R(1-h)) / 2h" : "A_i = (R(run i) - R(run 0)) / (factor - 1)")
       << ", A0 = R(run 0) - sum A_i; terms that round to 0.000 are left out, as in the report.\n\n```\n";
    for (int k = 0; k < 3; ++k) {
      std::vector<std::pair<std::string, double>> terms;
      for (std::size_t i = 0; i < result.derivatives.size(); ++i) terms.emplace_back(parameter_of(i), result.derivatives[i][k]);
      md << equation(k, result.constant[k], terms) << '\n';
    }
    md << "```\n";
  }

  // Second-order fit, its constants and the derivatives at P = 1 (Table 14).
  const QuadraticFit& fit = result.fit;
  const auto second_order_derivative = [&](const std::string& name, int k) {
    for (const SensitivityDerivative& d : fit.derivatives)
      if (d.second.empty() && d.first == name) return d.value[k];
    return kNaN;
  };
  if (!fit.terms.empty()) {
    std::ostringstream csv;
    csv << "term,R1,R2,R3\n1," << csv_number(fit.constant[0]) << ',' << csv_number(fit.constant[1]) << ','
        << csv_number(fit.constant[2]) << '\n';
    for (std::size_t k = 0; k < fit.terms.size(); ++k)
      csv << fit.terms[k].label() << ',' << csv_number(fit.coefficients[k][0]) << ',' << csv_number(fit.coefficients[k][1])
          << ',' << csv_number(fit.coefficients[k][2]) << '\n';
    write_whole_file(directory + "/sensitivity_second_order.csv", csv.str());
    md << "\n## Second-order fit (report Section 4.4, reduced second-order form)\n\n";
    std::string term_list = "1";
    for (const SensitivityTerm& t : fit.terms) term_list += ", " + t.label();
    md << fit.unknowns << " constants (terms " << term_list << ") from " << fit.equations << " runs: "
       << (fit.equations == fit.unknowns ? "square system" : fit.equations > fit.unknowns ? "least squares" : "fewer runs than constants")
       << ", rank " << fit.rank << ", condition number " << number(fit.condition_number, "%.3g");
    if (fit.determined() && fit.equations > fit.unknowns) md << ", largest residual " << number(fit.largest_residual, "%.3g");
    md << ".\nRuns used: ";
    for (std::size_t k = 0; k < fit.samples.size(); ++k) md << (k ? ", " : "") << fit.samples[k];
    md << ".\n";
    if (!result.fit_note.empty()) md << "Left out: " << result.fit_note << ".\n";
    if (!fit.undetermined.empty()) {
      md << "**Not determined** (the runs used cannot separate them; they are n/a below): ";
      for (std::size_t k = 0; k < fit.undetermined.size(); ++k) md << (k ? ", " : "") << fit.undetermined[k];
      md << ".\n";
    }
    md << "\n```\n";
    for (int k = 0; k < 3; ++k) {
      std::vector<std::pair<std::string, double>> terms;
      for (std::size_t i = 0; i < fit.terms.size(); ++i) terms.emplace_back(power_label(fit.terms[i]), fit.coefficients[i][k]);
      md << equation(k, fit.constant[k], terms) << '\n';
    }
    md << "```\n\n## Derivatives at the design point, all P = 1 (report Table 14)\n\n"
       << "| Derivative | R1 | R2 | R3 | first order: R1 | R2 | R3 |\n|---|---|---|---|---|---|---|\n";
    std::ostringstream derivatives_csv;
    derivatives_csv << "derivative,R1,R2,R3,first_order_R1,first_order_R2,first_order_R3\n";
    for (const SensitivityDerivative& d : fit.derivatives) {
      std::array<double, 3> first_order{kNaN, kNaN, kNaN};
      if (d.second.empty())
        for (std::size_t i = 0; i < result.derivatives.size(); ++i)
          if (parameter_of(i) == d.first) first_order = result.derivatives[i];
      md << "| " << d.label() << " | " << number(d.value[0]) << " | " << number(d.value[1]) << " | " << number(d.value[2])
         << " | " << (d.second.empty() ? number(first_order[0]) : "") << " | " << (d.second.empty() ? number(first_order[1]) : "")
         << " | " << (d.second.empty() ? number(first_order[2]) : "") << " |\n";
      derivatives_csv << d.label() << ',' << csv_number(d.value[0]) << ',' << csv_number(d.value[1]) << ','
                      << csv_number(d.value[2]) << ',' << csv_number(first_order[0]) << ',' << csv_number(first_order[1])
                      << ',' << csv_number(first_order[2]) << '\n';
    }
    write_whole_file(directory + "/sensitivity_derivatives.csv", derivatives_csv.str());
  }

  // Rankings (Tables 15-17): by |first-order coefficient|, as the report ranks them.
  std::ostringstream ranking_csv;
  ranking_csv << "response,rank,parameter,description,first_order,second_order_derivative\n";
  static const char* const kTitles[3] = {"Crush sensitivity (R1, report Table 15)", "Override sensitivity (R2, report Table 16)",
                                         "Crush with subsequent override sensitivity (R3, report Table 17)"};
  const std::size_t count = result.derivatives.size();
  for (int k = 0; k < 3; ++k) {
    std::vector<std::size_t> order(count);
    for (std::size_t i = 0; i < count; ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      const double da = std::abs(result.derivatives[a][k]), db = std::abs(result.derivatives[b][k]);
      return (std::isnan(db) && !std::isnan(da)) || da > db;
    });
    md << "\n## " << kTitles[k] << "\n\nRanked by the first-order coefficient (equation " << k + 1
       << ")" << (result.central ? ", central differences" : "")
       << "; the last column is dR/dP at P = 1 from the second-order form where it has the parameter.\n\n"
       << "| Rank | Parameter | Physical description | Sensitivity | second-order dR/dP |\n|---|---|---|---|---|\n";
    std::string negligible, failed;
    int rank = 0;
    for (std::size_t i : order) {
      const double value = result.derivatives[i][k];
      const std::string name = parameter_of(i);
      ranking_csv << 'R' << k + 1 << ',' << (std::isnan(value) ? 0 : ++rank) << ',' << name << ','
                  << csv_text(description(name)) << ',' << csv_number(value) << ','
                  << csv_number(second_order_derivative(name, k)) << '\n';
      if (std::isnan(value)) {
        failed += (failed.empty() ? "" : ", ") + name;
      } else if (std::abs(value) < 0.0005) {
        negligible += (negligible.empty() ? "" : ", ") + name;
      } else {
        const double second = second_order_derivative(name, k);
        md << "| " << rank << " | " << name << " | " << description(name) << " | " << number(value) << " | "
           << (std::isnan(second) ? "" : number(second)) << " |\n";
      }
    }
    if (!negligible.empty()) md << "\nNo effect at 3 decimals (|dR/dP| < 0.0005): " << negligible << ".\n";
    if (!failed.empty()) md << "\nNot available (a run failed): " << failed << ".\n";
  }
  write_whole_file(directory + "/sensitivity_ranking.csv", ranking_csv.str());
  write_whole_file(directory + "/sensitivity.md", md.str());
  return md.str();
}

}  // namespace railcrash
