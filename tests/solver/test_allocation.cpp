// The hot path allocates nothing: residual, Jacobian, root functions and quadrature rates
// of the report's two-car model are evaluated with a counting global operator new.
#include <catch2/catch.hpp>

#include <atomic>
#include <cstdlib>
#include <new>

#include "railcrash/model/model_io.hpp"
#include "railcrash/solver/dae_system.hpp"

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_counting{false};
}  // namespace

// Replaces the global allocation functions of the test program (the array and sized forms
// of the standard library forward to these).
void* operator new(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

using namespace railcrash;

TEST_CASE("residual, Jacobian, roots and quadrature rates allocate no memory", "[dae][performance]") {
  const Model model = load_model(std::string(RAILCRASH_SOURCE_DIR) + "/models/report/final_two_car.yaml").model;
  DaeSystem system(model);
  std::vector<double> y = system.initial_state();
  std::vector<double> yp(y.size(), 0.0), r(y.size()), values(static_cast<std::size_t>(system.pattern().nonzeros()));
  std::vector<double> g(static_cast<std::size_t>(system.root_count())), rates(static_cast<std::size_t>(system.quadrature_count()));
  for (std::size_t k = 0; k < y.size(); ++k) yp[k] = 1e-3 * static_cast<double>(k % 7);  // any rates will do

  g_allocations = 0;
  g_counting = true;
  for (int repeat = 0; repeat < 3; ++repeat) {
    system.residual(0.01, y.data(), yp.data(), r.data());
    system.jacobian(0.01, 1e4, y.data(), yp.data(), values.data());
    system.roots(0.01, y.data(), g.data());
    system.quadrature_rates(0.01, y.data(), rates.data());
  }
  g_counting = false;
  CHECK(g_allocations.load() == 0);

  // The counter itself works: a vector allocates.
  g_allocations = 0;
  g_counting = true;
  std::vector<double> probe(100);
  g_counting = false;
  CHECK(g_allocations.load() >= 1);
  CHECK(probe.size() == 100);
}
