// The fuzz target (README "Fuzzing"): one input is the text of a model file. It is loaded and
// finalized, its DAE assembled, the residual and Jacobian evaluated once at t = 0 from the
// model's own state, and the initial state assembled onto the joints. Input errors (InputError,
// with its subclasses) and solver failures the project documents (SolverError) are expected
// answers to a hostile model and are caught here; anything else escapes and is a defect:
// another exception (std::terminate), a crash, a sanitizer report, a leak or a slow input.
//
// Linked with libFuzzer in the clang fuzz build (RAILCRASH_FUZZ=ON), and with
// fuzz_replay.cpp's main in every build, which runs the regression inputs.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "railcrash/core/error.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/results/scenario_criteria.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "railcrash/solver/initial_conditions.hpp"

namespace {

/// What a fuzz input is called in messages (the loader reads no file of that name, but a
/// `variant_of` is resolved against its folder: the working directory).
constexpr const char* kInputLabel = "fuzz-input.yaml";

// The loader reads `scenario:` sections through the reader results/scenario_criteria.cpp registers; this
// program uses nothing else of that layer, so it names the reader to link it (and fuzz it).
[[maybe_unused]] const bool kScenarioReader = railcrash::set_scenario_section_reader(&railcrash::read_scenario_section);

void exercise_model(const std::string& text) {
  using namespace railcrash;
  const Model model = load_model_text(text, kInputLabel).model;
  DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  const std::vector<double> yp(y.size(), 0.0);
  std::vector<double> residual(y.size(), 0.0);
  system.residual(0.0, y.data(), yp.data(), residual.data());
  std::vector<double> jacobian(static_cast<std::size_t>(system.pattern().nonzeros()), 0.0);
  const double cj = 1.0;  // [1/time] the BDF coefficient: any positive value exercises the same code
  system.jacobian(0.0, cj, y.data(), yp.data(), jacobian.data());
  assemble_initial_state(system, y);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    exercise_model(text);
  } catch (const railcrash::InputError&) {
  } catch (const railcrash::SolverError&) {
  }
  return 0;
}
