// Forward-mode dual numbers: first derivatives of every operation against analytic
// derivatives, and nested duals' second derivatives against analytic Hessians.
#include <catch2/catch.hpp>

#include <cmath>

#include "railcrash/core/autodiff.hpp"

using namespace railcrash;

namespace {

using D = Dual<double, 2>;   // unknowns (x, y)
using D1 = Dual<double, 2>;
using D2 = Dual<D1, 2>;      // second derivatives in (x, y)

constexpr double kX = 0.7;
constexpr double kY = -1.3;

D x_seed(double x = kX) { return D(x, 0); }
D y_seed(double y = kY) { return D(y, 1); }

/// Seeds both levels of a nested dual with the same unknown.
D2 second_order_seed(double value, int index) { return D2(D1(value, index), index); }

/// Catch's default Approx tolerance (1e-5 relative) is far too loose for exact derivatives.
Approx exactly(double expected) { return Approx(expected).epsilon(1e-12).margin(1e-13); }

/// Value and gradient of a first-order dual against expected numbers.
void check_first_order(const D& f, double value, double dfdx, double dfdy) {
  CHECK(f.value == exactly(value));
  CHECK(f.grad[0] == exactly(dfdx));
  CHECK(f.grad[1] == exactly(dfdy));
}

/// Value, gradient (both copies) and Hessian of a nested dual against expected numbers.
void check_second_order(const D2& f, double value, const std::array<double, 2>& gradient,
                        const std::array<std::array<double, 2>, 2>& hessian) {
  CHECK(f.value.value == exactly(value));
  for (std::size_t i = 0; i < 2; ++i) {
    INFO("i = " << i);
    // The first derivative appears twice: in the inner gradient of the value and as the
    // value of the outer gradient.
    CHECK(f.value.grad[i] == exactly(gradient[i]));
    CHECK(f.grad[i].value == exactly(gradient[i]));
    for (std::size_t j = 0; j < 2; ++j) {
      INFO("j = " << j);
      CHECK(f.grad[i].grad[j] == exactly(hessian[i][j]));
    }
  }
}

}  // namespace

TEST_CASE("Dual seeding sets one unit derivative and promoted constants have none", "[autodiff]") {
  check_first_order(x_seed(), kX, 1.0, 0.0);
  check_first_order(y_seed(), kY, 0.0, 1.0);
  check_first_order(D(2.5), 2.5, 0.0, 0.0);
}

TEST_CASE("Dual sums, differences and negation differentiate linearly", "[autodiff]") {
  const D x = x_seed(), y = y_seed();
  check_first_order(x + y, kX + kY, 1.0, 1.0);
  check_first_order(x - y, kX - kY, 1.0, -1.0);
  check_first_order(-x, -kX, -1.0, 0.0);
  check_first_order(x + 2.0, kX + 2.0, 1.0, 0.0);
  check_first_order(2.0 + y, 2.0 + kY, 0.0, 1.0);
  check_first_order(x - 2.0, kX - 2.0, 1.0, 0.0);
  check_first_order(2.0 - y, 2.0 - kY, 0.0, -1.0);

  D accumulated = x;
  accumulated += y;
  check_first_order(accumulated, kX + kY, 1.0, 1.0);
  accumulated -= x;
  check_first_order(accumulated, kY, 0.0, 1.0);
}

TEST_CASE("Dual products follow the product rule", "[autodiff]") {
  const D x = x_seed(), y = y_seed();
  check_first_order(x * y, kX * kY, kY, kX);
  check_first_order(x * x, kX * kX, 2.0 * kX, 0.0);
  check_first_order(3.0 * x, 3.0 * kX, 3.0, 0.0);
  check_first_order(y * -4.0, -4.0 * kY, 0.0, -4.0);

  D product = x;
  product *= y;
  check_first_order(product, kX * kY, kY, kX);
}

TEST_CASE("Dual quotients follow the quotient rule", "[autodiff]") {
  const D x = x_seed(), y = y_seed();
  check_first_order(x / y, kX / kY, 1.0 / kY, -kX / (kY * kY));
  check_first_order(x / 4.0, kX / 4.0, 0.25, 0.0);
  check_first_order(2.0 / y, 2.0 / kY, 0.0, -2.0 / (kY * kY));
  check_first_order((x * y) / (x + y), kX * kY / (kX + kY), kY * kY / ((kX + kY) * (kX + kY)),
                    kX * kX / ((kX + kY) * (kX + kY)));
}

TEST_CASE("Dual sin, cos and sqrt apply the chain rule", "[autodiff]") {
  const D x = x_seed(), y = y_seed();
  check_first_order(sin(x), std::sin(kX), std::cos(kX), 0.0);
  check_first_order(cos(y), std::cos(kY), 0.0, -std::sin(kY));
  check_first_order(sin(x * y), std::sin(kX * kY), kY * std::cos(kX * kY), kX * std::cos(kX * kY));
  check_first_order(cos(2.0 * x - y), std::cos(2.0 * kX - kY), -2.0 * std::sin(2.0 * kX - kY), std::sin(2.0 * kX - kY));
  const double r = std::sqrt(kX * kX + kY * kY);
  check_first_order(sqrt(x * x + y * y), r, kX / r, kY / r);
  check_first_order(sqrt(x), std::sqrt(kX), 0.5 / std::sqrt(kX), 0.0);
}

TEST_CASE("Dual atan2 differentiates both arguments in every quadrant", "[autodiff]") {
  // atan2(y, x): d/dx = -y / r^2, d/dy = x / r^2
  const double points[][2] = {{0.7, 0.4}, {-0.7, 0.4}, {-0.7, -0.4}, {0.7, -0.4}, {0.0, 1.2}};
  for (const auto& p : points) {
    const double px = p[0], py = p[1];
    INFO("x = " << px << ", y = " << py);
    const double r2 = px * px + py * py;
    check_first_order(atan2(y_seed(py), x_seed(px)), std::atan2(py, px), -py / r2, px / r2);
  }
  // Only one argument a dual: atan2(y, 2) as a function of y.
  check_first_order(atan2(y_seed(), D(2.0)), std::atan2(kY, 2.0), 0.0, 2.0 / (4.0 + kY * kY));
}

TEST_CASE("Dual composite expression matches its analytic gradient", "[autodiff]") {
  // f = sin(x y) / sqrt(x^2 + y^2) + atan2(y, x) cos(x)
  const auto f = [](const auto& x, const auto& y) { return sin(x * y) / sqrt(x * x + y * y) + atan2(y, x) * cos(x); };
  const double points[][2] = {{kX, kY}, {1.9, 0.35}, {-0.4, 2.2}};
  for (const auto& p : points) {
    const double x = p[0], y = p[1];
    INFO("x = " << x << ", y = " << y);
    const double r2 = x * x + y * y, r = std::sqrt(r2), r3 = r2 * r;
    const double s = std::sin(x * y), c = std::cos(x * y), angle = std::atan2(y, x);
    const double value = s / r + angle * std::cos(x);
    const double dfdx = y * c / r - s * x / r3 - y / r2 * std::cos(x) - angle * std::sin(x);
    const double dfdy = x * c / r - s * y / r3 + x / r2 * std::cos(x);
    check_first_order(f(x_seed(x), y_seed(y)), value, dfdx, dfdy);
    CHECK(f(x, y) == exactly(value));  // the same code with plain doubles
  }
}

TEST_CASE("Nested duals give the Hessians of products and quotients", "[autodiff]") {
  const D2 x = second_order_seed(kX, 0), y = second_order_seed(kY, 1);
  // x^2 y
  check_second_order(x * x * y, kX * kX * kY, {2.0 * kX * kY, kX * kX}, {{{2.0 * kY, 2.0 * kX}, {2.0 * kX, 0.0}}});
  // x / y: f_xy = -1/y^2, f_yy = 2x/y^3
  check_second_order(x / y, kX / kY, {1.0 / kY, -kX / (kY * kY)},
                     {{{0.0, -1.0 / (kY * kY)}, {-1.0 / (kY * kY), 2.0 * kX / (kY * kY * kY)}}});
  // 3 x y - 2 x + 5 (linear pieces have no curvature, constants no gradient)
  check_second_order(3.0 * x * y - 2.0 * x + 5.0, 3.0 * kX * kY - 2.0 * kX + 5.0, {3.0 * kY - 2.0, 3.0 * kX},
                     {{{0.0, 3.0}, {3.0, 0.0}}});
}

TEST_CASE("Nested duals give the Hessians of sin, cos, sqrt and atan2", "[autodiff]") {
  const D2 x = second_order_seed(kX, 0), y = second_order_seed(kY, 1);
  const double sx = std::sin(kX), cx = std::cos(kX), sy = std::sin(kY), cy = std::cos(kY);
  // sin(x) cos(y)
  check_second_order(sin(x) * cos(y), sx * cy, {cx * cy, -sx * sy}, {{{-sx * cy, -cx * sy}, {-cx * sy, -sx * cy}}});

  const double r2 = kX * kX + kY * kY, r = std::sqrt(r2), r3 = r2 * r, r4 = r2 * r2;
  // sqrt(x^2 + y^2): r_xx = y^2/r^3, r_xy = -x y/r^3, r_yy = x^2/r^3
  check_second_order(sqrt(x * x + y * y), r, {kX / r, kY / r},
                     {{{kY * kY / r3, -kX * kY / r3}, {-kX * kY / r3, kX * kX / r3}}});
  // atan2(y, x): a_xx = 2 x y/r^4, a_xy = (y^2 - x^2)/r^4, a_yy = -2 x y/r^4
  check_second_order(atan2(y, x), std::atan2(kY, kX), {-kY / r2, kX / r2},
                     {{{2.0 * kX * kY / r4, (kY * kY - kX * kX) / r4}, {(kY * kY - kX * kX) / r4, -2.0 * kX * kY / r4}}});
}

TEST_CASE("value_of unwraps plain, single and nested duals", "[autodiff]") {
  CHECK(value_of(1.25) == 1.25);
  CHECK(value_of(D(-3.5, 1)) == -3.5);
  const D2 nested = second_order_seed(kX, 0) * second_order_seed(kY, 1) + 0.5;
  CHECK(value_of(nested) == exactly(kX * kY + 0.5));
  // Comparisons of nested duals look at that value.
  CHECK(nested < kX * kY + 0.6);
  CHECK_FALSE(nested < kX * kY + 0.4);
  CHECK(nested > kX * kY + 0.4);
}
