// Joints: assembled Jacobians, constraint equations at satisfying and violating
// configurations, AD gradients and Hessians against central differences, rotational rows.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "railcrash/elements/joints.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

// ---- joint types and layouts ----------------------------------------------------------

/// What separation r2 - r1 a joint allows.
enum class Separation { Zero, AlongAxis, Free };

struct JointType {
  const char* type;
  int rows;
  std::vector<bool> rotational;  // per row
  bool has_axis;
  bool locks_angle;
  Separation separation;
};

const std::vector<JointType> kJoints = {
    {"pin_joint", 2, {false, false}, false, false, Separation::Zero},
    {"slider_joint", 2, {false, true}, true, true, Separation::AlongAxis},
    {"sliding_pin_joint", 1, {false}, true, false, Separation::AlongAxis},
    {"double_slider_joint", 1, {true}, false, true, Separation::Free},
    {"rigid_joint", 3, {false, false, true}, false, true, Separation::Zero},
};

/// Which ends of the joint are bodies.
enum class Ends { GroundBody, BodyGround, BodyBody };
const Ends kAllEnds[] = {Ends::GroundBody, Ends::BodyGround, Ends::BodyBody};
const char* ends_name(Ends ends) {
  return ends == Ends::GroundBody ? "ground-body" : (ends == Ends::BodyGround ? "body-ground" : "body-body");
}

struct Vec {
  double x, y;
};
Vec rotated(double theta, const Vec& s) {
  return {std::cos(theta) * s.x - std::sin(theta) * s.y, std::sin(theta) * s.x + std::cos(theta) * s.y};
}

constexpr Vec kOffset1{0.5, 0.25};       // P1 on end 1, body frame
constexpr Vec kOffset2{-0.4, 0.3};       // P2 on end 2, body frame
constexpr Vec kAxis{0.6, 0.8};           // sliding direction in end 1's frame (unit)
constexpr double kTravel = 0.7;          // P2 - P1 along the axis in the satisfied layout
constexpr Vec kFreeSeparation{0.9, -0.6};  // P2 - P1 for the double slider

/// Pose of one end; ground ends sit at the origin unrotated.
struct End {
  bool ground;
  double x, y, theta;
};

struct JointLayout {
  End end1, end2;
  double relative_angle() const { return end2.theta - end1.theta; }
};

/// A layout that satisfies the joint: body 1 rotated (unless ground), body 2 rotated further.
JointLayout satisfied_layout(const JointType& joint, Ends ends) {
  JointLayout l;
  l.end1 = {ends == Ends::GroundBody, 0.0, 0.0, ends == Ends::GroundBody ? 0.0 : 0.4};
  l.end2 = {ends == Ends::BodyGround, 0.0, 0.0, ends == Ends::BodyGround ? 0.0 : 0.75};
  Vec separation{0.0, 0.0};
  if (joint.separation == Separation::AlongAxis) {
    const Vec along = rotated(l.end1.theta, kAxis);
    separation = {kTravel * along.x, kTravel * along.y};
  } else if (joint.separation == Separation::Free) {
    separation = kFreeSeparation;
  }
  const Vec arm1 = rotated(l.end1.theta, kOffset1), arm2 = rotated(l.end2.theta, kOffset2);
  if (ends == Ends::BodyGround) {
    // P2 is fixed at its ground offset: place body 1 so that P1 = P2 - separation.
    l.end1.x = kOffset2.x - separation.x - arm1.x;
    l.end1.y = kOffset2.y - separation.y - arm1.y;
  } else {
    l.end1.x = ends == Ends::GroundBody ? 0.0 : 0.3;
    l.end1.y = ends == Ends::GroundBody ? 0.0 : -0.2;
    const Vec p1{l.end1.x + arm1.x, l.end1.y + arm1.y};
    l.end2.x = p1.x + separation.x - arm2.x;
    l.end2.y = p1.y + separation.y - arm2.y;
  }
  return l;
}

/// YAML of a one-joint model; the joint's locked angle is written out unless `default_angle`.
std::string joint_model(const JointType& joint, const JointLayout& l, bool default_angle = false) {
  std::ostringstream text;
  text << std::setprecision(17);
  text << "railcrash: 1\nname: joint test\nunits: SI\ngravity: [0, 0]\nbodies:\n";
  const auto body = [&](const char* name, const End& e, double vx, double vy, double omega) {
    if (e.ground) return;
    text << "  - {name: " << name << ", mass: 1.5, inertia: 0.2, position: [" << e.x << ", " << e.y
         << "], angle: " << e.theta << ", velocity: [" << vx << ", " << vy << "], angular_velocity: " << omega << "}\n";
  };
  body("one", l.end1, 0.3, -0.2, 0.5);
  body("two", l.end2, -0.1, 0.4, -0.7);
  text << "elements:\n  - name: j\n    type: " << joint.type << "\n";
  if (joint.has_axis) text << "    axis: [" << kAxis.x << ", " << kAxis.y << "]\n";
  if (joint.locks_angle && !default_angle) text << "    relative_angle: " << l.relative_angle() << "\n";
  text << "    points: [{body: " << (l.end1.ground ? "ground" : "one") << ", at: [" << kOffset1.x << ", " << kOffset1.y
       << "]}, {body: " << (l.end2.ground ? "ground" : "two") << ", at: [" << kOffset2.x << ", " << kOffset2.y
       << "]}]\n";
  text << "simulation: {t_end: 1.0}\n";
  return text.str();
}

// ---- the documented constraint equations, computed by hand -------------------------------

/// Phi of the joint with the two ends at the given poses and locked angle a0.
std::vector<double> hand_constraint(const JointType& joint, const End& end1, const End& end2, double locked_angle) {
  const Vec arm1 = rotated(end1.theta, kOffset1), arm2 = rotated(end2.theta, kOffset2);
  const Vec d{end2.x + arm2.x - end1.x - arm1.x, end2.y + arm2.y - end1.y - arm1.y};  // r2 - r1
  const Vec normal = rotated(end1.theta, {-kAxis.y, kAxis.x});
  const double along_normal = normal.x * d.x + normal.y * d.y;
  const double angle = end2.theta - end1.theta - locked_angle;
  const std::string type = joint.type;
  if (type == "pin_joint") return {d.x, d.y};
  if (type == "slider_joint") return {along_normal, angle};
  if (type == "sliding_pin_joint") return {along_normal};
  if (type == "double_slider_joint") return {angle};
  return {d.x, d.y, angle};  // rigid_joint
}

// ---- access to the DAE system ---------------------------------------------------------------

std::vector<double> constraint_values(const DaeSystem& system, const std::vector<double>& q) {
  std::vector<double> phi(static_cast<std::size_t>(system.constraint_rows()), 0.0);
  system.constraints(q.data(), phi.data(), nullptr);
  return phi;
}

/// The layout's ends with the body of one end moved (the global q of the one-joint model).
struct Poses {
  End end1, end2;
};

/// Global q for ends (bodies in model order: end 1 first if it is a body).
std::vector<double> global_q(const Poses& p) {
  std::vector<double> q;
  for (const End* e : {&p.end1, &p.end2})
    if (!e->ground)
      for (double value : {e->x, e->y, e->theta}) q.push_back(value);
  return q;
}

std::array<Pose<double>, 2> local_poses(const std::vector<double>& values) {
  return {Pose<double>{values[0], values[1], values[2]}, Pose<double>{values[3], values[4], values[5]}};
}

}  // namespace

// ---- (a) Jacobians ------------------------------------------------------------------------

TEST_CASE("joint DAE Jacobians match central differences inside the pattern", "[elements]") {
  for (const JointType& joint : kJoints)
    for (const Ends ends : kAllEnds) {
      INFO(joint.type << " " << ends_name(ends));
      const Model model = testing::model_from_text(joint_model(joint, satisfied_layout(joint, ends)));
      DaeSystem system(model);
      REQUIRE(system.constraint_rows() == joint.rows);
      std::mt19937 rng(5);
      for (int trial = 0; trial < 4; ++trial) {
        INFO("trial " << trial);
        // random_state perturbs every unknown, so lambda and mu are non-zero here.
        const std::vector<double> y = testing::random_state(system, rng, 0.5);
        const std::vector<double> yp = testing::random_state(system, rng, 0.5);
        double outside = -1.0;
        CHECK(testing::jacobian_error(system, 0.2, 15.0 * (trial + 1), y, yp, &outside) < 1e-6);
        CHECK(outside == 0.0);
      }
    }
}

// ---- (b) constraint values ------------------------------------------------------------------

TEST_CASE("joint constraints vanish in a satisfying layout and follow the documented equations when violated",
          "[elements]") {
  for (const JointType& joint : kJoints)
    for (const Ends ends : kAllEnds) {
      INFO(joint.type << " " << ends_name(ends));
      const JointLayout layout = satisfied_layout(joint, ends);
      const Model model = testing::model_from_text(joint_model(joint, layout));
      DaeSystem system(model);
      REQUIRE(system.constraint_rows() == joint.rows);
      const double a0 = layout.relative_angle();

      const Poses satisfied{layout.end1, layout.end2};
      for (double phi : constraint_values(system, global_q(satisfied))) CHECK(std::abs(phi) < 1e-12);

      // Move the body end (end 2, or end 1 when end 2 is ground).
      const bool move_end2 = !layout.end2.ground;
      const double sign = move_end2 ? 1.0 : -1.0;  // moving end 1 by delta changes r2 - r1 by -delta
      const auto moved = [&](double dx, double dy, double dtheta) {
        Poses p = satisfied;
        End& e = move_end2 ? p.end2 : p.end1;
        e.x += dx;
        e.y += dy;
        e.theta += dtheta;
        return p;
      };

      {
        INFO("a translation violates the translational rows by the documented amounts");
        const Vec delta{0.03, -0.02};
        const std::vector<double> phi = constraint_values(system, global_q(moved(delta.x, delta.y, 0.0)));
        const Vec normal = rotated(layout.end1.theta, {-kAxis.y, kAxis.x});
        std::vector<double> expected;
        if (joint.separation == Separation::Zero) expected = {sign * delta.x, sign * delta.y};
        if (joint.separation == Separation::AlongAxis) expected = {sign * (normal.x * delta.x + normal.y * delta.y)};
        if (joint.locks_angle) expected.push_back(0.0);  // the angle row ignores translation
        REQUIRE(phi.size() == expected.size());
        for (std::size_t r = 0; r < phi.size(); ++r) {
          INFO("row " << r);
          CHECK(phi[r] == Approx(expected[r]).margin(1e-12));
        }
        if (joint.separation != Separation::Free) CHECK(std::abs(phi[0]) > 1e-3);
      }

      {
        INFO("a rotation violates the angle row by the rotation and moves the points");
        const double turn = 0.05;
        const Poses p = moved(0.0, 0.0, turn);
        const std::vector<double> phi = constraint_values(system, global_q(p));
        const std::vector<double> expected = hand_constraint(joint, p.end1, p.end2, a0);
        REQUIRE(phi.size() == expected.size());
        for (std::size_t r = 0; r < phi.size(); ++r) {
          INFO("row " << r);
          CHECK(phi[r] == Approx(expected[r]).margin(1e-12));
          if (joint.rotational[r]) CHECK(phi[r] == Approx(sign * turn).margin(1e-12));
          CHECK(std::abs(phi[r]) > 1e-3);  // offset points: every row notices a rotation
        }
      }

      {
        INFO("general motions follow the documented equations");
        std::mt19937 rng(17);
        std::uniform_real_distribution<double> u(-0.4, 0.4);
        for (int trial = 0; trial < 5; ++trial) {
          const Poses p = moved(u(rng), u(rng), u(rng));
          const std::vector<double> phi = constraint_values(system, global_q(p));
          const std::vector<double> expected = hand_constraint(joint, p.end1, p.end2, a0);
          for (std::size_t r = 0; r < phi.size(); ++r) {
            INFO("trial " << trial << " row " << r);
            CHECK(phi[r] == Approx(expected[r]).margin(1e-12));
          }
        }
      }
    }
}

TEST_CASE("sliding joints stay satisfied when body 2 slides along the axis in body 1's frame", "[elements]") {
  for (const char* type : {"slider_joint", "sliding_pin_joint"}) {
    const JointType& joint = *std::find_if(kJoints.begin(), kJoints.end(),
                                           [&](const JointType& j) { return std::string(j.type) == type; });
    INFO(type);
    const JointLayout layout = satisfied_layout(joint, Ends::BodyBody);
    const Model model = testing::model_from_text(joint_model(joint, layout));
    DaeSystem system(model);
    const Vec along = rotated(layout.end1.theta, kAxis);  // rotated with body 1, not the global axis
    Poses slid{layout.end1, layout.end2};
    slid.end2.x += 0.4 * along.x;
    slid.end2.y += 0.4 * along.y;
    for (double phi : constraint_values(system, global_q(slid))) CHECK(std::abs(phi) < 1e-12);
    // Sliding along the unrotated axis instead does violate the joint.
    Poses wrong{layout.end1, layout.end2};
    wrong.end2.x += 0.4 * kAxis.x;
    wrong.end2.y += 0.4 * kAxis.y;
    CHECK(std::abs(constraint_values(system, global_q(wrong))[0]) > 1e-2);
  }
}

TEST_CASE("joints without relative_angle lock the initial relative angle", "[elements]") {
  for (const JointType& joint : kJoints) {
    if (!joint.locks_angle) continue;
    INFO(joint.type);
    // Relative angle in the layout: 0.75 - 0.4.
    const JointLayout layout = satisfied_layout(joint, Ends::BodyBody);
    const Model model = testing::model_from_text(joint_model(joint, layout, /*default_angle=*/true));
    const auto* locking = dynamic_cast<const AngleLockingJoint*>(model.elements().front().get());
    REQUIRE(locking != nullptr);
    REQUIRE(locking->locked_angle.has_value());
    CHECK(*locking->locked_angle == Approx(0.35).epsilon(1e-12));
    DaeSystem system(model);
    Poses p{layout.end1, layout.end2};
    const std::vector<double> at_start = constraint_values(system, global_q(p));
    p.end2.theta += 0.1;
    const std::vector<double> turned = constraint_values(system, global_q(p));
    for (int r = 0; r < joint.rows; ++r)
      if (joint.rotational[static_cast<std::size_t>(r)]) {
        CHECK(std::abs(at_start[static_cast<std::size_t>(r)]) < 1e-12);
        CHECK(turned[static_cast<std::size_t>(r)] == Approx(0.1).epsilon(1e-12));
      }
  }
}

// ---- (c) gradients and Hessians ------------------------------------------------------------

TEST_CASE("joint gradients and Hessians match central differences of the constraint", "[elements]") {
  for (const JointType& joint : kJoints)
    for (const Ends ends : kAllEnds) {
      INFO(joint.type << " " << ends_name(ends));
      const Model model = testing::model_from_text(joint_model(joint, satisfied_layout(joint, ends)));
      const Element& element = *model.elements().front();
      REQUIRE(element.constraint_count() == joint.rows);
      const auto rows = static_cast<std::size_t>(joint.rows);

      const auto phi_at = [&](const std::vector<double>& values) {
        double phi[kMaxConstraintRows] = {};
        element.constraint(local_poses(values), phi);
        return std::vector<double>(phi, phi + rows);
      };
      const auto gradient_at = [&](const std::vector<double>& values) {
        double phi[kMaxConstraintRows] = {};
        double gradient[kMaxConstraintRows][6] = {};
        element.constraint_gradient(local_poses(values), phi, gradient);
        std::vector<std::vector<double>> g(rows);
        for (std::size_t r = 0; r < rows; ++r) g[r].assign(gradient[r], gradient[r] + 6);
        return g;
      };

      std::mt19937 rng(23);
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      for (int trial = 0; trial < 5; ++trial) {
        INFO("trial " << trial);
        std::vector<double> q(6);
        for (double& value : q) value = u(rng);

        double phi[kMaxConstraintRows] = {};
        double gradient[kMaxConstraintRows][6] = {};
        double hessian[kMaxConstraintRows][6][6] = {};
        element.constraint_hessian(local_poses(q), phi, gradient, hessian);
        const std::vector<double> plain = phi_at(q);
        const std::vector<std::vector<double>> g = gradient_at(q);

        for (std::size_t r = 0; r < rows; ++r) {
          INFO("row " << r);
          CHECK(phi[r] == Approx(plain[r]).margin(1e-14));
          for (std::size_t j = 0; j < 6; ++j) {
            INFO("column " << j);
            const double h = 1e-6;
            std::vector<double> plus = q, minus = q;
            plus[j] += h;
            minus[j] -= h;
            const double fd_gradient = (phi_at(plus)[r] - phi_at(minus)[r]) / (2.0 * h);
            CHECK(g[r][j] == Approx(fd_gradient).margin(1e-8));
            CHECK(gradient[r][j] == Approx(g[r][j]).margin(1e-14));
            const std::vector<std::vector<double>> g_plus = gradient_at(plus), g_minus = gradient_at(minus);
            for (std::size_t i = 0; i < 6; ++i) {
              INFO("second column " << i);
              const double fd_hessian = (g_plus[r][i] - g_minus[r][i]) / (2.0 * h);
              CHECK(hessian[r][i][j] == Approx(fd_hessian).margin(1e-8));
            }
          }
        }
      }
    }
}

TEST_CASE("pin_joint gradient and Hessian have the analytic offset terms", "[elements]") {
  // Body-body pin: Phi = x2 + R(t2) s2 - x1 - R(t1) s1, so dPhi_x/dt1 = +(R(t1) s1)_y and
  // d^2 Phi_x / dt1^2 = +(R(t1) s1)_x (and the opposite signs for body 2).
  const JointType& pin = kJoints.front();
  const Model model = testing::model_from_text(joint_model(pin, satisfied_layout(pin, Ends::BodyBody)));
  const Element& element = *model.elements().front();
  const std::array<Pose<double>, 2> q{Pose<double>{0.1, 0.2, 0.9}, Pose<double>{-0.3, 0.5, -0.4}};
  double phi[kMaxConstraintRows], gradient[kMaxConstraintRows][6], hessian[kMaxConstraintRows][6][6];
  element.constraint_hessian(q, phi, gradient, hessian);
  const Vec arm1 = rotated(0.9, kOffset1), arm2 = rotated(-0.4, kOffset2);
  CHECK(phi[0] == Approx(-0.3 + arm2.x - 0.1 - arm1.x));
  CHECK(phi[1] == Approx(0.5 + arm2.y - 0.2 - arm1.y));
  const double expected_gradient[2][6] = {{-1, 0, arm1.y, 1, 0, -arm2.y}, {0, -1, -arm1.x, 0, 1, arm2.x}};
  for (std::size_t r = 0; r < 2; ++r)
    for (std::size_t j = 0; j < 6; ++j) {
      INFO("row " << r << " column " << j);
      CHECK(gradient[r][j] == Approx(expected_gradient[r][j]).margin(1e-14));
    }
  CHECK(hessian[0][2][2] == Approx(arm1.x));
  CHECK(hessian[1][2][2] == Approx(arm1.y));
  CHECK(hessian[0][5][5] == Approx(-arm2.x));
  CHECK(hessian[1][5][5] == Approx(-arm2.y));
  CHECK(hessian[0][2][5] == Approx(0.0).margin(1e-14));
  CHECK(hessian[0][0][2] == Approx(0.0).margin(1e-14));
}

// ---- (d) rotational rows --------------------------------------------------------------------

TEST_CASE("constraint_row_is_rotational marks exactly the angle rows", "[elements]") {
  for (const JointType& joint : kJoints) {
    INFO(joint.type);
    const Model model = testing::model_from_text(joint_model(joint, satisfied_layout(joint, Ends::BodyBody)));
    const Element& element = *model.elements().front();
    for (int r = 0; r < joint.rows; ++r) {
      INFO("row " << r);
      CHECK(element.constraint_row_is_rotational(r) == joint.rotational[static_cast<std::size_t>(r)]);
    }
  }
}

TEST_CASE("DaeSystem maps rotational rows and owners through the constraint offsets", "[elements]") {
  // All five joints between two bodies (over-constrained, but the row layout is what counts).
  const Model model = testing::model_from_text(
      "railcrash: 1\nname: all joints\nunits: SI\ngravity: [0, 0]\n"
      "bodies:\n  - {name: a, mass: 1.0, inertia: 1.0, position: [0, 0]}\n"
      "  - {name: b, mass: 1.0, inertia: 1.0, position: [1, 0]}\n"
      "elements:\n"
      "  - {name: pin, type: pin_joint, points: [{body: a, at: [0.5, 0]}, {body: b, at: [-0.5, 0]}]}\n"
      "  - {name: slider, type: slider_joint, axis: [1, 0], points: [{body: a}, {body: b}]}\n"
      "  - {name: sliding_pin, type: sliding_pin_joint, points: [{body: a}, {body: b}]}\n"
      "  - {name: double_slider, type: double_slider_joint, points: [{body: a}, {body: b}]}\n"
      "  - {name: rigid, type: rigid_joint, points: [{body: a, at: [0.5, 0]}, {body: b, at: [-0.5, 0]}]}\n"
      "simulation: {t_end: 1.0}\n");
  DaeSystem system(model);
  REQUIRE(system.constraint_rows() == 9);
  const bool rotational[9] = {false, false, false, true, false, true, false, false, true};
  const char* owners[9] = {"pin", "pin", "slider", "slider", "sliding_pin", "double_slider", "rigid", "rigid", "rigid"};
  for (int row = 0; row < 9; ++row) {
    INFO("row " << row);
    CHECK(system.constraint_row_is_rotational(row) == rotational[row]);
    CHECK(system.constraint_owner(row).name() == owners[row]);
  }
}
