#include <catch2/catch.hpp>

#include "railcrash/model_io.hpp"
#include "support.hpp"

using namespace railcrash;

TEST_CASE("slider-crank Jacobian matches central differences at random states", "[dae]") {
  const Model model = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/verification/cases/slider_crank.yaml");
  const DaeSystem system(model);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const std::vector<double> y = testing::random_state(system, rng);
    const std::vector<double> yp = testing::random_state(system, rng);
    double outside = 0.0;
    const double cj = 10.0 * (trial + 1);
    CHECK(testing::jacobian_error(system, 0.3, cj, y, yp, &outside) < 1e-6);
    CHECK(outside == 0.0);
  }
}
