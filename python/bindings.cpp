// railcrash._railcrash: the Python extension over the public interface (api.hpp) and the
// sensitivity study. The package railcrash (__init__.py) gives the user-facing functions
// (load, run, ...) on top of it.
//
// Runs release the GIL, so Python threads run models in parallel. Model input errors become
// railcrash.InputError (a ValueError), carrying the loader's "file:line: ..." message.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <atomic>
#include <chrono>
#include <future>
#include <map>
#include <thread>
#include <tuple>

#include "railcrash/api.hpp"
#include "railcrash/core/table_text.hpp"
#include "railcrash/studies/sensitivity.hpp"
#include "railcrash/studies/sweep.hpp"

namespace py = pybind11;
namespace rc = railcrash::api;

namespace {

/// A read-only numpy view of one result column; the Results object stays alive with it.
py::array column_view(const py::object& owner, const std::vector<double>& values) {
  py::array_t<double> view(static_cast<py::ssize_t>(values.size()), values.data(), owner);
  py::detail::array_proxy(view.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return std::move(view);
}

py::dict sensitivity_run_dict(const railcrash::SensitivityRun& run) {
  py::dict row;
  py::dict variation;
  for (const auto& [name, value] : run.variation) variation[py::str(name)] = value;
  row["parameter"] = run.parameter.empty() ? std::string("base") : run.parameter;
  row["variation"] = variation;
  row["factor"] = run.factor;
  row["ok"] = run.ok;
  row["message"] = run.message;
  row["R1"] = run.responses.r1;
  row["R2"] = run.responses.r2;
  row["R3"] = run.responses.r3;
  row["wall_seconds"] = run.wall_seconds;
  row["outcomes"] = run.ok ? run.outcomes.text() : std::string();  // the discrete outcome (issue 40)
  row["branch"] = run.ok ? run.outcomes.order() : std::string();    // order only: equal texts, one branch
  row["integrator_used"] = run.integrator.method;     // "ida", "euler", "ida+euler", "ida+euler+ida" ("" : the run did not start)
  row["euler_from_t"] = run.integrator.euler_from_t;  // ida+euler: when IDA handed the run to Euler (else NaN)
  return row;
}

/// A first-order run off run 0's branch, bisected (sensitivity.hpp's BranchChange).
py::dict branch_change_dict(const railcrash::BranchChange& c) {
  py::dict row;
  row["parameter"] = c.parameter;
  row["nominal_value"] = c.nominal_value;
  row["on_branch_value"] = c.on_branch_value;
  row["off_branch_value"] = c.off_branch_value;
  row["off_branch_outcomes"] = c.off_branch_signature;
  for (int k = 0; k < 3; ++k) {
    const std::string r = "R" + std::to_string(k + 1);
    row[py::str("A_" + r)] = c.nominal_derivative[static_cast<std::size_t>(k)];
    row[py::str("within_" + r)] = c.within_branch[static_cast<std::size_t>(k)];
    row[py::str("jump_" + r)] = c.jump[static_cast<std::size_t>(k)];
  }
  row["extra_runs"] = c.bisection_runs.size();
  row["note"] = c.note;
  return row;
}

/// Runs work() on a thread of its own while this thread, holding the GIL between waits, looks
/// for Python's signals every 100 ms. On Ctrl-C (PyErr_CheckSignals raises KeyboardInterrupt) it
/// raises `stop`, as the command line's SIGINT handler raises its flag: the runs in progress stop
/// at their next step and no new run starts. It waits for work to end and raises the
/// KeyboardInterrupt; the partial result is dropped.
template <typename Work>
auto until_interrupted(std::atomic<bool>& stop, Work work) -> decltype(work()) {
  auto done = std::async(std::launch::async, std::move(work));
  while (true) {
    {
      py::gil_scoped_release release;
      if (done.wait_for(std::chrono::milliseconds(100)) == std::future_status::ready) break;
    }
    if (PyErr_CheckSignals() != 0) {
      stop = true;
      {
        py::gil_scoped_release release;
        done.wait();
      }
      try {
        (void)done.get();
      } catch (...) {  // the interruption is what the caller hears of
      }
      throw py::error_already_set();
    }
  }
  return done.get();
}

/// `railcrash sweep`: (columns of runs.csv, each run's fields as text; runs not done left out).
std::pair<std::vector<std::string>, std::vector<std::vector<std::string>>> sweep(const std::string& model_path,
                                                                                 const std::string& plan_path, int jobs,
                                                                                 const std::string& out_dir, bool resume,
                                                                                 double run_limit) {
  std::atomic<bool> stop{false};
  railcrash::SweepPlan plan;
  const railcrash::SweepResult result = until_interrupted(stop, [&] {
    plan = railcrash::load_sweep_plan(plan_path, model_path);
    railcrash::SweepOptions options;
    options.jobs = jobs > 0 ? jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    options.resume = resume;
    options.run_time_limit = run_limit;
    options.stop = &stop;
    return railcrash::run_sweep(model_path, plan, out_dir, options);
  });
  std::vector<std::vector<std::string>> rows;
  for (const auto& [number, line] : result.lines) rows.push_back(railcrash::csv_fields(line));
  return {railcrash::csv_fields(railcrash::sweep_csv_header(plan)), rows};
}

/// The first-order study of `railcrash sensitivity`: rows of runs and of fitted A_i.
py::dict sensitivity(const std::string& model_path, const std::string& design, int jobs, const std::vector<std::string>& only,
                     bool second_order, double central, double run_limit, int bisections) {
  railcrash::SensitivityDesign loaded;
  std::atomic<bool> stop{false};
  const railcrash::SensitivityResult result = until_interrupted(stop, [&] {
    const std::string path = design == "report" ? railcrash::default_design_path(model_path) : design;
    loaded = railcrash::load_design(path);
    railcrash::SensitivityOptions options;
    options.jobs = jobs > 0 ? jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    options.only = only;
    options.second_order = second_order;
    options.central_step = central;
    options.run_time_limit = run_limit;
    options.branch_bisections = bisections;
    options.stop = &stop;
    return railcrash::run_sensitivity(model_path, loaded, options);
  });
  py::list runs;
  runs.append(sensitivity_run_dict(result.base));
  for (const auto& r : result.runs) runs.append(sensitivity_run_dict(r));
  for (const auto& r : result.second_order_runs) runs.append(sensitivity_run_dict(r));
  py::list first_order;
  // derivatives[i] belongs to the i-th parameter run (runs[i], or runs[2i] and runs[2i+1] central).
  const std::size_t per_parameter = result.central ? 2 : 1;
  for (std::size_t i = 0; i < result.derivatives.size() && per_parameter * i < result.runs.size(); ++i) {
    const std::string& name = result.runs[per_parameter * i].parameter;
    py::dict row;
    row["parameter"] = name;
    for (const railcrash::SensitivityParameter& p : loaded.parameters)
      if (p.name == name) row["description"] = p.description;
    row["A_R1"] = result.derivatives[i][0];
    row["A_R2"] = result.derivatives[i][1];
    row["A_R3"] = result.derivatives[i][2];
    first_order.append(row);
  }
  py::dict out;
  out["runs"] = runs;
  out["first_order"] = first_order;
  out["constant"] = py::make_tuple(result.constant[0], result.constant[1], result.constant[2]);
  out["central"] = result.central;
  py::list changes;
  for (const railcrash::BranchChange& c : result.branch_changes) changes.append(branch_change_dict(c));
  out["branch_changes"] = changes;
  if (!result.fit.terms.empty()) {
    py::list terms;
    for (std::size_t k = 0; k < result.fit.terms.size(); ++k) {
      py::dict row;
      row["term"] = result.fit.terms[k].label();
      row["R1"] = result.fit.coefficients[k][0];
      row["R2"] = result.fit.coefficients[k][1];
      row["R3"] = result.fit.coefficients[k][2];
      terms.append(row);
    }
    out["second_order"] = terms;
    out["second_order_constant"] = py::make_tuple(result.fit.constant[0], result.fit.constant[1], result.fit.constant[2]);
    out["fit_note"] = result.fit_note;
  }
  return out;
}

}  // namespace

PYBIND11_MODULE(_railcrash, m) {
  m.doc() = "railcrash: planar rail-vehicle crash dynamics (the extension; use the railcrash package)";
  m.attr("__version__") = rc::version();

  // InputError: the model or a setting must change (message: file:line: what to change).
  static py::exception<railcrash::InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<railcrash::SolverError> solver_error(m, "SolverError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const railcrash::InputError& e) {
      input_error(e.what());
    } catch (const railcrash::SolverError& e) {
      solver_error(e.what());
    }
  });

  py::class_<rc::Model>(m, "Model", "A checked model, ready to run (immutable; with_settings gives an edited copy).")
      .def_static("load", &rc::Model::load, py::arg("path"), py::arg("settings") = std::vector<std::string>{},
                  py::call_guard<py::gil_scoped_release>())
      .def_static("from_yaml", &rc::Model::from_yaml, py::arg("text"), py::arg("source") = "<string>",
                  py::arg("settings") = std::vector<std::string>{}, py::call_guard<py::gil_scoped_release>())
      .def("with_settings", &rc::Model::with, py::arg("settings"), py::call_guard<py::gil_scoped_release>(),
           "A copy with more KEY=VALUE / KEY*=FACTOR settings applied.")
      .def_property_readonly("name", &rc::Model::name)
      .def_property_readonly("path", &rc::Model::path)
      .def_property_readonly("yaml", &rc::Model::yaml)
      .def_property_readonly("settings", &rc::Model::settings)
      .def_property_readonly("units", &rc::Model::units)
      .def_property_readonly("bodies", &rc::Model::bodies)
      .def_property_readonly("elements", &rc::Model::elements)
      .def_property_readonly("columns", &rc::Model::columns)
      .def_property_readonly("t_end", &rc::Model::t_end)
      .def("__repr__", [](const rc::Model& model) {
        return "<railcrash.Model '" + model.name() + "': " + std::to_string(model.bodies().size()) + " bodies, " +
               std::to_string(model.elements().size()) + " elements>";
      });

  py::class_<rc::RunSettings>(m, "RunSettings")
      .def(py::init<>())
      .def_readwrite("integrator", &rc::RunSettings::integrator)
      .def_readwrite("t_end", &rc::RunSettings::t_end)
      .def_readwrite("rtol", &rc::RunSettings::rtol)
      .def_readwrite("atol", &rc::RunSettings::atol)
      .def_readwrite("dt", &rc::RunSettings::dt)
      .def_readwrite("output_interval", &rc::RunSettings::output_interval)
      .def_readwrite("force_dt", &rc::RunSettings::force_dt)
      .def_readwrite("timings", &rc::RunSettings::timings);

  py::class_<rc::Results, std::shared_ptr<rc::Results>>(m, "Results", "What a run gives, in memory.")
      .def_property_readonly("ok", &rc::Results::ok)
      .def_property_readonly("columns", [](const rc::Results& r) { return r.columns; })
      .def_property_readonly("t", [](py::object self) { return column_view(self, self.cast<const rc::Results&>().t()); },
                             "sample times [s] (numpy array)")
      .def("series", [](py::object self, const std::string& column) {
            return column_view(self, self.cast<const rc::Results&>().series(column));
          }, py::arg("column"), "one column over the samples (numpy array), e.g. series('car1_center_body.x')")
      .def_property_readonly("events", [](const rc::Results& r) {
        py::list out;
        for (const rc::Event& e : r.events) out.append(py::make_tuple(e.t, e.element, e.event, e.value));
        return out;
      }, "committed mode changes: (t, element, event, value) tuples")
      .def_property_readonly("summary_json", [](const rc::Results& r) { return r.summary_json; })
      .def_property_readonly("message", [](const rc::Results& r) { return r.summary.message; })
      .def_property_readonly("accuracy_warnings", [](const rc::Results& r) { return r.summary.accuracy_warnings; },
                             "the run's accuracy warnings (summary.json's): energy drift or joints opening past the stated limits");

  py::class_<rc::ModelBuilder>(m, "ModelBuilder",
                               "Builds a model in code; build() checks it as a model file is checked.")
      .def(py::init<std::string, std::string>(), py::arg("name"), py::arg("units") = "SI")
      .def("gravity", &rc::ModelBuilder::gravity, py::arg("x"), py::arg("y"), py::return_value_policy::reference_internal)
      .def("body", [](rc::ModelBuilder& b, const std::string& name, double mass, double inertia, std::array<double, 2> position,
                      double angle, std::array<double, 2> velocity, double angular_velocity, const std::string& car) -> rc::ModelBuilder& {
            return b.body({name, mass, inertia, position[0], position[1], angle, velocity[0], velocity[1], angular_velocity, car});
          }, py::arg("name"), py::arg("mass"), py::arg("inertia"), py::arg("position"), py::arg("angle") = 0.0,
          py::arg("velocity") = std::array<double, 2>{0.0, 0.0}, py::arg("angular_velocity") = 0.0, py::arg("car") = "",
          py::return_value_policy::reference_internal)
      .def("element", [](rc::ModelBuilder& b, const std::string& name, const std::string& type,
                         const std::vector<std::tuple<std::string, double, double>>& points,
                         const std::map<std::string, rc::Parameter>& parameters) -> rc::ModelBuilder& {
            std::vector<rc::Point> at;
            for (const auto& [body, x, y] : points) at.push_back({body, x, y});
            return b.element(name, type, at, parameters);
          }, py::arg("name"), py::arg("type"), py::arg("points"), py::arg("parameters") = std::map<std::string, rc::Parameter>{},
          "points: [(body, x, y), ...] (body-frame offsets); parameters: {key: number | bool | [numbers] | [[numbers]]}",
          py::return_value_policy::reference_internal)
      .def("force", [](rc::ModelBuilder& b, const std::string& body, std::array<double, 2> at,
                       std::array<double, 2> value) -> rc::ModelBuilder& { return b.force({body, at[0], at[1]}, value[0], value[1]); },
           py::arg("body"), py::arg("at"), py::arg("value"), py::return_value_policy::reference_internal)
      .def("moment", &rc::ModelBuilder::moment, py::arg("body"), py::arg("value"), py::return_value_policy::reference_internal)
      .def("simulation", &rc::ModelBuilder::simulation, py::arg("settings"), py::return_value_policy::reference_internal)
      .def("yaml", &rc::ModelBuilder::yaml)
      .def("build", &rc::ModelBuilder::build);

  m.def("_run", [](const rc::Model& model, const rc::RunSettings& settings) {
        return std::make_shared<rc::Results>(rc::run(model, settings));
      }, py::arg("model"), py::arg("settings"), py::call_guard<py::gil_scoped_release>());

  m.def("_sweep", &sweep, py::arg("model_path"), py::arg("plan_path"), py::arg("jobs"), py::arg("out_dir"), py::arg("resume"),
        py::arg("run_limit"));
  m.def("_sensitivity", &sensitivity, py::arg("model_path"), py::arg("design"), py::arg("jobs"), py::arg("only"),
        py::arg("second_order"), py::arg("central"), py::arg("run_limit"), py::arg("bisections"));
}
