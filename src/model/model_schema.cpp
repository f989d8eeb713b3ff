#include "railcrash/model/model_schema.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

#include "railcrash/core/json_text.hpp"
#include "railcrash/model/model_io.hpp"
#include "railcrash/model/train_expansion.hpp"

namespace railcrash {

namespace {

// ---- a small JSON value, printed with two-space indentation ------------------------------

class Json {
 public:
  Json() = default;  // the JSON null
  static Json text(const std::string& value) { return Json(json_string(value)); }
  static Json number(double value) {
    char out[40];
    if (value == std::floor(value) && std::fabs(value) < 1e15) {
      std::snprintf(out, sizeof out, "%.0f", value);
    } else {
      for (int digits = 15; digits <= 17; ++digits) {
        std::snprintf(out, sizeof out, "%.*g", digits, value);
        if (std::strtod(out, nullptr) == value) break;
      }
    }
    return Json(out);
  }
  static Json boolean(bool value) { return Json(value ? "true" : "false"); }
  static Json object() {
    Json j;
    j.kind_ = Kind::Object;
    return j;
  }
  static Json array(std::vector<Json> items = {}) {
    Json j;
    j.kind_ = Kind::Array;
    j.items_ = std::move(items);
    return j;
  }
  static Json texts(const std::vector<std::string>& values) {
    Json j = array();
    for (const std::string& v : values) j.push(text(v));
    return j;
  }

  /// Adds `key` (or replaces its value); returns *this for chaining.
  Json& set(const std::string& key, Json value) {
    for (auto& member : members_)
      if (member.first == key) {
        member.second = std::move(value);
        return *this;
      }
    members_.emplace_back(key, std::move(value));
    return *this;
  }
  Json& push(Json item) {
    items_.push_back(std::move(item));
    return *this;
  }
  bool has(const std::string& key) const {
    for (const auto& member : members_)
      if (member.first == key) return true;
    return false;
  }

  std::string dump(int indent = 0) const {
    const std::string pad(static_cast<std::size_t>(indent), ' '), inner(static_cast<std::size_t>(indent) + 2, ' ');
    switch (kind_) {
      case Kind::Scalar: return scalar_;
      case Kind::Object: {
        if (members_.empty()) return "{}";
        std::string out = "{\n";
        for (std::size_t i = 0; i < members_.size(); ++i)
          out += inner + json_string(members_[i].first) + ": " + members_[i].second.dump(indent + 2) +
                 (i + 1 < members_.size() ? ",\n" : "\n");
        return out + pad + "}";
      }
      case Kind::Array: {
        bool flat = true;
        for (const Json& item : items_) flat = flat && item.kind_ == Kind::Scalar;
        std::string out = flat ? "[" : "[\n";
        for (std::size_t i = 0; i < items_.size(); ++i)
          out += flat ? (i ? ", " : "") + items_[i].dump() : inner + items_[i].dump(indent + 2) + (i + 1 < items_.size() ? ",\n" : "\n");
        return out + (flat ? "" : pad) + "]";
      }
    }
    return "";
  }

 private:
  enum class Kind { Scalar, Object, Array };

  explicit Json(std::string scalar) : scalar_(std::move(scalar)) {}
  Kind kind_ = Kind::Scalar;
  std::string scalar_ = "null";
  std::vector<std::pair<std::string, Json>> members_;
  std::vector<Json> items_;
};

// ---- building blocks ------------------------------------------------------------------------

Json typed(const char* type, const std::string& description) {
  Json j = Json::object().set("type", Json::text(type));
  if (!description.empty()) j.set("description", Json::text(description));
  return j;
}

Json word(const std::string& description) { return typed("string", description); }
/// A name the loader bounds (kMaxNameLength, model_io.hpp).
Json name_word(const std::string& description) {
  return word(description).set("maxLength", Json::number(static_cast<double>(kMaxNameLength)));
}
Json flag(const std::string& description) { return typed("boolean", description); }

/// The bounds of `range` on a number's schema.
Json& with_range(Json& j, Range range) {
  switch (range) {
    case Range::Any: break;
    case Range::Positive: j.set("exclusiveMinimum", Json::number(0)); break;
    case Range::NonNegative: j.set("minimum", Json::number(0)); break;
    case Range::Fraction: j.set("exclusiveMinimum", Json::number(0)).set("maximum", Json::number(1)); break;
    case Range::UnitInterval: j.set("minimum", Json::number(0)).set("maximum", Json::number(1)); break;
  }
  return j;
}

Json number(const std::string& description, Range range = Range::Any) {
  Json j = typed("number", description);
  return with_range(j, range);
}

Json numbers(std::size_t size, Range range = Range::Any) {
  Json item = typed("number", "");
  return Json::object()
      .set("type", Json::text("array"))
      .set("items", with_range(item, range))
      .set("minItems", Json::number(static_cast<double>(size)))
      .set("maxItems", Json::number(static_cast<double>(size)));
}

Json pair(const std::string& description, Range range = Range::Any) { return numbers(2, range).set("description", Json::text(description)); }

/// [[a, b], ...]: at least one row of two numbers.
Json table(const std::string& description, Range range = Range::Any) {
  return Json::object()
      .set("type", Json::text("array"))
      .set("description", Json::text(description))
      .set("items", numbers(2, range))
      .set("minItems", Json::number(1));
}

Json definition_ref(const std::string& definition) { return Json::object().set("$ref", Json::text("#/definitions/" + definition)); }

/// A reference with its own description (draft-07 ignores a $ref's sibling keys: wrap it).
Json definition_ref(const std::string& definition, const std::string& description) {
  return Json::object().set("description", Json::text(description)).set("allOf", Json::array({definition_ref(definition)}));
}

Json list_of(Json item, const std::string& description) {
  return Json::object().set("type", Json::text("array")).set("description", Json::text(description)).set("items", std::move(item));
}

Json one_of_words(const std::vector<std::string>& values, const std::string& description) {
  return Json::object().set("description", Json::text(description)).set("enum", Json::texts(values));
}

/// A unit kind's unit in the three systems of the model file: "force/length [SI: N/m,
/// mm-t-s-N: N/mm, in-lbf-s: lbf/in]"; the kind alone when it has no unit.
std::string unit_text(Unit unit) {
  const std::string kind = unit_kind_name(unit);
  const std::string si = unit_symbol(unit, UnitSystem::SI), in = unit_symbol(unit, UnitSystem::InLbfS);
  if (si.empty()) return kind;
  if (si == in) return kind + " [" + si + "]";
  // mm-t-s-N: lengths in mm, forces in N (the loader's scale, model_io.cpp's UnitScale).
  std::string mm;
  switch (unit) {
    case Unit::Length: case Unit::Position: mm = "mm"; break;
    case Unit::Force: mm = "N"; break;
    case Unit::Moment: mm = "N*mm"; break;
    case Unit::ForcePerLength: mm = "N/mm"; break;
    case Unit::MomentPerAngle: mm = "N*mm/rad"; break;
    case Unit::ForceTimePerLength: mm = "N*s/mm"; break;
    case Unit::MomentTimePerAngle: mm = "N*mm*s/rad"; break;
    case Unit::Velocity: mm = "mm/s"; break;
    case Unit::Stress: mm = "MPa"; break;
    case Unit::Area: mm = "mm^2"; break;
    case Unit::SectionModulus: mm = "mm^3"; break;
    case Unit::SecondMoment: mm = "mm^4"; break;
    case Unit::LengthForceCurve: mm = "[[mm, N], ...]"; break;
    default: mm = si; break;
  }
  return kind + " [SI: " + si + ", mm-t-s-N: " + mm + ", in-lbf-s: " + in + "]";
}

// ---- element types --------------------------------------------------------------------------

std::string presence_text(const Presence& presence) {
  switch (presence.kind) {
    case Presence::Required: return "Required.";
    case Presence::Optional: return "Optional; absent: " + presence.text + ".";
    case Presence::Default: return "Default: " + presence.text + ".";
  }
  return "";
}

/// One declared parameter: its shape, range, allowed values and default, described by its
/// meaning, unit and presence.
Json parameter_schema(const ParameterSpec& spec) {
  const std::string range = range_text(spec.range);
  const std::string unit = spec.unit == Unit::Choice ? "" : unit_text(spec.unit) + (range.empty() ? "" : ", " + range) + ". ";
  const std::string description = spec.meaning + ". " + unit + presence_text(spec.presence);
  const std::vector<std::string> values = choice_values(spec);
  Json j;
  switch (spec.shape) {
    case Shape::Number:
      if (!values.empty()) {
        Json list = Json::array();
        for (const std::string& v : values) list.push(Json::number(std::stod(v)));
        j = Json::object().set("type", Json::text("number")).set("description", Json::text(description)).set("enum", list);
      } else {
        j = number(description, spec.range);
      }
      // (A default that depends on the unit system is given in the description alone.)
      if (spec.presence.kind == Presence::Default && !spec.presence.si_value)
        j.set("default", Json::number(spec.presence.value));
      break;
    case Shape::Pair: j = pair(description, spec.range); break;
    case Shape::Table: j = table(description, spec.range); break;
    case Shape::Flag:
      j = flag(description);
      if (spec.presence.kind == Presence::Default) j.set("default", Json::boolean(spec.presence.value != 0.0));
      break;
    case Shape::Word:
      j = values.empty() ? word(description) : one_of_words(values, description).set("type", Json::text("string"));
      if (spec.presence.kind == Presence::Default) j.set("default", Json::text(spec.presence.text));
      break;
  }
  return j;
}

/// An element of type `type`: exactly its declared keys (name, type, points and its parameters).
Json element_type_schema(const ElementType& type) {
  Json properties = Json::object();
  properties.set("name", Json::object());
  properties.set("type", Json::object().set("const", Json::text(type.name)));
  const auto count = Json::number(static_cast<double>(type.points));
  properties.set("points", Json::object().set("description", Json::text(type.points_meaning)).set("minItems", count).set("maxItems", count));
  std::vector<std::string> required{"name", "type", "points"};
  for (const ParameterSpec& spec : type.parameters) {
    properties.set(spec.name, parameter_schema(spec));
    if (spec.presence.kind == Presence::Required) required.push_back(spec.name);
  }
  const std::string report = type.report_type.empty() ? "" : " (IITRAIN report type " + type.report_type + ")";
  return Json::object()
      .set("description", Json::text(type.name + report + ": " + type.summary))
      .set("type", Json::text("object"))
      .set("properties", properties)
      .set("required", Json::texts(required))
      .set("additionalProperties", Json::boolean(false));
}

/// An element whose points are `point` (a body point, or an interface type's end point): its
/// type names one of the registry's, and the type's own keys apply (if type = X then element_X).
Json element_schema(const ElementRegistry& registry, const std::string& point, const std::string& description) {
  Json properties = Json::object();
  properties.set("name", name_word("the element's name (its output columns are <name>.<quantity>)"));
  // enumDescriptions (VS Code's extension of JSON Schema): each type's law, shown as it is completed.
  Json laws = Json::array();
  for (const std::string& name : registry.types()) laws.push(Json::text(registry.find(name)->summary));
  properties.set("type", one_of_words(registry.types(), "the element type (railcrash elements TYPE; docs/elements.md)")
                             .set("enumDescriptions", laws));
  properties.set("points", list_of(definition_ref(point), "connection points, as many as the type takes"));
  Json cases = Json::array();
  for (const std::string& name : registry.types())
    cases.push(Json::object()
                   .set("if", Json::object()
                                  .set("properties", Json::object().set("type", Json::object().set("const", Json::text(name))))
                                  .set("required", Json::texts({"type"})))
                   .set("then", definition_ref("element_" + name)));
  return Json::object()
      .set("description", Json::text(description))
      .set("type", Json::text("object"))
      .set("properties", properties)
      .set("required", Json::texts({"name", "type", "points"}))
      .set("allOf", cases);
}

// ---- the sections outside the elements --------------------------------------------------------

/// A key's schema (with its description) and whether the section requires it.
struct KeySchema {
  Json schema;
  bool required = false;
};
using SectionKeys = std::map<std::string, KeySchema>;

const std::string kLength = unit_text(Unit::Length);
const std::string kVelocity = unit_text(Unit::Velocity);

/// The keys of every section, described. Their names must be the loader's (checked in section()).
std::map<std::string, SectionKeys> section_keys() {
  std::map<std::string, SectionKeys> s;
  s["model"] = {
      {"railcrash", {Json::object().set("description", Json::text("model format version: 1")).set("const", Json::number(1)), true}},
      {"name", {name_word("the model's name"), true}},
      {"description", {word("what the model is (free text)")}},
      {"units", {one_of_words({"SI", "in-lbf-s", "mm-t-s-N"},
                              "unit system of every number in the file: SI (kg, m, s, N), in-lbf-s (the 1980 report's: weights in "
                              "lbf, lengths in inches) or mm-t-s-N (mm, tonne, s, N; converted to SI when read)"),
                 true}},
      {"gravity", {pair("gravity [gx, gy] (length/time^2); default: standard gravity in -y; [0, 0] switches it off")}},
      {"bodies", {list_of(definition_ref("body"), "the rigid bodies (ground is reserved: fixed, not listed)")}},
      {"elements", {list_of(definition_ref("element"), "the elements joining bodies (railcrash elements; docs/elements.md)")}},
      {"loads", {list_of(definition_ref("load"), "applied forces and moments, constant or tabulated in time")}},
      {"simulation", {definition_ref("simulation", "run settings: end time, integrator, tolerances, output interval"), true}},
      {"outputs", {list_of(definition_ref("output"), "extra output points: position, velocity and acceleration of a body point")}},
      {"responses", {definition_ref("responses", "the report's responses R1-R3: crush gauges, anticlimber and reference values")}},
      {"scenario", {definition_ref("scenario", "EN 15227 scenario criteria (written by railcrash scenario)")}},
  };
  s["body"] = {
      {"name", {name_word("the body's name (ground is reserved)"), true}},
      {"mass", {number("mass [SI: kg, mm-t-s-N: t, in-lbf-s: lbf*s^2/in]; give mass or (in-lbf-s) weight", Range::Positive)}},
      {"weight", {number("weight [lbf], in-lbf-s models only, instead of mass", Range::Positive)}},
      {"inertia", {number("centroidal moment of inertia [SI: kg*m^2, mm-t-s-N: t*mm^2, in-lbf-s: lbf*s^2*in]; 0: a point mass",
                          Range::NonNegative),
                   true}},
      {"position", {pair("global position of the centre of mass [x, y]: " + kLength), true}},
      {"angle", {number("initial angle [rad]; default 0")}},
      {"velocity", {pair("initial velocity [vx, vy]: " + kVelocity + "; default [0, 0]")}},
      {"angular_velocity", {number("initial angular velocity [rad/s]; default 0")}},
      {"car", {word("the car the body belongs to (heads its rows in summary.json and the report)")}},
  };
  s["point"] = {
      {"body", {word("a body's name, or ground"), true}},
      {"at", {pair("offset from the body's centre of mass, in the body's frame [x, y]: " + kLength + "; default [0, 0]")}},
  };
  s["load"] = {
      {"type", {one_of_words({"force", "moment"}, "force (value [Fx, Fy]) or moment (value M)"), true}},
      {"body", {word("the loaded body"), true}},
      {"at", {pair("force only: point of application in the body's frame [x, y]: " + kLength + "; default [0, 0]")}},
      {"value",
       {Json::object()
            .set("description", Json::text("force [Fx, Fy] (" + unit_text(Unit::Force) + ") or moment M (" + unit_text(Unit::Moment) +
                                           "), or a table [[t, value], ...] (a force's rows may be [t, Fx, Fy]) with t increasing"))
            .set("anyOf", Json::array({typed("number", ""), numbers(2),
                                       Json::object()
                                           .set("type", Json::text("array"))
                                           .set("minItems", Json::number(1))
                                           .set("items", Json::object()
                                                             .set("type", Json::text("array"))
                                                             .set("minItems", Json::number(2))
                                                             .set("maxItems", Json::number(3)))})),
        true}},
  };
  s["simulation"] = {
      {"t_end", {number("end time of the run [s]", Range::Positive), true}},
      {"integrator", {one_of_words(integrator_names(),
                                   "auto (default: IDA, handing the run to Euler where Euler is clearly the cheaper at "
                                   "the same resolution), ida (SUNDIALS IDA, BDF with KLU) or euler (explicit Euler with "
                                   "penalty constraints, as IITRAIN)")}},
      {"rtol", {number("ida: relative tolerance", Range::Positive)}},
      {"atol", {number("ida: absolute tolerance of lengths (" + kLength + "); default from the model's size", Range::Positive)}},
      {"position_tolerance", {one_of_words({"relative", "absolute"},
                                           "ida: relative (default: rtol |q| + atol, atol 0.1 rtol x the model's size) or "
                                           "absolute (atol alone, default rtol x the speed scale over the model's highest "
                                           "frequency; README \"Position tolerances\")")}},
      {"linear_ordering", {one_of_words({"fewest_entries", "amd", "colamd"},
                                        "ida: the fill-reducing ordering of the sparse LU (KLU): fewest_entries (default: AMD "
                                        "or COLAMD, whichever factors the first Newton matrix with fewer entries), amd or "
                                        "colamd; it changes round-off only")}},
      {"jacobian_kept_steps", {typed("integer", "ida: steps a Jacobian serves IDA's later setups, its rates' part updated "
                                                "(default 20; 0: one evaluated at every setup, as before it was kept); it "
                                                "changes IDA's Newton iterates only, within its tolerance")
                                              .set("minimum", Json::number(0))}},
      {"dt", {number("euler: time step [s]", Range::Positive)}},
      {"output_interval", {number("time between output rows [s]", Range::Positive)}},
      {"force_dt", {flag("euler: run with dt even above the stability limit")}},
      {"max_steps", {typed("integer", "most steps either integrator may take").set("minimum", Json::number(1))}},
      {"static_equilibrium", {flag("start from static equilibrium under gravity (computed before the run)")}},
      {"penalty_stiffness", {number("euler: stiffness of constraint penalty springs (" + unit_text(Unit::ForcePerLength) + ")", Range::Positive)}},
      {"penalty_damping", {number("euler: damping of constraint penalty springs (" + unit_text(Unit::ForceTimePerLength) + ")", Range::Positive)}},
      {"penalty_rotational_stiffness",
       {number("euler: rotational penalty stiffness (" + unit_text(Unit::MomentPerAngle) + ")", Range::Positive)}},
      {"penalty_rotational_damping",
       {number("euler: rotational penalty damping (" + unit_text(Unit::MomentTimePerAngle) + ")", Range::Positive)}},
  };
  s["output"] = {
      {"name", {name_word("the point's name (its columns); default <body>_point<k>")}},
      {"body", {word("the body the point is on"), true}},
      {"at", {pair("offset from the body's centre of mass, in the body's frame [x, y]: " + kLength + "; default [0, 0]")}},
      {"quantities", {Json::object()
                          .set("type", Json::text("array"))
                          .set("description", Json::text("what to write; default all three"))
                          .set("minItems", Json::number(1))
                          .set("items", Json::object().set("enum", Json::texts({"position", "velocity", "acceleration"})))}},
  };
  s["responses"] = {
      {"crush_gauges", {list_of(definition_ref("crush_gauge"), "pairs of points whose approach is crush (R1)")}},
      {"crush", {one_of_words({"total", "largest", "anticlimber"},
                              "R1's crush: total or largest of the crush gauges, or the anticlimber's horizontal deflection")}},
      {"reference_crush", {number("maximum safe crush, R1 = crush / it: " + kLength, Range::Positive)}},
      {"anticlimber", {word("the anticlimber element R2 is measured at")}},
      {"vertical_yield_force", {number("R2 = largest vertical anticlimber force / it: " + unit_text(Unit::Force), Range::Positive)}},
      {"reference_velocity", {number("the velocity that fails the collision post (R2 after override): " + kVelocity, Range::Positive)}},
      {"vertical_force_window", {one_of_words({"whole_run", "until_largest_crush", "until_separation"},
                                              "the part of the run in which R2's vertical force counts")}},
      {"override_velocity_at", {one_of_words({"collision_post", "override"},
                                             "when R2's relative velocity is taken after an override: when the "
                                             "overriding end sill reaches the collision post (default) or at the override")}},
      {"collision_post_distance", {number("the anticlimber faces' approach from first touch at which the overriding end "
                                          "sill reaches the other car's collision post (default reference_crush): " + kLength,
                                          Range::Positive)}},
  };
  s["crush_gauge"] = {
      {"name", {name_word("the gauge's name"), true}},
      {"points", {Json::object()
                      .set("type", Json::text("array"))
                      .set("description", Json::text("two points [{body, at}, {body, at}]: front and rear"))
                      .set("items", definition_ref("point"))
                      .set("minItems", Json::number(2))
                      .set("maxItems", Json::number(2)),
                  true}},
  };
  s["variant"] = {
      {"railcrash", {Json::object().set("description", Json::text("model format version: 1")).set("const", Json::number(1)), true}},
      {"variant_of", {word("the base model file, relative to this file's folder"), true}},
      {"name", {name_word("the variant's name (replaces the base model's)")}},
      {"description", {word("what the variant changes")}},
      {"set", {Json::object()
                   .set("type", Json::text("object"))
                   .set("description", Json::text("changes to the base model: KEY: VALUE with the keys of --set "
                                                  "(simulation.t_end, elements.<name>.<key>, bodies.<name>.<key>, ...)"))}},
  };
  // Car types and trains (train_expansion.hpp; README "Car types and trains").
  s["sections"] = {
      {"car_types", {Json::object()
                         .set("type", Json::text("object"))
                         .set("description", Json::text("cars defined once, in their own coordinates, by name"))
                         .set("additionalProperties", definition_ref("car_type"))}},
      {"interface_types", {Json::object()
                               .set("type", Json::text("object"))
                               .set("description", Json::text("what joins two car ends (couplers, anticlimbers, buffers), by name"))
                               .set("additionalProperties", definition_ref("interface_type"))}},
      {"trains", {list_of(definition_ref("train"), "trains placing car instances one after another")}},
      {"connections", {list_of(definition_ref("connection"), "interfaces between trains (the collision)")}},
  };
  s["car_type"] = {
      {"description", {word("what the car type is")}},
      {"bodies", {list_of(definition_ref("body"), "the car's bodies, in the car's coordinates (x forward)"), true}},
      {"elements", {list_of(definition_ref("element"), "the car's elements: points on the car's bodies or on ground")}},
      {"interfaces", {Json::object()
                          .set("type", Json::text("object"))
                          .set("description", Json::text("the car's two ends: front (at larger x) and rear"))
                          .set("properties", Json::object().set("front", definition_ref("interface")).set("rear", definition_ref("interface")))
                          .set("required", Json::texts({"front", "rear"}))
                          .set("additionalProperties", Json::boolean(false)),
                      true}},
  };
  s["interface_type"] = {
      {"description", {word("what the interface type is")}},
      {"elements", {list_of(definition_ref("interface_element"), "elements whose points are {end: 1 | 2, at: [dx, dy]}")}},
  };
  s["interface"] = s["point"];  // a car end: {body, at} on the car type's bodies
  s["train"] = {
      {"name", {name_word("the train's name (generated names start with it: <train>.<car>.<name>)"), true}},
      {"description", {word("what the train is")}},
      {"front", {number("global x of the first car's leading end: " + kLength + "; default 0")}},
      {"facing", {one_of_words({"+x", "-x"}, "where the train's front points; default +x")}},
      {"speed", {number("initial speed along facing: " + kVelocity + "; default 0")}},
      {"coupling", {definition_ref("coupling", "the coupling between every two cars")}},
      {"couplings", {list_of(definition_ref("coupling"), "one coupling per gap, in order, instead of coupling")}},
      {"cars", {Json::object()
                    .set("type", Json::text("array"))
                    .set("description", Json::text("the cars, front first"))
                    .set("items", definition_ref("car"))
                    .set("minItems", Json::number(1)),
                true}},
  };
  s["car"] = {
      {"type", {word("a car type's name"), true}},
      {"name", {name_word("the car's name in the train; default car<k>")}},
      {"reversed", {flag("turned round: its rear end leads; default false")}},
  };
  s["coupling"] = {
      {"type", {word("an interface type's name"), true}},
      {"gap", {number("gap between the two ends: " + kLength + "; default 0")}},
  };
  s["connection"] = {
      {"name", {name_word("the connection's name (its elements are <connection>.<name>)"), true}},
      {"type", {word("an interface type's name"), true}},
      {"ends", {Json::object()
                    .set("type", Json::text("array"))
                    .set("description", Json::text("two interfaces [<train>.<car>.front|rear, <train>.<car>.front|rear]"))
                    .set("items", Json::object().set("type", Json::text("string")).set("pattern", Json::text("^.+\\.(front|rear)$")))
                    .set("minItems", Json::number(2))
                    .set("maxItems", Json::number(2)),
                true}},
  };
  s["end_point"] = {
      {"end", {Json::object().set("description", Json::text("1: the end at the smaller global x, 2: the other")).set("enum", Json::array({Json::number(1), Json::number(2)})),
               true}},
      {"at", {pair("offset from the end, global axes [dx, dy]: " + kLength + "; default [0, 0]")}},
  };
  return s;
}

/// The scenario section (read by results/scenario_criteria.cpp's read_scenario_section, whose key
/// lists are written where they are read).
Json scenario_schema() {
  const auto section = [](const std::string& description, Json properties, std::vector<std::string> required) {
    return Json::object()
        .set("type", Json::text("object"))
        .set("description", Json::text(description))
        .set("properties", std::move(properties))
        .set("required", Json::texts(required))
        .set("additionalProperties", Json::boolean(false));
  };
  const auto names = [](const std::string& description) { return list_of(typed("string", ""), description); };
  const std::string source = "where the limit comes from (a public source, or 'required input')";
  return section(
      "EN 15227 design collision scenario and its criteria",
      Json::object()
          .set("standard", word("the standard, e.g. EN 15227"))
          .set("number", Json::object().set("description", Json::text("the scenario's number")).set("enum", Json::array({Json::number(1), Json::number(2), Json::number(3), Json::number(4)})))
          .set("category", one_of_words({"C-I", "C-II", "C-III", "C-IV"}, "EN 15227's crashworthiness design category"))
          .set("closing_speed", number("closing speed: " + kVelocity, Range::Positive))
          .set("mean_deceleration",
               section("mean deceleration of the passenger areas",
                       Json::object()
                           .set("limit", number("limit (length/time^2)", Range::Positive))
                           .set("cfc", number("CFC filter class of the velocity", Range::Positive))
                           .set("source", word(source))
                           .set("bodies", names("the passenger bodies")),
                       {"limit", "source", "bodies"}))
          .set("survival_space",
               section("survival space",
                       Json::object()
                           .set("limit", number("largest loss of survival space: " + kLength, Range::Positive))
                           .set("source", word(source))
                           .set("cars", names("cars (a body's car) whose crush outside their declared crush zones counts"))
                           .set("excluded", names("elements left out of the survival space (the struck body's)"))
                           .set("zones", list_of(section("a declared crush zone: its crush up to its stroke is not survival-space loss",
                                                         Json::object()
                                                             .set("element", word("the crush element"))
                                                             .set("stroke", number("the crush it may take: " + kLength, Range::Positive)),
                                                         {"element", "stroke"}),
                                                 "declared crush zones"))
                           .set("gauges", list_of(section("a pair of bodies whose approach is lost survival space",
                                                          Json::object().set("name", name_word("the gauge's name")).set("front", word("front body")).set("rear", word("rear body")),
                                                          {"name", "front", "rear"}),
                                                  "body pairs")),
                       {"limit", "source"}))
          .set("override",
               section("override and wheel lift",
                       Json::object()
                           .set("limit", number("largest vertical relative displacement at the interface: " + kLength, Range::Positive))
                           .set("source", word(source))
                           .set("interface", word("the anticlimber element at the interface"))
                           .set("bodies", names("or the two bodies meeting at the interface [A, B]"))
                           .set("wheel_lift_limit", number("largest wheel lift: " + kLength, Range::Positive))
                           .set("wheel_lift_source", word(source))
                           .set("wheels", names("the wheel_rail elements whose lift counts (with wheel_lift_limit and wheel_lift_source)"))
                           .set("rail_supports", names("or the slider_joints holding the leading bogies on the rail, whose "
                                                       "unloading (Q0 - Q) / Q0 must stay below 1")),
                       {})),
      {"standard", "number", "category", "closing_speed", "mean_deceleration", "survival_space", "override"});
}

/// The map `name` of the loader: exactly the keys `allowed` (the loader's list), described by
/// `described` (which must describe those keys and no other).
Json section_schema(const std::string& name, const std::vector<std::string>& allowed, const SectionKeys& described,
                    const std::string& description) {
  Json properties = Json::object();
  std::vector<std::string> required;
  for (const std::string& key : allowed) {
    const auto it = described.find(key);
    if (it == described.end())
      throw std::logic_error("model schema: the loader allows key '" + key + "' in section '" + name +
                             "', which model_schema.cpp does not describe");
    properties.set(key, it->second.schema);
    if (it->second.required) required.push_back(key);
  }
  for (const auto& entry : described)
    if (!properties.has(entry.first))
      throw std::logic_error("model schema: model_schema.cpp describes key '" + entry.first + "' in section '" + name +
                             "', which the loader does not allow");
  Json j = Json::object().set("type", Json::text("object"));
  if (!description.empty()) j.set("description", Json::text(description));
  j.set("properties", properties);
  if (!required.empty()) j.set("required", Json::texts(required));
  return j.set("additionalProperties", Json::boolean(false));
}

}  // namespace

std::vector<std::string> choice_values(const ParameterSpec& spec) {
  std::vector<std::string> values;
  if (spec.unit != Unit::Choice || spec.shape == Shape::Flag) return values;
  const std::string& text = spec.meaning;
  // A choice starts the meaning or follows ", " / "; ", and is one word followed by ": ".
  for (std::size_t begin = 0; begin < text.size();) {
    const std::size_t end = text.find_first_of(" ,;:", begin);
    if (end != std::string::npos && end > begin && text.compare(end, 2, ": ") == 0) values.push_back(text.substr(begin, end - begin));
    const std::size_t next = std::min(text.find(", ", begin), text.find("; ", begin));
    if (next == std::string::npos) break;
    begin = next + 2;
  }
  return values;
}

std::string model_schema_json(const ElementRegistry& registry) {
  std::map<std::string, std::vector<std::string>> allowed;
  for (auto& entry : model_file_sections()) allowed[entry.first] = entry.second;
  for (auto& entry : train_expansion_sections()) allowed[entry.first] = entry.second;
  const std::map<std::string, SectionKeys> described = section_keys();
  const auto section = [&](const std::string& name, const std::string& description) {
    const auto keys = allowed.find(name);
    const auto docs = described.find(name);
    if (keys == allowed.end() || docs == described.end())
      throw std::logic_error("model schema: no key list or no description for section '" + name + "'");
    return section_schema(name, keys->second, docs->second, description);
  };

  Json definitions = Json::object();
  // The top level: the loader's keys and the car types' and trains' sections (expanded before
  // the loader reads the file). Bodies come from the file or from its trains.
  std::vector<std::string> top = allowed.at("model");
  for (const std::string& key : allowed.at("sections")) top.push_back(key);
  SectionKeys top_described = described.at("model");
  for (const auto& entry : described.at("sections")) top_described.insert(entry);
  definitions.set("model", section_schema("model", top, top_described, "a model file (format 1)")
                               .set("anyOf", Json::array({Json::object().set("required", Json::texts({"bodies"})),
                                                          Json::object().set("required", Json::texts({"trains"}))})));
  definitions.set("variant", section("variant", "a model variant: a base model with some keys changed (README \"Model variants\")"));
  definitions.set("body", section("body", "a rigid body"));
  definitions.set("point", section("point", "a connection point: a body and an offset in its frame"));
  definitions.set("load", section("load", "an applied force or moment"));
  definitions.set("simulation", section("simulation", "run settings"));
  definitions.set("output", section("output", "an output point"));
  definitions.set("responses", section("responses", "the report's responses R1-R3"));
  definitions.set("crush_gauge", section("crush_gauge", "a crush gauge"));
  definitions.set("scenario", scenario_schema());
  definitions.set("car_type", section("car_type", "a car type: bodies, elements and interfaces in the car's coordinates"));
  definitions.set("interface_type", section("interface_type", "an interface type: the elements joining two car ends"));
  definitions.set("interface", section("interface", "a car end: a body of the car type and an offset"));
  definitions.set("train", section("train", "a train"));
  definitions.set("car", section("car", "a car instance"));
  definitions.set("coupling", section("coupling", "a coupling between two neighbouring cars"));
  definitions.set("connection", section("connection", "an interface type joining two trains' car ends"));
  definitions.set("end_point", section("end_point", "a point of an interface type's element: a car end and an offset"));
  definitions.set("element", element_schema(registry, "point", "an element"));
  definitions.set("interface_element", element_schema(registry, "end_point", "an element of an interface type"));
  for (const std::string& name : registry.types()) definitions.set("element_" + name, element_type_schema(*registry.find(name)));

  Json schema = Json::object();
  schema.set("$schema", Json::text("http://json-schema.org/draft-07/schema#"));
  schema.set("title", Json::text("railcrash model file (format 1)"));
  schema.set("description", Json::text("Generated by `railcrash schema` from the loader's key lists and the element registry's "
                                       "declared parameters; do not edit. README \"Editor support\"."));
  schema.set("type", Json::text("object"));
  schema.set("if", Json::object().set("required", Json::texts({"variant_of"})));
  schema.set("then", definition_ref("variant"));
  schema.set("else", definition_ref("model"));
  schema.set("definitions", definitions);
  return schema.dump() + "\n";
}

}  // namespace railcrash
