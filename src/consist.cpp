// Consists from a two-car template (consist.hpp says what is built and why).
#include "railcrash/consist.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "railcrash/error.hpp"
#include "railcrash/yaml_file.hpp"

namespace railcrash {
namespace {

struct Point2 {
  double x = 0.0, y = 0.0;  // [length]
};

class TemplateReader {
 public:
  TemplateReader(std::string path, YAML::Node root) : path_(std::move(path)), root_(std::move(root)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const {
    SourceLocation where{path_, node.IsDefined() ? node.Mark().line + 1 : 0};
    throw InputError(where.prefix() + "consist template: " + what);
  }

  const YAML::Node& root() const { return root_; }

  YAML::Node body(const std::string& name) const {
    for (const YAML::Node& b : root_["bodies"])
      if (b["name"] && b["name"].as<std::string>() == name) return b;
    fail(root_["bodies"], "no body named '" + name + "'; the template must name its bodies car1_* (striking car) and "
                          "car2_* (standing car) like models/report/final_two_car.yaml");
  }

  Point2 position(const std::string& name) const {
    const YAML::Node b = body(name);
    if (b["angle"] && b["angle"].as<double>() != 0.0)
      fail(b, "body '" + name + "' starts rotated; the consist builder needs the template's cars level");
    const YAML::Node p = b["position"];
    if (!p || !p.IsSequence() || p.size() != 2) fail(b, "body '" + name + "' has no position [x, y]");
    return {p[0].as<double>(), p[1].as<double>()};
  }

  YAML::Node element(const std::string& name) const {
    for (const YAML::Node& e : root_["elements"])
      if (e["name"] && e["name"].as<std::string>() == name) return e;
    fail(root_["elements"], "no element named '" + name + "' (the coupler_end between car1_coupler and car2_coupler)");
  }

 private:
  std::string path_;
  YAML::Node root_;
};

/// Deep copy of node with every scalar found in `names` replaced by its new name.
YAML::Node renamed(const YAML::Node& node, const std::map<std::string, std::string>& names) {
  if (node.IsScalar()) {
    const auto it = names.find(node.Scalar());
    YAML::Node out = YAML::Clone(node);
    if (it != names.end()) out = it->second;
    return out;
  }
  if (node.IsSequence()) {
    YAML::Node out(YAML::NodeType::Sequence);
    for (const YAML::Node& item : node) out.push_back(renamed(item, names));
    return out;
  }
  if (node.IsMap()) {
    YAML::Node out(YAML::NodeType::Map);
    for (const auto& item : node) out[item.first.Scalar()] = renamed(item.second, names);
    return out;
  }
  return YAML::Clone(node);
}

bool starts_with(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

YAML::Node point_on(const std::string& body, double x, double y) {
  YAML::Node p(YAML::NodeType::Map);
  p["body"] = body;
  p["at"] = flow_pair(x, y);
  p.SetStyle(YAML::EmitterStyle::Flow);
  return p;
}

}  // namespace

double available_memory_bytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  double kilobytes = 0.0;
  while (meminfo >> key >> kilobytes) {
    if (key == "MemAvailable:") return kilobytes * 1024.0;
    meminfo.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  }
  return std::numeric_limits<double>::infinity();
}

void check_consist_memory(const std::string& template_path, int cars_per_consist, double available_bytes) {
  const double needed = 2.0 * cars_per_consist * kConsistBytesPerCar;  // [bytes]
  if (needed <= available_bytes) return;
  std::ostringstream msg;
  msg.precision(3);
  msg << template_path << ": consist: " << cars_per_consist << " + " << cars_per_consist << " cars would need about "
      << needed / 1e9 << " GB of memory (" << kConsistBytesPerCar / 1e6 << " MB per car) and " << available_bytes / 1e9
      << " GB are available; use --cars " << std::max(1, static_cast<int>(available_bytes / (2.0 * kConsistBytesPerCar)))
      << " or fewer";
  throw InputError(msg.str());
}

std::string make_consist_model(const std::string& template_path, int cars_per_consist) {
  if (cars_per_consist >= 1) check_consist_memory(template_path, cars_per_consist, available_memory_bytes());
  YAML::Node root;
  try {
    root = load_yaml_file(template_path, "consist template");
  } catch (const YAML::Exception& e) {
    throw InputError(template_path + ": cannot read the consist template: " + e.what());
  }
  return make_consist_model(root, template_path, cars_per_consist);
}

std::string make_consist_model(const YAML::Node& root, const std::string& template_path, int cars_per_consist) {
  if (cars_per_consist < 1) throw InputError("consist: the number of cars per consist must be at least 1");
  const TemplateReader t(template_path, root);
  if (!root["bodies"] || !root["bodies"].IsSequence() || !root["elements"] || !root["elements"].IsSequence())
    t.fail(root, "needs 'bodies' and 'elements' lists");

  // ---- the template's geometry ----
  const YAML::Node faces = t.element("coupler_faces");
  const YAML::Node face_points = faces["points"];
  const YAML::Node free_length = faces["free_length"];
  if (!face_points || face_points.size() != 2 || !free_length || free_length.size() != 2)
    t.fail(faces, "coupler_faces needs two points and free_length [K, L]");
  const std::string striking_coupler = face_points[0]["body"].as<std::string>();
  const std::string standing_coupler = face_points[1]["body"].as<std::string>();
  if (striking_coupler != "car1_coupler" || standing_coupler != "car2_coupler")
    t.fail(faces, "coupler_faces must join car1_coupler (first point) and car2_coupler (second point)");
  const Point2 coupler_s = t.position("car1_coupler"), coupler_t = t.position("car2_coupler");
  const Point2 point_s{coupler_s.x + face_points[0]["at"][0].as<double>(), coupler_s.y + face_points[0]["at"][1].as<double>()};
  const Point2 point_t{coupler_t.x + face_points[1]["at"][0].as<double>(), coupler_t.y + face_points[1]["at"][1].as<double>()};
  const double free_s = free_length[0].as<double>(), free_t = free_length[1].as<double>();
  const double face_s = point_s.x + free_s;  // [length] striking car's coupler face
  const double face_t = point_t.x - free_t;  // [length] standing car's
  const Point2 centre_s = t.position("car1_center_body"), centre_t = t.position("car2_center_body");
  const Point2 rear_s = t.position("car1_rear_body"), rear_t = t.position("car2_rear_body");
  const double length_s = 2.0 * (face_s - centre_s.x);  // [length] over the coupler faces
  const double length_t = 2.0 * (centre_t.x - face_t);
  if (!(length_s > 0.0) || !(length_t > 0.0))
    t.fail(faces, "car1 must lie at x < 0 and car2 at x > 0 of their coupler faces");

  // ---- bodies ----
  YAML::Node bodies(YAML::NodeType::Sequence);
  std::vector<std::map<std::string, std::string>> names_s(static_cast<std::size_t>(cars_per_consist)),
      names_t(static_cast<std::size_t>(cars_per_consist));
  for (int k = 1; k <= cars_per_consist; ++k) {
    auto& ns = names_s[static_cast<std::size_t>(k - 1)];
    auto& nt = names_t[static_cast<std::size_t>(k - 1)];
    for (const YAML::Node& e : root["elements"]) {
      const std::string name = e["name"].as<std::string>();
      if (starts_with(name, "car1_")) ns[name] = "s" + std::to_string(k) + "_" + name.substr(5);
      if (starts_with(name, "car2_")) nt[name] = "t" + std::to_string(k) + "_" + name.substr(5);
    }
    for (const YAML::Node& b : root["bodies"]) {
      const std::string name = b["name"].as<std::string>();
      if (starts_with(name, "car1_")) ns[name] = "s" + std::to_string(k) + "_" + name.substr(5);
      else if (starts_with(name, "car2_")) nt[name] = "t" + std::to_string(k) + "_" + name.substr(5);
      else t.fail(b, "body '" + name + "' belongs to neither car (names must start with car1_ or car2_)");
    }
  }
  for (int k = 1; k <= cars_per_consist; ++k) {
    for (const YAML::Node& b : root["bodies"]) {
      const std::string name = b["name"].as<std::string>();
      const bool striking = starts_with(name, "car1_");
      YAML::Node copy = renamed(b, striking ? names_s[static_cast<std::size_t>(k - 1)] : names_t[static_cast<std::size_t>(k - 1)]);
      const double shift = (k - 1) * (striking ? -length_s : length_t);
      copy["position"] = flow_pair(b["position"][0].as<double>() + shift, b["position"][1].as<double>());
      copy["car"] = (striking ? "s" : "t") + std::to_string(k);  // each generated car is summarised on its own
      copy.SetStyle(YAML::EmitterStyle::Flow);
      bodies.push_back(copy);
    }
  }

  // ---- elements ----
  YAML::Node elements(YAML::NodeType::Sequence);
  std::map<std::string, std::string> interface_names = names_s[0];
  interface_names.insert(names_t[0].begin(), names_t[0].end());
  for (const YAML::Node& e : root["elements"]) {
    const std::string name = e["name"].as<std::string>();
    if (!starts_with(name, "car1_") && !starts_with(name, "car2_")) elements.push_back(renamed(e, interface_names));
  }
  for (int k = 1; k <= cars_per_consist; ++k) {
    for (const YAML::Node& e : root["elements"]) {
      const std::string name = e["name"].as<std::string>();
      if (starts_with(name, "car1_")) elements.push_back(renamed(e, names_s[static_cast<std::size_t>(k - 1)]));
      if (starts_with(name, "car2_")) elements.push_back(renamed(e, names_t[static_cast<std::size_t>(k - 1)]));
    }
    if (k == 1) continue;
    // Striking consist: car k's coupler face meets car k-1's rear face.
    const std::string ks = std::to_string(k), previous = std::to_string(k - 1);
    YAML::Node coupling_s = renamed(faces, {});
    coupling_s["name"] = "s" + ks + "_coupling";
    coupling_s["coupled"] = true;
    coupling_s["total_horizontal_slack"] = 0.0;
    YAML::Node points_s(YAML::NodeType::Sequence);
    points_s.push_back(point_on("s" + ks + "_coupler", point_s.x - coupler_s.x, point_s.y - coupler_s.y));
    points_s.push_back(point_on("s" + previous + "_rear_body", face_s - length_s + free_t - rear_s.x, point_s.y - rear_s.y));
    coupling_s["points"] = points_s;
    elements.push_back(coupling_s);
    // Standing consist: car k-1's rear face meets car k's coupler face.
    YAML::Node coupling_t = renamed(faces, {});
    coupling_t["name"] = "t" + ks + "_coupling";
    coupling_t["coupled"] = true;
    coupling_t["total_horizontal_slack"] = 0.0;
    YAML::Node points_t(YAML::NodeType::Sequence);
    points_t.push_back(point_on("t" + previous + "_rear_body", face_t + length_t - free_s - rear_t.x, point_t.y - rear_t.y));
    points_t.push_back(point_on("t" + ks + "_coupler", point_t.x - coupler_t.x, point_t.y - coupler_t.y));
    coupling_t["points"] = points_t;
    elements.push_back(coupling_t);
  }

  // ---- the model ----
  YAML::Node out(YAML::NodeType::Map);
  out["railcrash"] = root["railcrash"] ? root["railcrash"] : YAML::Node(1);
  std::ostringstream title;
  title << cars_per_consist << "-car consist striking a standing " << cars_per_consist << "-car consist (built from "
        << template_path << ")";
  out["name"] = title.str();
  for (const char* key : {"units", "gravity"})
    if (root[key]) out[key] = YAML::Clone(root[key]);
  out["bodies"] = bodies;
  out["elements"] = elements;
  for (const char* key : {"loads", "simulation", "responses"})
    if (root[key]) out[key] = renamed(root[key], interface_names);

  YAML::Emitter emitter;
  emitter << out;
  std::ostringstream text;
  text << "# Generated by `railcrash consist` from " << template_path << " (" << cars_per_consist
       << " cars per consist).\n# Car length over the coupler faces: striking " << length_s << ", standing " << length_t
       << " (include/railcrash/consist.hpp says how the consist is built).\n"
       << emitter.c_str() << "\n";
  return text.str();
}

}  // namespace railcrash
