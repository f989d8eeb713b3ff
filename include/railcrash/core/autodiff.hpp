// Forward-mode automatic differentiation over a fixed, small number of local unknowns.
//
// Element laws are written once as templates over a scalar type T. Evaluated with
// T = double they give the residual; with T = Dual<double, N> they give the exact
// derivatives with respect to the element's N local unknowns (no finite-difference
// step to tune); nesting Dual<Dual<double, N>, N> gives second derivatives, which the
// constraint elements need for d(G^T lambda)/dq. Everything is fixed-size: no heap
// allocation, so it is safe inside residual and Jacobian evaluations.
#pragma once

#include <array>
#include <cmath>

namespace railcrash {

template <class S, int N>
struct Dual {
  S value{};
  std::array<S, N> grad{};

  Dual() = default;
  Dual(double v) : value(v) {}  // NOLINT: constants promote implicitly, as in arithmetic
  Dual(const S& v, int seed_index) : value(v) { grad[static_cast<std::size_t>(seed_index)] = S(1.0); }
  template <class U = S, class = std::enable_if_t<!std::is_same<U, double>::value>>
  Dual(const S& v) : value(v) {}  // NOLINT
};

template <class T> struct ScalarTraits { static double value(const T& x) { return x; } };
template <class S, int N> struct ScalarTraits<Dual<S, N>> {
  static double value(const Dual<S, N>& x) { return ScalarTraits<S>::value(x.value); }
};
/// The plain number behind any (possibly nested) dual.
template <class T> double value_of(const T& x) { return ScalarTraits<T>::value(x); }

#define RAILCRASH_DUAL_T template <class S, int N>
#define RAILCRASH_D Dual<S, N>

RAILCRASH_DUAL_T RAILCRASH_D operator-(const RAILCRASH_D& a) {
  RAILCRASH_D r; r.value = -a.value;
  for (int i = 0; i < N; ++i) r.grad[i] = -a.grad[i];
  return r;
}
RAILCRASH_DUAL_T RAILCRASH_D operator+(const RAILCRASH_D& a, const RAILCRASH_D& b) {
  RAILCRASH_D r; r.value = a.value + b.value;
  for (int i = 0; i < N; ++i) r.grad[i] = a.grad[i] + b.grad[i];
  return r;
}
RAILCRASH_DUAL_T RAILCRASH_D operator-(const RAILCRASH_D& a, const RAILCRASH_D& b) {
  RAILCRASH_D r; r.value = a.value - b.value;
  for (int i = 0; i < N; ++i) r.grad[i] = a.grad[i] - b.grad[i];
  return r;
}
RAILCRASH_DUAL_T RAILCRASH_D operator*(const RAILCRASH_D& a, const RAILCRASH_D& b) {
  RAILCRASH_D r; r.value = a.value * b.value;
  for (int i = 0; i < N; ++i) r.grad[i] = a.grad[i] * b.value + a.value * b.grad[i];
  return r;
}
RAILCRASH_DUAL_T RAILCRASH_D operator/(const RAILCRASH_D& a, const RAILCRASH_D& b) {
  RAILCRASH_D r; r.value = a.value / b.value;
  const S inv_b = S(1.0) / b.value;
  for (int i = 0; i < N; ++i) r.grad[i] = (a.grad[i] - r.value * b.grad[i]) * inv_b;
  return r;
}
RAILCRASH_DUAL_T RAILCRASH_D operator+(const RAILCRASH_D& a, double b) { RAILCRASH_D r = a; r.value = r.value + b; return r; }
RAILCRASH_DUAL_T RAILCRASH_D operator+(double a, const RAILCRASH_D& b) { return b + a; }
RAILCRASH_DUAL_T RAILCRASH_D operator-(const RAILCRASH_D& a, double b) { RAILCRASH_D r = a; r.value = r.value - b; return r; }
RAILCRASH_DUAL_T RAILCRASH_D operator-(double a, const RAILCRASH_D& b) { return -b + a; }
RAILCRASH_DUAL_T RAILCRASH_D operator*(const RAILCRASH_D& a, double b) {
  RAILCRASH_D r; r.value = a.value * b;
  for (int i = 0; i < N; ++i) r.grad[i] = a.grad[i] * b;
  return r;
}
RAILCRASH_DUAL_T RAILCRASH_D operator*(double a, const RAILCRASH_D& b) { return b * a; }
RAILCRASH_DUAL_T RAILCRASH_D operator/(const RAILCRASH_D& a, double b) { return a * (1.0 / b); }
RAILCRASH_DUAL_T RAILCRASH_D operator/(double a, const RAILCRASH_D& b) { return RAILCRASH_D(a) / b; }
RAILCRASH_DUAL_T RAILCRASH_D& operator+=(RAILCRASH_D& a, const RAILCRASH_D& b) { return a = a + b; }
RAILCRASH_DUAL_T RAILCRASH_D& operator-=(RAILCRASH_D& a, const RAILCRASH_D& b) { return a = a - b; }
RAILCRASH_DUAL_T RAILCRASH_D& operator*=(RAILCRASH_D& a, const RAILCRASH_D& b) { return a = a * b; }

// Comparisons look at the value only (mode selection, never differentiated).
RAILCRASH_DUAL_T bool operator<(const RAILCRASH_D& a, double b) { return value_of(a) < b; }
RAILCRASH_DUAL_T bool operator>(const RAILCRASH_D& a, double b) { return value_of(a) > b; }

// Chain rule helper: f(a) with f'(a) given.
template <class S, int N>
RAILCRASH_D chain(const RAILCRASH_D& a, const S& f, const S& dfda) {
  RAILCRASH_D r; r.value = f;
  for (int i = 0; i < N; ++i) r.grad[i] = a.grad[i] * dfda;
  return r;
}

using std::sin;
using std::cos;
using std::sqrt;
using std::atan2;
using std::tanh;
using std::exp;

RAILCRASH_DUAL_T RAILCRASH_D sin(const RAILCRASH_D& a) { return chain(a, S(sin(a.value)), S(cos(a.value))); }
RAILCRASH_DUAL_T RAILCRASH_D cos(const RAILCRASH_D& a) { return chain(a, S(cos(a.value)), S(-sin(a.value))); }
RAILCRASH_DUAL_T RAILCRASH_D sqrt(const RAILCRASH_D& a) {
  const S root = sqrt(a.value);
  return chain(a, root, S(0.5) / root);
}
RAILCRASH_DUAL_T RAILCRASH_D tanh(const RAILCRASH_D& a) {
  const S value = tanh(a.value);
  return chain(a, value, S(1.0) - value * value);
}
RAILCRASH_DUAL_T RAILCRASH_D exp(const RAILCRASH_D& a) {
  const S value = exp(a.value);
  return chain(a, value, value);
}
// atan2(y, x): d = (x dy - y dx) / (x^2 + y^2)
RAILCRASH_DUAL_T RAILCRASH_D atan2(const RAILCRASH_D& y, const RAILCRASH_D& x) {
  RAILCRASH_D r; r.value = atan2(y.value, x.value);
  const S inv_r2 = S(1.0) / (x.value * x.value + y.value * y.value);
  for (int i = 0; i < N; ++i) r.grad[i] = (x.value * y.grad[i] - y.value * x.grad[i]) * inv_r2;
  return r;
}

#undef RAILCRASH_D
#undef RAILCRASH_DUAL_T

}  // namespace railcrash
