// Planar rigid-body kinematics shared by all elements.
//
// Body coordinates are q = (x, y, theta) of the centre of mass; a connection point with
// body-fixed offset s (from the centre of mass, in the body frame) sits at
//   r = (x, y) + R(theta) s,   R(theta) = [cos -sin; sin cos],
// and moves with  r' = (vx, vy) + omega * perp(R s),  perp(a) = (-a_y, a_x).
// A force F at that point is the generalized force (F_x, F_y, (R s) x F) on the body.
#pragma once

#include "railcrash/autodiff.hpp"

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

/// R(theta) s: the body-fixed offset s expressed in global axes.
template <class T>
Vec2<T> rotate(const T& theta, double sx, double sy) {
  const T c = cos(theta), s = sin(theta);
  return {c * sx - s * sy, s * sx + c * sy};
}

/// Global position of the point with body-fixed offset (sx, sy).
template <class T>
Vec2<T> point_position(const Pose<T>& q, double sx, double sy) {
  const Vec2<T> arm = rotate(q.theta, sx, sy);
  return {q.x + arm.x, q.y + arm.y};
}

/// Global velocity of that point.
template <class T>
Vec2<T> point_velocity(const Pose<T>& q, const Pose<T>& v, double sx, double sy) {
  const Vec2<T> arm = rotate(q.theta, sx, sy);
  return {v.x - v.theta * arm.y, v.y + v.theta * arm.x};
}

/// Adds the generalized force of a global force F applied at offset (sx, sy).
template <class T>
void add_point_force(const Pose<T>& q, double sx, double sy, const Vec2<T>& force, Pose<T>& generalized) {
  const Vec2<T> arm = rotate(q.theta, sx, sy);
  generalized.x += force.x;
  generalized.y += force.y;
  generalized.theta += cross(arm, force);
}

}  // namespace railcrash
