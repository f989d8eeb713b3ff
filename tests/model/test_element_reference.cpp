// The element reference is written from the declarations: every type and every parameter
// appears, with its unit in both unit systems.
#include <catch2/catch.hpp>

#include <algorithm>
#include <string>

#include "railcrash/model/element_reference.hpp"

using namespace railcrash;

TEST_CASE("the element reference lists every type and every declared parameter", "[registry]") {
  const ElementRegistry& registry = ElementRegistry::instance();
  const std::string list = element_type_list(registry);
  const std::string markdown = element_reference_markdown(registry);
  CHECK(std::count(list.begin(), list.end(), '\n') == static_cast<long>(registry.types().size()) + 2);
  for (const std::string& name : registry.types()) {
    INFO("element type " << name);
    const ElementType& type = *registry.find(name);
    CHECK_THAT(list, Catch::Contains("\n" + name + " ") || Catch::StartsWith(name + " "));
    CHECK_THAT(markdown, Catch::Contains("\n## " + name + "\n"));
    CHECK_THAT(markdown, Catch::Contains("  type: " + name + "\n"));
    const std::string text = element_type_reference(type);
    CHECK_THAT(text, Catch::StartsWith(name + " ("));
    CHECK_THAT(text, Catch::Contains("points: " + std::to_string(type.points) + " (" + type.points_meaning + ")"));
    for (const ParameterSpec& spec : type.parameters) {
      INFO("key " << spec.name);
      CHECK_THAT(markdown, Catch::Contains("| `" + spec.name + "` | " + unit_kind_name(spec.unit)));
      CHECK_THAT(text, Catch::Contains("  " + spec.name + " "));
    }
  }
  // Units in both systems, as the model format converts them (design.md section 5).
  const std::string spring = element_type_reference(*registry.find("linear_spring"));
  CHECK_THAT(spring, Catch::Contains("stiffness") && Catch::Contains("force/length (in-lbf-s: lbf/in, SI: N/m); required; >= 0"));
  CHECK_THAT(spring, Catch::Contains("free_length") && Catch::Contains("length (in-lbf-s: in, SI: m); optional; absent: the initial distance P1-P2"));
  const std::string beam = element_type_reference(*registry.find("elastic_plastic_beam"));
  CHECK_THAT(beam, Catch::Contains("stress (in-lbf-s: psi, SI: Pa)") && Catch::Contains("second moment of area (in-lbf-s: in^4, SI: m^4)"));
  CHECK_THAT(element_type_reference(*registry.find("pin_joint")), Catch::Contains("angular velocity (rad/s); default 0.01; > 0"));
}
