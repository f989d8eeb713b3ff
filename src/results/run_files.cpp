// model.json and energy.csv of a run folder (see the header).
#include "railcrash/results/run_files.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "railcrash/results/output_sink.hpp"
#include "railcrash/results/results.hpp"

namespace railcrash {

const std::vector<std::string>& run_folder_files() {
  static const std::vector<std::string> names = [] {
    // In the order the messages have always named them; then the files of a format registered since.
    std::vector<std::string> files = {"timeseries.csv", "events.csv",   "accelerations.csv", "energy.csv",
                                      "timeseries.h5",  "summary.json", "summary.json.tmp",  "model.json",
                                      "report.html",    "energy_zones.csv"};
    for (const OutputFormat& format : output_formats())
      for (const std::string& file : format.folder_files)
        if (std::find(files.begin(), files.end(), file) == files.end()) files.push_back(file);
    return files;
  }();
  return names;
}

std::vector<std::string> remove_earlier_run_files(const std::string& directory) {
  namespace fs = std::filesystem;
  std::vector<std::string> removed;
  for (const std::string& name : run_folder_files()) {
    const fs::path path = fs::path(directory) / name;
    std::error_code error;
    if (!fs::is_regular_file(fs::symlink_status(path, error))) continue;
    const bool removed_now = fs::remove(path, error);
    if (error)
      throw InputError("cannot remove " + path.string() + ", a file of an earlier run in the output folder: " + error.message() +
                       "; remove it yourself or give another --out folder");
    if (removed_now) removed.push_back(name);
  }
  return removed;
}

void write_model_geometry(const DaeSystem& system, const std::string& path, const std::string& run_id) {
  const Model& model = system.model();
  const bool si = model.units == UnitSystem::SI;
  // Connection points of each body, without repeats.
  std::vector<std::vector<std::array<double, 2>>> points(static_cast<std::size_t>(model.body_count()));
  for (const auto& e : model.elements())
    for (const PointRef& p : e->points()) {
      if (p.body == kGround) continue;
      auto& list = points[static_cast<std::size_t>(p.body)];
      const std::array<double, 2> at{p.sx, p.sy};
      if (std::find(list.begin(), list.end(), at) == list.end()) list.push_back(at);
    }
  std::ostringstream j;
  j << "{\n  \"format\": 1,\n";
  if (!run_id.empty()) j << "  \"run_id\": " << json_string(run_id) << ",\n";
  j << "  \"name\": " << json_string(model.name) << ",\n  \"units\": {\"length\": "
    << json_string(si ? "m" : "in") << ", \"force\": " << json_string(si ? "N" : "lbf") << ", \"mass\": "
    << json_string(si ? "kg" : "lbf*s^2/in") << ", \"energy\": " << json_string(si ? "J" : "in*lbf")
    << ", \"standard_gravity\": " << json_number(standard_gravity(model)) << "},\n  \"bodies\": [";
  for (int i = 0; i < model.body_count(); ++i) {
    const Body& b = model.bodies()[static_cast<std::size_t>(i)];
    j << (i ? "," : "") << "\n    {\"name\": " << json_string(b.name) << ", \"mass\": " << json_number(b.mass)
      << ", \"inertia\": " << json_number(b.inertia);
    if (!b.car.empty()) j << ", \"car\": " << json_string(b.car);
    j << ", \"points\": [";
    const auto& list = points[static_cast<std::size_t>(i)];
    for (std::size_t k = 0; k < list.size(); ++k)
      j << (k ? ", " : "") << "[" << json_number(list[k][0]) << ", " << json_number(list[k][1]) << "]";
    j << "]}";
  }
  j << "\n  ],\n  \"elements\": [";
  for (std::size_t e = 0; e < model.elements().size(); ++e) {
    const Element& el = *model.elements()[e];
    j << (e ? "," : "") << "\n    {\"name\": " << json_string(el.name()) << ", \"type\": " << json_string(el.type())
      << ", \"constraint\": " << (el.constraint_count() > 0 ? "true" : "false") << ", \"points\": [";
    for (std::size_t k = 0; k < el.points().size(); ++k) {
      const PointRef& p = el.points()[k];
      j << (k ? ", " : "") << "{\"body\": " << p.body << ", \"at\": [" << json_number(p.sx) << ", " << json_number(p.sy) << "]}";
    }
    j << "], \"outputs\": [";
    const auto names = el.output_names();
    for (std::size_t k = 0; k < names.size(); ++k) j << (k ? ", " : "") << json_string(names[k]);
    j << "], \"roles\": {";
    const auto roles = el.output_roles();
    for (std::size_t k = 0; k < roles.size(); ++k)
      j << (k ? ", " : "") << json_string(output_role_name(roles[k].role)) << ": " << json_string(roles[k].output);
    j << "}";
    if (const std::optional<Element::GroundSurface> g = el.ground_surface()) {  // a wall or barrier, drawn by the report
      if (g->kind == Element::GroundSurface::Kind::Line)
        j << ", \"surface\": {\"kind\": \"line\", \"point\": [" << json_number(g->x) << ", " << json_number(g->y)
          << "], \"normal\": [" << json_number(g->nx) << ", " << json_number(g->ny) << "]}";
      else
        j << ", \"surface\": {\"kind\": \"circle\", \"center\": [" << json_number(g->x) << ", " << json_number(g->y)
          << "], \"radius\": " << json_number(g->radius) << ", \"inside\": " << (g->inside ? "true" : "false") << "}";
    }
    j << "}";
  }
  j << "\n  ]\n}\n";
  std::ofstream out(path);
  out << j.str();
  if (!out) throw InputError("cannot write " + path);
}

EnergyWriter::EnergyWriter(const DaeSystem& system) : system_(system) {
  const Model& model = system.model();
  for (const auto& e : model.elements()) {
    auto it = std::find(types_.begin(), types_.end(), e->type());
    if (it == types_.end()) it = types_.insert(types_.end(), e->type());
    type_of_element_.push_back(static_cast<int>(it - types_.begin()));
  }
  if (model.constraint_rows() > 0) types_.push_back("penalty");  // Euler's penalty joints (zero under IDA)
  dissipated_.assign(types_.size(), 0.0);
  columns_ = {"t", "kinetic", "elastic", "gravity", "external_work", "dissipated"};
  for (const std::string& type : types_) columns_.push_back("dissipated." + type);
  columns_.push_back("integration_drift");
}

void EnergyWriter::sample(double t, const double* y, const double* quadratures) {
  const Model& model = system_.model();
  const int nq = system_.body_unknowns();
  // Kinetic and gravity energy as DaeSystem::energy has them; the elastic energy is summed
  // below from each element's own (DaeSystem::energy would evaluate every element once more).
  const double kinetic = system_.kinetic_energy(y + nq), gravity_potential = system_.gravity_potential(y);
  const double load_work = quadratures[DaeSystem::kLoadWork];
  std::fill(dissipated_.begin(), dissipated_.end(), 0.0);
  if (first_) initial_elastic_.assign(model.elements().size(), 0.0);
  double elastic = 0.0;
  for (std::size_t e = 0; e < model.elements().size(); ++e) {
    const DaeSystem::StoredEnergy energy = system_.element_stored_energy(e, y);
    if (first_) initial_elastic_[e] = energy.stored;
    elastic += energy.stored;
    if (!energy.dissipates) continue;  // conservative: its work less its stored energy is drift
    const double work = quadratures ? quadratures[DaeSystem::kFirstElementWork + static_cast<int>(e)] : 0.0;
    dissipated_[static_cast<std::size_t>(type_of_element_[e])] += work - (energy.stored - initial_elastic_[e]);
  }
  if (model.constraint_rows() > 0 && quadratures) dissipated_.back() += quadratures[DaeSystem::kPenaltyWork];
  if (first_) {
    initial_gravity_ = gravity_potential;
    initial_total_ = kinetic + elastic;
    first_ = false;
  }
  double dissipated = 0.0;
  for (double d : dissipated_) dissipated += d;
  const double gravity = gravity_potential - initial_gravity_;
  const double drift = initial_total_ + load_work - (kinetic + elastic + gravity + dissipated);
  row_.assign({t, kinetic, elastic, gravity, load_work, dissipated});
  row_.insert(row_.end(), dissipated_.begin(), dissipated_.end());
  row_.push_back(drift);
}

}  // namespace railcrash
