// Planar rigid-body kinematics shared by all elements.
//
// Body coordinates are q = (x, y, theta) of the centre of mass; a connection point with
// body-fixed offset s (from the centre of mass, in the body frame) sits at
//   r = (x, y) + R(theta) s,   R(theta) = [cos -sin; sin cos],
// and moves with  r' = (vx, vy) + omega * perp(R s),  perp(a) = (-a_y, a_x).
// A force F at that point is the generalized force (F_x, F_y, (R s) x F) on the body.
#pragma once

#include "railcrash/core/autodiff.hpp"

namespace railcrash {

template <class T>
struct Vec2 {
  T x{}, y{};
};
template <class T> Vec2<T> operator+(const Vec2<T>& a, const Vec2<T>& b) { return {a.x + b.x, a.y + b.y}; }
template <class T> Vec2<T> operator-(const Vec2<T>& a, const Vec2<T>& b) { return {a.x - b.x, a.y - b.y}; }
template <class T> Vec2<T> operator*(const T& k, const Vec2<T>& a) { return {k * a.x, k * a.y}; }
template <class T> T dot(const Vec2<T>& a, const Vec2<T>& b) { return a.x * b.x + a.y * b.y; }
template <class T> T cross(const Vec2<T>& a, const Vec2<T>& b) { return a.x * b.y - a.y * b.x; }

/// Pose (x, y, theta) or its rate (vx, vy, omega) of one body, in global axes.
template <class T>
struct Pose {
  T x{}, y{}, theta{};
};

/// cos and sin of a body's angle: an element evaluation computes them once per body slot
/// (ElementState::rotation) and every point of the body uses them. Ground: the identity.
template <class T>
struct Rotation {
  T cos = T(1.0), sin = T(0.0);
};
template <class T>
Rotation<T> rotation_of(const T& theta) {
  return {cos(theta), sin(theta)};
}
/// The same for a dual angle whose value's rotation r is known: d cos = -sin d theta,
/// d sin = cos d theta (no second cos and sin of the value).
template <int N>
Rotation<Dual<double, N>> rotation_of(const Dual<double, N>& theta, const Rotation<double>& r) {
  Rotation<Dual<double, N>> out;
  out.cos.value = r.cos;
  out.sin.value = r.sin;
  for (std::size_t i = 0; i < static_cast<std::size_t>(N); ++i) {
    out.cos.grad[i] = -r.sin * theta.grad[i];
    out.sin.grad[i] = r.cos * theta.grad[i];
  }
  return out;
}

/// R(theta) s: the body-fixed offset s expressed in global axes.
template <class T>
Vec2<T> rotate(const Rotation<T>& r, double sx, double sy) {
  return {r.cos * sx - r.sin * sy, r.sin * sx + r.cos * sy};
}
template <class T>
Vec2<T> rotate(const T& theta, double sx, double sy) {
  return rotate(rotation_of(theta), sx, sy);
}

/// Global position of the point with body-fixed offset (sx, sy); r: the body's rotation.
template <class T>
Vec2<T> point_position(const Pose<T>& q, const Rotation<T>& r, double sx, double sy) {
  const Vec2<T> arm = rotate(r, sx, sy);
  return {q.x + arm.x, q.y + arm.y};
}
template <class T>
Vec2<T> point_position(const Pose<T>& q, double sx, double sy) {
  return point_position(q, rotation_of(q.theta), sx, sy);
}

/// Global velocity of that point.
template <class T>
Vec2<T> point_velocity(const Pose<T>& v, const Rotation<T>& r, double sx, double sy) {
  const Vec2<T> arm = rotate(r, sx, sy);
  return {v.x - v.theta * arm.y, v.y + v.theta * arm.x};
}
template <class T>
Vec2<T> point_velocity(const Pose<T>& q, const Pose<T>& v, double sx, double sy) {
  return point_velocity(v, rotation_of(q.theta), sx, sy);
}

/// Adds the generalized force of a global force F applied at offset (sx, sy).
template <class T>
void add_point_force(const Rotation<T>& r, double sx, double sy, const Vec2<T>& force, Pose<T>& generalized) {
  const Vec2<T> arm = rotate(r, sx, sy);
  generalized.x += force.x;
  generalized.y += force.y;
  generalized.theta += cross(arm, force);
}
template <class T>
void add_point_force(const Pose<T>& q, double sx, double sy, const Vec2<T>& force, Pose<T>& generalized) {
  add_point_force(rotation_of(q.theta), sx, sy, force, generalized);
}

}  // namespace railcrash
