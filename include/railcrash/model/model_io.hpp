// Model files (YAML, format 1; see README "Model file"). Every problem is an InputError
// whose message starts with "file:line: " and says what to change.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "railcrash/model/model.hpp"
#include "railcrash/model/run_spec.hpp"
#include "railcrash/model/train_expansion.hpp"
#include "railcrash/model/yaml_file.hpp"

namespace railcrash {

/// A KEY*=FACTOR setting whose model value is 0: the factor would change nothing.
class ZeroScaledError : public InputError {
 public:
  using InputError::InputError;
};

/// Throws an InputError naming the file and line of `where` (and the setting it came from):
/// how a section reader outside model_io reports a problem.
using SectionFail = std::function<void(const YAML::Node& where, const std::string& message)>;

/// Reads and checks a model file's `scenario:` section against the model's bodies and elements;
/// `length_scale` converts the file's lengths to the model's (mm-t-s-N: 1e-3, else 1). The
/// results layer supplies it (results/scenario_criteria.cpp registers read_scenario_section when the
/// program starts), so the model layer reads the run's settings without depending on scenarios.
using ScenarioSectionReader = std::shared_ptr<const ScenarioCriteria> (*)(const YAML::Node& section, const Model& model,
                                                                          double length_scale, const SectionFail& fail);
/// Registers the reader of the `scenario:` section (a model with one is refused without it).
/// Returns true, to initialise a static with. results/scenario_criteria.cpp registers it from a static
/// initialiser, which runs whenever that file is linked: every program that runs models links it
/// (run.cpp uses its ScenarioTracker); a program linking librailcrash.a that only loads models
/// names read_scenario_section itself (tests/fuzz/fuzz_model.cpp).
bool set_scenario_section_reader(ScenarioSectionReader reader);

/// What a model file describes: the physical model and, beside it, the run's settings.
struct LoadedModel {
  Model model;       // the physical model (bodies, elements, loads), finalized
  RunSpec run_spec;  // the run's settings (simulation, responses, outputs, scenario)
};

/// Reads and checks a model file; the model comes back finalized.
LoadedModel load_model(const std::string& path);
/// Same, from text (path is only used in messages). `overrides` are KEY=VALUE settings
/// applied before finalize (e.g. "simulation.t_end=0.5", "bodies.bob.mass=2").
LoadedModel load_model_text(const std::string& text, const std::string& path, const std::vector<std::string>& overrides = {});
LoadedModel load_model(const std::string& path, const std::vector<std::string>& overrides);
/// A model file's text, its YAML structure checked (InputError "path:line: ..." as load_model
/// gives for the same text); the runs of a sweep then load it without walking it again.
CheckedYamlText check_model_text(std::string text, const std::string& path);
/// load_model_text of a checked text.
LoadedModel load_model_text(const CheckedYamlText& text, const std::string& path, const std::vector<std::string>& overrides);

/// The texts of the files a model reads, in order: `text` itself (the model file at `path`) and,
/// for a variant (README "Model variants"), its base model's. A sweep's run hash covers them all.
std::vector<std::string> model_input_texts(const std::string& text, const std::string& path);

/// A KEY=VALUE setting that goes through the same path as --set but is named in messages by
/// the command-line option it came from (e.g. setting "simulation.t_end=-1", option "--t-end -1").
struct OptionSetting {
  std::string setting;
  std::string option;
};
/// load_model with the --set settings first, then the command-line options' settings.
LoadedModel load_model(const std::string& path, const std::vector<std::string>& overrides, const std::vector<OptionSetting>& options);
/// load_model_text with the settings first, then the options' settings (the library's run).
LoadedModel load_model_text(const std::string& text, const std::string& path, const std::vector<std::string>& overrides,
                            const std::vector<OptionSetting>& options);

/// The model file's length unit in the model's: 1e-3 (m) for an mm-t-s-N file, whose lengths are
/// converted to SI when read; 1 otherwise. A setting's length (simulation.atol, --atol) is in it.
double file_length_unit(const Model& model);

/// A model file with its car types and trains expanded into flat bodies and elements
/// (README "Car types and trains"), the settings applied: what `railcrash expand` writes.
struct ExpandedModel {
  std::string text;               // YAML of the flat model (the file's units)
  std::vector<ExpandedCar> cars;  // the cars placed, in train order (empty for a flat model)
};
ExpandedModel expand_model_file(const std::string& path, const std::vector<std::string>& overrides);

/// Every key of the model file outside the element parameters (top-level sections, body, load,
/// simulation, outputs, responses and variant keys; the scenario section's are its own), each
/// once: with the element registry's parameter names, the fuzzer's dictionary (tests/fuzz).
std::vector<std::string> model_file_keys();

/// The keys the loader allows in each section of the model file, by section: "model" (top level),
/// "body", "point", "load", "simulation", "output", "responses", "crush_gauge", "variant". The
/// loader's own lists: `railcrash schema` (model_schema.hpp) builds the JSON Schema from them.
std::vector<std::pair<std::string, std::vector<std::string>>> model_file_sections();


/// The longest name the loader takes, in characters (UTF-8 code points): of the model, a body,
/// an element, an output point, a crush gauge, a car type, a car, a train, a connection. Names
/// become CSV column headers (with ".quantity"), JSON keys and report labels, each repeated in
/// every file of a run; 256 is far above any real name (the longest in models/ and examples/
/// has 28 characters, a train's expanded "train.car.element" a few dozen) and keeps a header
/// line and a message readable. A longer name is a mistake (pasted text, a generator's bug);
/// 20,000 characters once crashed the report (issue 36).
constexpr std::size_t kMaxNameLength = 256;

/// "" when name has at most kMaxNameLength characters, else the reason to refuse it: "WHAT
/// 'its first 40 characters...' is 20000 characters long, more than the limit of 256; shorten it".
std::string name_length_problem(const std::string& what, const std::string& name);

}  // namespace railcrash
