#include "railcrash/sensitivity.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>

#include "railcrash/model_io.hpp"
#include "railcrash/run.hpp"

namespace railcrash {

namespace {

[[noreturn]] void design_error(const std::string& path, const YAML::Node& node, const std::string& message) {
  const int line = node && !node.Mark().is_null() ? node.Mark().line + 1 : 0;
  throw InputError(SourceLocation{path, line}.prefix() + message);
}

struct Job {
  const SensitivityParameter* parameter = nullptr;  // null: base run
  double factor = 1.0;
};

SensitivityRun run_one(const std::string& model_path, const Job& job) {
  SensitivityRun run;
  run.parameter = job.parameter ? job.parameter->name : "";
  run.factor = job.factor;
  const auto start = std::chrono::steady_clock::now();
  try {
    std::vector<std::string> settings;
    if (job.parameter)
      for (const auto& [key, power] : job.parameter->scales) {
        char text[64];
        std::snprintf(text, sizeof text, "%.17g", std::pow(job.factor, power));
        settings.push_back(key + "*=" + text);
      }
    const Model model = load_model(model_path, settings);
    if (!model.responses.defined())
      throw InputError(model_path + ": a parameter study needs a 'responses' section (R1-R3) in the model");
    const RunReport report = run_model(model, "");
    run.ok = report.outcome.ok;
    run.message = report.outcome.message;
    run.responses = report.responses;
  } catch (const std::exception& e) {
    run.ok = false;
    run.message = e.what();
  }
  run.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

double response(const Responses& r, int k) { return k == 0 ? r.r1 : (k == 1 ? r.r2 : r.r3); }

}  // namespace

SensitivityDesign load_design(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InputError(path + ": cannot open the design file (check the path)");
  } catch (const YAML::ParserException& e) {
    throw InputError(SourceLocation{path, e.mark.line + 1}.prefix() + "not valid YAML: " + e.msg);
  }
  if (!root.IsMap() || !root["sensitivity"]) design_error(path, root, "a design file starts with 'sensitivity: 1'");
  SensitivityDesign design;
  if (root["factor"]) {
    design.factor = root["factor"].as<double>();
    if (!(design.factor > 0.0) || design.factor == 1.0) design_error(path, root["factor"], "factor must be positive and not 1");
  }
  const YAML::Node parameters = root["parameters"];
  if (!parameters || !parameters.IsSequence() || parameters.size() == 0)
    design_error(path, root, "'parameters' must list the parameters: - {name, description, scale: [{key, power}]}");
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    const YAML::Node p = parameters[i];
    if (!p.IsMap() || !p["name"] || !p["scale"] || !p["scale"].IsSequence())
      design_error(path, p, "each parameter needs 'name' and a 'scale' list of {key, power}");
    SensitivityParameter parameter;
    parameter.name = p["name"].as<std::string>();
    parameter.description = p["description"] ? p["description"].as<std::string>() : "";
    for (std::size_t k = 0; k < p["scale"].size(); ++k) {
      const YAML::Node s = p["scale"][k];
      if (!s.IsMap() || !s["key"]) design_error(path, s, "parameter '" + parameter.name + "': each scale entry needs 'key'");
      parameter.scales.emplace_back(s["key"].as<std::string>(), s["power"] ? s["power"].as<double>() : 1.0);
    }
    design.parameters.push_back(std::move(parameter));
  }
  return design;
}

SensitivityResult run_sensitivity(const std::string& model_path, const SensitivityDesign& design,
                                  const SensitivityOptions& options) {
  if (options.central_step < 0.0 || options.central_step >= 1.0)
    throw InputError("--central H: H must be between 0 and 1 (e.g. 0.05 for runs at 0.95 and 1.05)");
  std::vector<const SensitivityParameter*> chosen;
  for (const SensitivityParameter& p : design.parameters)
    if (options.only.empty() || std::find(options.only.begin(), options.only.end(), p.name) != options.only.end())
      chosen.push_back(&p);
  for (const std::string& name : options.only)
    if (std::none_of(design.parameters.begin(), design.parameters.end(), [&](const auto& p) { return p.name == name; }))
      throw InputError("--only: the design has no parameter '" + name + "'");
  SensitivityResult result;
  result.central = options.central_step > 0.0;
  std::vector<Job> jobs{Job{}};
  for (const SensitivityParameter* p : chosen) {
    if (result.central) {
      jobs.push_back({p, 1.0 + options.central_step});
      jobs.push_back({p, 1.0 - options.central_step});
    } else {
      jobs.push_back({p, design.factor});
    }
  }
  std::vector<SensitivityRun> runs(jobs.size());
  std::atomic<std::size_t> next{0};
  const auto worker = [&]() {
    for (std::size_t k = next++; k < jobs.size(); k = next++) runs[k] = run_one(model_path, jobs[k]);
  };
  const int threads = std::max(1, std::min<int>(options.jobs, static_cast<int>(jobs.size())));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();

  result.base = runs[0];
  result.runs.assign(runs.begin() + 1, runs.end());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    std::array<double, 3> d{nan, nan, nan};
    for (int k = 0; k < 3; ++k) {
      if (result.central) {
        const SensitivityRun& plus = result.runs[2 * i];
        const SensitivityRun& minus = result.runs[2 * i + 1];
        if (plus.ok && minus.ok)
          d[static_cast<std::size_t>(k)] =
              (response(plus.responses, k) - response(minus.responses, k)) / (2.0 * options.central_step);
      } else {
        const SensitivityRun& run = result.runs[i];
        if (run.ok && result.base.ok)
          d[static_cast<std::size_t>(k)] =
              (response(run.responses, k) - response(result.base.responses, k)) / (design.factor - 1.0);
      }
    }
    result.derivatives.push_back(d);
  }
  return result;
}

std::string write_sensitivity(const SensitivityResult& result, const SensitivityDesign& design, const std::string& directory) {
  std::filesystem::create_directories(directory);
  const auto description = [&](const std::string& name) {
    for (const auto& p : design.parameters)
      if (p.name == name) return p.description;
    return std::string();
  };
  std::ofstream csv(directory + "/sensitivity.csv");
  csv << "run,parameter,factor,status,R1,R2,R3,override,message\n";
  std::ostringstream md;
  md << "| Run | Parameter varied | Factor | R1 | R2 | R3 | dR1 % | dR2 % | dR3 % |\n|---|---|---|---|---|---|---|---|---|\n";
  const auto row = [&](std::size_t index, const SensitivityRun& r) {
    char line[512];
    std::snprintf(line, sizeof line, "%zu,%s,%.6g,%s,%.6g,%.6g,%.6g,%d,\"%s\"\n", index, r.parameter.c_str(), r.factor,
                  r.ok ? "ok" : "failed", r.responses.r1, r.responses.r2, r.responses.r3, r.responses.overridden ? 1 : 0,
                  r.message.c_str());
    csv << line;
    if (!r.ok) {
      md << "| " << index << " | " << (r.parameter.empty() ? "base" : r.parameter) << " | " << r.factor << " | failed: "
         << r.message << " | | | | | |\n";
      return;
    }
    const auto percent = [&](double now, double base) { return base != 0.0 ? 100.0 * (now - base) / base : 0.0; };
    std::snprintf(line, sizeof line, "| %zu | %s | %.3g | %.3f | %.3f | %.3f | %+.2f | %+.2f | %+.2f |\n", index,
                  r.parameter.empty() ? "base" : r.parameter.c_str(), r.factor, r.responses.r1, r.responses.r2, r.responses.r3,
                  percent(r.responses.r1, result.base.responses.r1), percent(r.responses.r2, result.base.responses.r2),
                  percent(r.responses.r3, result.base.responses.r3));
    md << line;
  };
  row(0, result.base);
  for (std::size_t k = 0; k < result.runs.size(); ++k) row(k + 1, result.runs[k]);
  // Derivatives ranked by magnitude for each response (the report's Tables 15-17).
  const std::size_t count = result.derivatives.size();
  for (int k = 0; k < 3; ++k) {
    std::vector<std::size_t> order(count);
    for (std::size_t i = 0; i < count; ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      const double da = std::abs(result.derivatives[a][static_cast<std::size_t>(k)]);
      const double db = std::abs(result.derivatives[b][static_cast<std::size_t>(k)]);
      return (std::isnan(db) && !std::isnan(da)) || da > db;
    });
    md << "\n| R" << k + 1 << ": parameter | description | dR" << k + 1 << "/dP" << (result.central ? " (central)" : "")
       << " |\n|---|---|---|\n";
    for (std::size_t i : order) {
      const std::string& name = result.runs[result.central ? 2 * i : i].parameter;
      char value[32];
      std::snprintf(value, sizeof value, "%+.3f", result.derivatives[i][static_cast<std::size_t>(k)]);
      md << "| " << name << " | " << description(name) << " | " << value << " |\n";
    }
  }
  std::ofstream(directory + "/sensitivity.md") << md.str();
  return md.str();
}

}  // namespace railcrash
