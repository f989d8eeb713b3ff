// Scenario requests shared by the scenario tests: the limits models/scenarios/make.sh lists
// (not values of the standard).
#pragma once

#include <string>

#include "railcrash/scenarios/en15227.hpp"

namespace railcrash::testing {

/// Scenario `number` of `train` with offset 40 mm and limits 5 g, 50 mm, 100 mm, 20 mm.
inline ScenarioRequest example_request(int number, const std::string& train) {
  ScenarioRequest q;
  q.number = number;
  q.train_path = train;
  q.offset = 40.0;
  q.deceleration_limit = 5.0;
  q.survival_limit = 50.0;
  q.override_limit = 100.0;
  q.wheel_lift_limit = 20.0;
  return q;
}

}  // namespace railcrash::testing
