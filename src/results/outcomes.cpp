#include "railcrash/results/outcomes.hpp"

#include <algorithm>
#include <cstdio>
#include <set>
#include <utility>

#include "railcrash/results/results.hpp"

namespace railcrash {

namespace {

/// The outcome a single change names ("" for a kink).
std::string single_outcome(const std::string& part) {
  static const char* const kExact[] = {"fracture",        "pin shear",     "face shear failure", "vertical overlap lost",
                                       "crushing failure", "shear failure", "bending failure",    "override",
                                       "solid"};
  for (const char* name : kExact)
    if (part == name) return part;
  if (part.rfind("bottomed", 0) == 0) return "bottomed";  // "bottomed (buff)": either side is the same outcome
  return "";
}

std::string milliseconds(double t) {
  char text[40];
  std::snprintf(text, sizeof text, "%.3fms", 1e3 * t);
  return text;
}

}  // namespace

std::string outcome_of_event(const std::string& what) {
  std::string outcomes;
  std::size_t start = 0;
  while (start <= what.size()) {
    const std::size_t comma = what.find(", ", start);
    const std::string part = what.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const std::string outcome = single_outcome(part);
    if (!outcome.empty()) outcomes += (outcomes.empty() ? "" : ", ") + outcome;
    if (comma == std::string::npos) break;
    start = comma + 2;
  }
  return outcomes;
}

OutcomeSignature outcome_signature(const std::vector<EventRecord>& events, double window) {
  OutcomeSignature signature;
  signature.window = window;
  std::set<std::pair<std::string, std::string>> seen;  // (element, outcome): first occurrence only
  for (const EventRecord& e : events) {
    const std::string outcomes = outcome_of_event(e.what);
    std::size_t start = 0;
    while (!outcomes.empty() && start <= outcomes.size()) {
      const std::size_t comma = outcomes.find(", ", start);
      const std::string outcome = outcomes.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      if (seen.emplace(e.element, outcome).second) signature.events.push_back(OutcomeEvent{e.t, e.element, outcome});
      if (comma == std::string::npos) break;
      start = comma + 2;
    }
  }
  std::stable_sort(signature.events.begin(), signature.events.end(),
                   [](const OutcomeEvent& a, const OutcomeEvent& b) { return a.t < b.t; });
  return signature;
}

std::string OutcomeSignature::text() const {
  if (events.empty()) return "none";
  std::string text;
  for (const OutcomeEvent& e : events) text += (text.empty() ? "" : ">") + e.element + ":" + e.what + "@" + milliseconds(e.t);
  return text;
}

std::string OutcomeSignature::order() const {
  if (events.empty()) return "none";
  std::string text;
  std::vector<std::string> group;
  const auto close_group = [&] {
    std::sort(group.begin(), group.end());
    std::string members;
    for (const std::string& m : group) members += (members.empty() ? "" : "+") + m;
    text += (text.empty() ? "" : ">") + members;
    group.clear();
  };
  for (std::size_t k = 0; k < events.size(); ++k) {
    if (k > 0 && events[k].t - events[k - 1].t > window) close_group();
    group.push_back(events[k].element + ":" + events[k].what);
  }
  close_group();
  return text;
}

std::string OutcomeSignature::json() const {
  std::string json = "{\"signature\": " + json_string(text()) + ", \"branch\": " + json_string(order()) +
                     ", \"window\": " + json_number(window) + ", \"events\": [";
  for (std::size_t k = 0; k < events.size(); ++k)
    json += std::string(k ? ", " : "") + "{\"t\": " + json_number(events[k].t) + ", \"element\": " +
            json_string(events[k].element) + ", \"what\": " + json_string(events[k].what) + "}";
  return json + "]}";
}

bool same_branch(const OutcomeSignature& a, const OutcomeSignature& b) { return a.order() == b.order(); }

}  // namespace railcrash
