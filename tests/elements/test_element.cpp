// Output roles (element.hpp OutputRole): every element type declares its roles on real outputs.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <random>
#include <set>
#include <string>

#include "railcrash/elements/beams.hpp"
#include "railcrash/model/element_registry.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/scenarios/consist.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

std::string source_path(const std::string& relative) { return std::string(RAILCRASH_SOURCE_DIR) + "/" + relative; }

// The element types no shipped model uses, one element each.
const char* const kOtherTypes =
    "railcrash: 1\nname: other types\nunits: SI\ngravity: [0, 0]\nbodies:\n"
    "  - {name: a, mass: 1, inertia: 1, position: [0, 0]}\n"
    "  - {name: b, mass: 1, inertia: 1, position: [1, 0]}\nelements:\n"
    "  - {name: coupling, type: coupling, kind: 1, curve: [[0, 0], [0.01, 1.0e5], [0.05, 3.0e5]], unloading_factor: 0.5,\n"
    "     points: [{body: a}, {body: b}]}\n"
    "  - {name: torsion, type: torsional_spring, stiffness: 10, points: [{body: ground}, {body: a}]}\n"
    "  - {name: torsion_damper, type: torsional_dashpot, damping: 0.5, points: [{body: ground}, {body: a}]}\n"
    "  - {name: double_slider, type: double_slider_joint, points: [{body: a}, {body: b}]}\n"
    "  - {name: rigid, type: rigid_joint, points: [{body: a, at: [0.5, 0]}, {body: b, at: [-0.5, 0]}]}\n"
    "simulation: {t_end: 0.1}\n";

}  // namespace

TEST_CASE("every element type's output roles name one of its outputs, each role at most once", "[roles]") {
  std::vector<Model> models;
  for (const char* file : {"models/report/final_two_car.yaml", "models/report/preliminary_car.yaml",
                           "models/barrier/two_car_barrier.yaml", "models/examples/coupled_cars.yaml"})
    models.push_back(load_model(source_path(file)).model);
  models.push_back(testing::model_from_text(kOtherTypes));
  std::set<std::string> checked;
  for (const Model& model : models)
    for (const auto& element : model.elements()) {
      INFO(element->type() << " '" << element->name() << "'");
      const std::vector<std::string> outputs = element->output_names();
      std::set<OutputRole> seen;
      for (const RoleOfOutput& r : element->output_roles()) {
        INFO("role " << output_role_name(r.role) << " -> " << r.output);
        CHECK(std::find(outputs.begin(), outputs.end(), std::string(r.output)) != outputs.end());
        CHECK(seen.insert(r.role).second);
        CHECK(element->output_with_role(r.role) == r.output);
      }
      checked.insert(element->type());
    }
  // Every registered type was among them, so none escapes the check.
  for (const std::string& type : ElementRegistry::instance().types()) {
    INFO(type);
    CHECK(checked.count(type) == 1);
  }
}

TEST_CASE("the roles say which outputs are crush, contact, coupler and interlock forces", "[roles]") {
  // What the run summary, converge, the responses and the report selected by type before.
  const Model model = load_model(source_path("models/report/final_two_car.yaml")).model;
  const auto role_of = [&](const std::string& type, OutputRole role) {
    for (const auto& e : model.elements())
      if (e->type() == type) return e->output_with_role(role);
    FAIL("no " << type << " in the report model");
    return std::string();
  };
  CHECK(role_of("anticlimber", OutputRole::Crush) == "horizontal_deformation");
  CHECK(role_of("anticlimber", OutputRole::ContactForce) == "horizontal_force");
  CHECK(role_of("anticlimber", OutputRole::VerticalInterlockForce) == "vertical_force");
  CHECK(role_of("coupler_end", OutputRole::CouplerForce) == "normal_force");
  CHECK(role_of("coupler_end", OutputRole::CrashDeformation).empty());  // a gap is no deformation
  CHECK(role_of("draft_gear", OutputRole::CrashForce) == "force");
  CHECK(role_of("draft_gear", OutputRole::CrashDeformation) == "compression");
  CHECK(role_of("draft_gear", OutputRole::CouplerForce).empty());
  CHECK(role_of("elastic_plastic_beam", OutputRole::Crush).empty());
  CHECK(role_of("wheel_rail", OutputRole::ContactForce).empty());
  CHECK(std::string(output_role_name(OutputRole::VerticalInterlockForce)) == "vertical_interlock_force");
}

TEST_CASE("a long train's elements lie side by side in memory, not one per page of the loader's heap", "[element][memory]") {
  // Loaded from a model file, each element object used to sit on its own 4 KiB page among the
  // parser's allocations (a median 2.9 KiB between consecutive elements; bench/HISTORY.md).
  // From the element pool (element.cpp) they fill the pages they occupy.
  const Model model = load_model_text(make_consist_model(source_path("models/report/final_two_car.yaml"), 20), "consist.yaml").model;
  REQUIRE(model.elements().size() == 1200);
  // Under AddressSanitizer elements come from the ordinary heap (its redzones and quarantine
  // decide the layout): only the count above is checked there.
  if (!Element::allocated_from_pool()) return;
  constexpr std::uintptr_t kPage = 4096;
  std::set<std::uintptr_t> pages;
  for (const auto& element : model.elements()) pages.insert(reinterpret_cast<std::uintptr_t>(element.get()) / kPage);
  INFO(model.elements().size() << " elements on " << pages.size() << " pages");
  // At about 440 bytes an element (the largest types about 1 KiB) nine share a page; a page per
  // element on the heap. Allow for slots reused from models freed earlier in this process.
  CHECK(pages.size() < model.elements().size() / 4);
}

TEST_CASE("every element's roots_and_outputs and force_roots_and_outputs equal its separate calls, bit for bit", "[element]") {
  // The step sweeps ask for roots and outputs at once (Element::roots_and_outputs), and for a
  // force element its force with them (force_roots_and_outputs); an element that evaluates its
  // law once for all (the beams) must give what the separate calls give, in every mode: the
  // two-car crash is run first so its beams, springs and contacts hold the modes of a crash
  // (plastic hinges among them), then every element is compared at random states.
  std::vector<LoadedModel> models;
  for (const char* file : {"models/report/final_two_car.yaml", "models/report/preliminary_car.yaml",
                           "models/barrier/two_car_barrier.yaml", "models/examples/coupled_cars.yaml"})
    models.push_back(load_model(source_path(file), {"simulation.t_end=0.15"}));
  models.push_back(testing::loaded_from_text(kOtherTypes));
  std::mt19937 rng(7);
  int compared = 0, compared_forces = 0, loaded_beams = 0, plastic_beams = 0, failed_beams = 0;
  for (std::size_t m = 0; m < models.size(); ++m) {
    DaeSystem system(models[m].model);
    if (m == 0) REQUIRE(testing::simulate(system, models[m].run_spec.simulation, 0.05).ok);  // the crash, to its t_end
    const int nq = system.body_unknowns();
    for (int sample = 0; sample < 3; ++sample) {
      // A beam in each mode family: as the run left it, then plastic in all three components,
      // then failed.
      if (sample > 0)
        for (std::size_t e = 0; e < system.model().elements().size(); ++e)
          if (dynamic_cast<const BeamElement*>(system.model().elements()[e].get()) != nullptr) {
            BeamElement::State st;
            if (sample == 1) st = {{1, -1, 1}, {1e-3, 2e-3, -1e-3}, false};
            else st.failed = true;
            testing::set_mode(system, st, e);
          }
      for (int draw = 0; draw < 20; ++draw) {
        const std::vector<double> y = testing::random_state(system, rng, 0.05);
        for (std::size_t e = 0; e < system.model().elements().size(); ++e) {
          const Element& el = *system.model().elements()[e];
          INFO(el.type() << " '" << el.name() << "', sample " << sample);
          const ElementState<double> s = gather_state(el, y.data(), y.data() + nq, system.modes().of(e));
          const double* lambda = el.constraint_count() > 0 ? y.data() + 2 * nq + system.model().constraint_offset(e) : nullptr;
          const auto roots = static_cast<std::size_t>(el.root_count());
          const std::size_t outputs = el.output_names().size();
          std::vector<double> g_apart(roots, -7.0), g_together(roots, -9.0), out_apart(outputs, -7.0), out_together(outputs, -9.0);
          el.roots(0.1, s, lambda, g_apart.data());
          el.outputs(s, lambda, out_apart.data());
          el.roots_and_outputs(0.1, s, lambda, roots > 0 ? g_together.data() : nullptr, outputs > 0 ? out_together.data() : nullptr);
          // (memcmp of bits: NaN equals NaN; never on an empty vector's null data)
          if (roots > 0) CHECK(std::memcmp(g_apart.data(), g_together.data(), roots * sizeof(double)) == 0);
          if (outputs > 0) CHECK(std::memcmp(out_apart.data(), out_together.data(), outputs * sizeof(double)) == 0);
          if (el.constraint_count() == 0) {
            std::array<Pose<double>, 2> f_apart{}, f_together{};
            el.add_force(0.1, s, f_apart);
            std::vector<double> g_all(roots, -5.0), out_all(outputs, -5.0);
            el.force_roots_and_outputs(0.1, s, lambda, f_together, roots > 0 ? g_all.data() : nullptr,
                                       outputs > 0 ? out_all.data() : nullptr);
            CHECK(std::memcmp(f_apart.data(), f_together.data(), sizeof(f_apart)) == 0);
            if (roots > 0) CHECK(std::memcmp(g_apart.data(), g_all.data(), roots * sizeof(double)) == 0);
            if (outputs > 0) CHECK(std::memcmp(out_apart.data(), out_all.data(), outputs * sizeof(double)) == 0);
            ++compared_forces;
            const bool loaded = f_apart[0].x != 0.0 || f_apart[0].theta != 0.0 || f_apart[1].y != 0.0;
            if (dynamic_cast<const BeamElement*>(&el) != nullptr && loaded) ++loaded_beams;
          }
          ++compared;
          if (dynamic_cast<const BeamElement*>(&el) != nullptr) {
            const auto& st = system.modes().as<BeamElement::State>(e);
            if (st.failed) ++failed_beams;
            else if (st.sign != std::array<int, 3>{0, 0, 0}) ++plastic_beams;
          }
        }
      }
    }
  }
  CHECK(compared > 1000);
  CHECK(compared_forces > 500);
  CHECK(loaded_beams > 100);  // the beams' forces compared are not all zero
  CHECK(plastic_beams > 0);
  CHECK(failed_beams > 0);
}
