// Verification cases: each runs a model from verification/cases/ and compares a quantity
// with a reference that comes from outside railcrash (closed-form solution, elliptic
// integral, published SUNDIALS example), within a tolerance stated next to it. Every
// comparison is also written as a Markdown table row to
// <build>/verification/results/<case>.md (collected into verification/README.md).

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "railcrash/model/model_io.hpp"
#include "railcrash/results/run.hpp"
#include "railcrash/solver/dae_system.hpp"
#include "railcrash/studies/readings.hpp"
#include "railcrash/studies/sensitivity.hpp"

using namespace railcrash;

namespace {

const double kPi = std::acos(-1.0);

struct Trajectory {
  RunOutcome outcome;
  std::vector<double> t;
  std::vector<std::vector<double>> y;  // state at each sample
};

class Recorder : public RunObserver {
 public:
  explicit Recorder(Trajectory& trajectory) : trajectory_(trajectory) {}
  void sample(double t, const double* y, const double*, const double*, const double*) override {
    trajectory_.t.push_back(t);
    trajectory_.y.emplace_back(y, y + size);
  }
  int size = 0;

 private:
  Trajectory& trajectory_;
};

std::string case_path(const std::string& name) { return std::string(RAILCRASH_SOURCE_DIR) + "/verification/cases/" + name + ".yaml"; }

/// Runs verification/cases/<name>.yaml with optional KEY=VALUE overrides.
Trajectory simulate(const std::string& name, const std::vector<std::string>& overrides = {}) {
  const LoadedModel loaded = load_model(case_path(name), overrides);
  const SimulationSettings& simulation = loaded.run_spec.simulation;
  DaeSystem system(loaded.model);
  Trajectory trajectory;
  Recorder recorder(trajectory);
  recorder.size = system.size();
  auto integrator = make_integrator(system, simulation);
  trajectory.outcome = integrator->run(simulation.t_end, output_interval_of(simulation), recorder);
  REQUIRE(trajectory.outcome.ok);
  return trajectory;
}

/// One comparison: asserted and written as a table row.
void check(const std::string& case_name, const std::string& quantity, double reference, double result, double tolerance,
           bool relative, const std::string& source) {
  const double error = relative ? std::abs(result - reference) / std::abs(reference) : std::abs(result - reference);
  const std::string dir = std::string(RAILCRASH_BINARY_DIR) + "/results";
  std::filesystem::create_directories(dir);
  std::ofstream out(dir + "/" + case_name + ".md", std::ios::app);
  char row[512];
  std::snprintf(row, sizeof row, "| %s | %s | %.12g | %.12g | %.2e %s | %.0e | %s |\n", case_name.c_str(), quantity.c_str(),
                reference, result, error, relative ? "rel" : "abs", tolerance, source.c_str());
  out << row;
  INFO(case_name << ": " << quantity << " reference " << reference << " result " << result << " error " << error);
  CHECK(error <= tolerance);
}

void start_case(const std::string& case_name) {
  std::filesystem::remove(std::string(RAILCRASH_BINARY_DIR) + "/results/" + case_name + ".md");
}

/// Complete elliptic integral of the first kind K(k) by the arithmetic-geometric mean.
double elliptic_k(double k) {
  double a = 1.0, b = std::sqrt(1.0 - k * k);
  for (int i = 0; i < 60 && std::abs(a - b) > 1e-16 * a; ++i) {
    const double next = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = next;
  }
  return kPi / (2.0 * a);
}

/// Times where coordinate `index` crosses `level` going down, located by cubic Hermite
/// interpolation with its rate (component `rate_index`) between samples.
std::vector<double> downward_crossings(const Trajectory& tr, int index, int rate_index, double level) {
  std::vector<double> times;
  for (std::size_t k = 1; k < tr.t.size(); ++k) {
    const double x0 = tr.y[k - 1][static_cast<std::size_t>(index)] - level;
    const double x1 = tr.y[k][static_cast<std::size_t>(index)] - level;
    if (!(x0 > 0.0 && x1 <= 0.0)) continue;
    const double h = tr.t[k] - tr.t[k - 1];
    const double d0 = tr.y[k - 1][static_cast<std::size_t>(rate_index)] * h;
    const double d1 = tr.y[k][static_cast<std::size_t>(rate_index)] * h;
    const auto hermite = [&](double s) {
      const double s2 = s * s, s3 = s2 * s;
      return (2 * s3 - 3 * s2 + 1) * x0 + (s3 - 2 * s2 + s) * d0 + (-2 * s3 + 3 * s2) * x1 + (s3 - s2) * d1;
    };
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < 80; ++i) {
      const double mid = 0.5 * (lo + hi);
      (hermite(mid) > 0.0 ? lo : hi) = mid;
    }
    times.push_back(tr.t[k - 1] + 0.5 * (lo + hi) * h);
  }
  return times;
}

}  // namespace

TEST_CASE("free flight under gravity follows the exact parabola", "[verification]") {
  start_case("free_flight");
  const double g = 9.81, t = 2.0;
  const double x = 1.0 + 3.0 * t, y = 2.0 + 4.0 * t - 0.5 * g * t * t, theta = 0.3 + 1.5 * t;
  // IDA (BDF) integrates a quadratic exactly up to round-off and the tolerance.
  const Trajectory ida = simulate("free_flight");
  check("free_flight", "ida x(2) [m]", x, ida.y.back()[0], 1e-9, false, "exact: x0 + vx t");
  check("free_flight", "ida y(2) [m]", y, ida.y.back()[1], 1e-9, false, "exact: y0 + vy t - g t^2/2");
  check("free_flight", "ida theta(2) [rad]", theta, ida.y.back()[2], 1e-9, false, "exact: theta0 + omega t");
  // Velocity-first Euler: y_N = y0 + vy T - g T^2/2 - g T dt/2 exactly (sum of g dt^2 k).
  const double dt = 1e-3;
  const Trajectory euler = simulate("free_flight", {"simulation.integrator=euler"});
  check("free_flight", "euler y(2) [m]", y - 0.5 * g * t * dt, euler.y.back()[1], 1e-10, false,
        "exact for Euler-Cromer: parabola - g T dt / 2");
  check("free_flight", "euler x(2) [m]", x, euler.y.back()[0], 1e-10, false, "exact: x0 + vx t");
}

TEST_CASE("undamped and damped spring-mass follow the exact solutions", "[verification]") {
  start_case("spring_mass");
  const double omega = 10.0, amplitude = 0.1, free_length = 1.0;
  const Trajectory undamped = simulate("spring_mass");
  double worst = 0.0;
  for (std::size_t k = 0; k < undamped.t.size(); ++k)
    worst = std::max(worst, std::abs(undamped.y[k][0] - (free_length + amplitude * std::cos(omega * undamped.t[k]))));
  check("spring_mass", "ida max abs(x - exact) over 3 s [m]", 0.0, worst, 1e-6, false, "exact: L0 + A cos(omega t)");

  const double zeta = 4.0 / (2.0 * 2.0 * omega), omega_d = omega * std::sqrt(1.0 - zeta * zeta);
  const auto exact = [&](double t) {
    return free_length + amplitude * std::exp(-zeta * omega * t) *
                             (std::cos(omega_d * t) + zeta * omega / omega_d * std::sin(omega_d * t));
  };
  const Trajectory damped = simulate("damped_spring_mass");
  worst = 0.0;
  for (std::size_t k = 0; k < damped.t.size(); ++k) worst = std::max(worst, std::abs(damped.y[k][0] - exact(damped.t[k])));
  check("spring_mass", "ida damped max abs(x - exact) over 3 s [m]", 0.0, worst, 1e-6, false,
        "exact: A exp(-zeta w t)(cos wd t + zeta w/wd sin wd t)");
  // Energy: all of the initial spring energy k A^2 / 2 goes into the damper or stays.
  const EnergyBalance energy = EnergyBalance::between(damped.outcome.initial_energy, damped.outcome.final_energy);
  check("spring_mass", "ida damped initial energy k A^2/2 [J]", 0.5 * 200.0 * amplitude * amplitude, energy.initial_total, 1e-12,
        true, "exact: k A^2 / 2");
  check("spring_mass", "ida damped energy balance error [J]", 0.0, energy.error(), 1e-6, false,
        "kinetic + elastic + dissipated = initial");

  const Trajectory euler = simulate("spring_mass", {"simulation.integrator=euler", "simulation.dt=1e-5"});
  worst = 0.0;
  for (std::size_t k = 0; k < euler.t.size(); ++k)
    worst = std::max(worst, std::abs(euler.y[k][0] - (free_length + amplitude * std::cos(omega * euler.t[k]))));
  // Euler-Cromer's phase error after time T is about omega^3 T dt^2 / 24 ... plus O(dt) amplitude
  // oscillation of size A omega dt / 2 = 5e-6: tolerance 1e-5.
  check("spring_mass", "euler dt=1e-5 max abs(x - exact) over 3 s [m]", 0.0, worst, 1e-5, false, "exact: L0 + A cos(omega t)");
}

TEST_CASE("large-amplitude pendulum period matches the complete elliptic integral", "[verification]") {
  start_case("pendulum");
  const double g = 9.81, length = 1.0, theta0 = 2.0 * kPi / 3.0;
  const double period = 4.0 * std::sqrt(length / g) * elliptic_k(std::sin(theta0 / 2.0));
  // Point mass (zero inertia) held by the pin: x of the bob crosses 0 going down (left) once per period.
  const Trajectory tr = simulate("pendulum");
  const std::vector<double> crossings = downward_crossings(tr, 0, 3, 0.0);
  REQUIRE(crossings.size() >= 4);
  const double measured = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  check("pendulum", "ida period, 120 deg [s]", period, measured, 1e-7, true, "4 sqrt(L/g) K(sin(theta0/2)), K by AGM");
  check("pendulum", "ida constraint residual max [m]", 0.0, tr.outcome.max_constraint_residual, 1e-8, false, "exact: 0");
  const EnergyBalance energy = EnergyBalance::between(tr.outcome.initial_energy, tr.outcome.final_energy);
  check("pendulum", "ida energy balance error / (m g L) over 10 s", 0.0, energy.error() / (g * length), 1e-6, false,
        "conservative: 0");

  // Physical pendulum (J = 0.1, L = 1): equivalent length (J + m L^2) / (m L) = 1.1 m.
  const double period_physical = 4.0 * std::sqrt(1.1 / g) * elliptic_k(std::sin(kPi / 4.0));
  const Trajectory physical = simulate("physical_pendulum", {"simulation.integrator=ida", "simulation.t_end=6",
                                                             "simulation.output_interval=0.002"});
  // The body angle goes from 0 down to -pi and back: it crosses -pi/2 going down once per period.
  const std::vector<double> downs = downward_crossings(physical, 2, 5, -kPi / 2.0);
  REQUIRE(downs.size() >= 2);
  check("pendulum", "ida physical pendulum period, 90 deg [s]", period_physical,
        (downs.back() - downs.front()) / static_cast<double>(downs.size() - 1), 1e-7, true,
        "4 sqrt(L_eq/g) K(sin 45deg), L_eq = (J + m L^2)/(m L)");
}

TEST_CASE("double pendulum conserves energy and keeps its joints closed over 10 s", "[verification]") {
  start_case("double_pendulum");
  const Trajectory tr = simulate("double_pendulum");
  const EnergyBalance energy = EnergyBalance::between(tr.outcome.initial_energy, tr.outcome.final_energy);
  const double scale = 2.0 * 9.81 * 1.0;  // m g L: the potential energy released in a swing
  check("double_pendulum", "ida energy balance error / (2 m g L) at t = 10 s", 0.0, energy.error() / scale, 1e-5, false,
        "conservative: 0");
  check("double_pendulum", "ida constraint residual max over 10 s [m]", 0.0, tr.outcome.max_constraint_residual, 1e-8, false,
        "exact: 0");
  // Euler: the penalty joints' damping and the first-order scheme leak energy in proportion to dt.
  std::vector<double> euler_errors;
  for (const char* dt : {"1e-4", "5e-5"}) {
    const Trajectory euler =
        simulate("double_pendulum", {"simulation.integrator=euler", "simulation.t_end=2", std::string("simulation.dt=") + dt});
    const EnergyBalance e = EnergyBalance::between(euler.outcome.initial_energy, euler.outcome.final_energy);
    euler_errors.push_back(std::abs(e.error()) / scale);
  }
  check("double_pendulum", "euler dt=1e-4 abs(energy balance error) / (2 m g L) at t = 2 s", 0.0, euler_errors[0], 5e-3, false,
        "conservative: 0");
  check("double_pendulum", "euler energy error order in dt (1e-4 -> 5e-5)", 1.0, std::log2(euler_errors[0] / euler_errors[1]),
        0.1, false, "first-order method");
}

TEST_CASE("SUNDIALS slider-crank: kinetic energy integral and final state", "[verification]") {
  start_case("slider_crank");
  // Tight-tolerance reference (issue 2): integral_0^10 KE dt = 3.33660679948280; at t = 10
  // crank angle 1.275675848650, slider x 1.023578558980, rod angle -0.498813049182.
  const double ke_reference = 3.33660679948280;
  const Trajectory tight = simulate("slider_crank", {"simulation.rtol=1e-11", "simulation.atol=1e-12"});
  check("slider_crank", "rtol 1e-11: integral KE dt", ke_reference, tight.outcome.quadratures[DaeSystem::kKineticIntegral], 1e-7,
        true, "independent tight integration");
  check("slider_crank", "rtol 1e-11: crank angle at t=10 [rad]", 1.275675848650, tight.y.back()[2], 1e-7, false,
        "independent tight integration");
  check("slider_crank", "rtol 1e-11: slider x at t=10 [m]", 1.023578558980, tight.y.back()[3], 1e-7, false,
        "independent tight integration");
  check("slider_crank", "rtol 1e-11: rod angle at t=10 [rad]", -0.498813049182, tight.y.back()[5], 1e-7, false,
        "independent tight integration");
  // The example itself prints 3.3366160662934146 at rtol 1e-6 / atol 1e-7: 2.8e-6 relative
  // error. At the same tolerances railcrash must be at least as close.
  const double example_error = std::abs(3.3366160662934146 - ke_reference) / ke_reference;
  const Trajectory loose = simulate("slider_crank");
  check("slider_crank", "rtol 1e-6: integral KE dt (tolerance = the example's own error)", ke_reference,
        loose.outcome.quadratures[DaeSystem::kKineticIntegral], example_error, true,
        "idasSlCrank_dns prints 3.3366160662934146");
}

TEST_CASE("Andrews' squeezer: the seven angles at t = 0.03 s against the test set's solution", "[verification]") {
  start_case("andrews_squeezer");
  // Hairer and Wanner's seven-body mechanism (the Bari test set's "andrews"); its reference
  // solution at t = 0.03 s: beta, Theta, gamma, Phi, delta, Omega, epsilon (Theta, Phi and
  // Omega relative to the body they hang on). railcrash's state holds absolute angles.
  const double reference[7] = {0.1581077119629904e+2, -0.1575637105984298e+2, 0.4082224013073101e-1,
                               -0.5347301163226948e+0, 0.5244099658805304e+0, 0.5347301163226948e+0,
                               0.1048080741042263e+1};
  const char* names[7] = {"beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon"};
  const auto angles = [](const std::vector<double>& y) {
    const auto theta = [&](int body) { return y[static_cast<std::size_t>(3 * body + 2)]; };
    // bodies: crank, rod, lever, link4, rocker5, link6, rocker7
    return std::array<double, 7>{theta(0), theta(1) - theta(0), theta(2), theta(3) - theta(4),
                                 theta(4), theta(5) - theta(6), theta(6)};
  };
  const Trajectory tight = simulate("andrews_squeezer", {"simulation.rtol=1e-10", "simulation.atol=1e-13"});
  REQUIRE(tight.t.back() == Approx(0.03));
  const std::array<double, 7> at_end = angles(tight.y.back());
  for (int k = 0; k < 7; ++k)
    check("andrews_squeezer", std::string("rtol 1e-10: ") + names[k] + " at t=0.03 [rad]", reference[k], at_end[k], 1e-7,
          false, "test set reference solution (Hairer, Wanner)");
  // The model's own tolerances (rtol 1e-6): the crank's 2.5 turns within 2e-4 rad, 1.3e-5 of the
  // angle (measured 1.54e-4 since each body's angle is held over its own size (91feeab, issue 14:
  // the crank's 7 mm, not the model's length); below 1e-4 before).
  const Trajectory own = simulate("andrews_squeezer");
  check("andrews_squeezer", "rtol 1e-6: beta at t=0.03 [rad]", reference[0], angles(own.y.back())[0], 2e-4, false,
        "test set reference solution (Hairer, Wanner)");
}

TEST_CASE("explicit Euler converges at first order and IDA error follows the tolerance", "[verification]") {
  start_case("convergence");
  // Reference: the physical pendulum's state at t = 2 s from IDA at rtol 1e-12.
  const Trajectory reference = simulate("physical_pendulum", {"simulation.integrator=ida", "simulation.rtol=1e-12"});
  const double x_ref = reference.y.back()[0];
  std::vector<double> errors;
  for (const char* dt : {"2e-5", "1e-5", "5e-6", "2.5e-6"}) {
    const Trajectory euler = simulate("physical_pendulum", {std::string("simulation.dt=") + dt});
    errors.push_back(std::abs(euler.y.back()[0] - x_ref));
  }
  for (std::size_t k = 1; k < errors.size(); ++k) {
    const double order = std::log2(errors[k - 1] / errors[k]);
    check("convergence", "euler observed order, dt halving " + std::to_string(k) + " (x(2) error " +
                             std::to_string(errors[k - 1]) + " -> " + std::to_string(errors[k]) + ")",
          1.0, order, 0.1, false, "first-order method");
  }
  std::vector<double> ida_errors;
  for (const char* rtol : {"1e-5", "1e-7", "1e-9"}) {
    const Trajectory ida = simulate("physical_pendulum", {"simulation.integrator=ida", std::string("simulation.rtol=") + rtol});
    ida_errors.push_back(std::abs(ida.y.back()[0] - x_ref));
  }
  for (std::size_t k = 1; k < ida_errors.size(); ++k) {
    // Each 100-fold tightening must cut the error at least 10-fold.
    check("convergence", "ida error ratio for rtol / 100 (step " + std::to_string(k) + ")", 0.0,
          ida_errors[k] / ida_errors[k - 1], 0.1, false, "error follows the tolerance");
  }
}

TEST_CASE("crush spring impact: contact time, crush, permanent set, rebound and absorbed energy", "[verification]") {
  start_case("crush_impact");
  for (const char* integrator : {"ida", "euler"}) {
    const std::string name = integrator;
    const bool ida = name == "ida";
    const Trajectory tr = simulate("crush_impact", {std::string("simulation.integrator=") + integrator});
    const auto& events = tr.outcome.events;
    REQUIRE(events.size() == 4);
    check("crush_impact", name + " contact time [s]", 0.05, events[0].t, ida ? 1e-10 : 2e-6, false, "gap / speed");
    check("crush_impact", name + " maximum crush [m]", 0.055, events[2].value, ida ? 1e-8 : 1e-5, false,
          "energy: (m v^2/2 - F0 dy/2) / F0 + dy");
    check("crush_impact", name + " permanent crush [m]", 0.045, events[3].value,
          ida ? 1e-8 : 1e-4, false, "maximum crush - F0 / k (crush at separation)");
    check("crush_impact", name + " rebound speed [m/s]", std::sqrt(10.0), tr.y.back()[3], ida ? 1e-7 : 1e-3, true,
          "elastic energy F0 dy / 2 returned");
    const EnergyBalance e = EnergyBalance::between(tr.outcome.initial_energy, tr.outcome.final_energy);
    check("crush_impact", name + " energy absorbed by crushing [J]", 4500.0, e.dissipated, ida ? 1e-7 : 1e-3, true,
          "m v^2/2 - m v_r^2/2");
  }
}

TEST_CASE("report sensitivity: crush falls as the anticlimber horizontal yield force and plastic slope rise",
          "[verification]") {
  // Report Table 15 (first-order, R1): P7 -0.225 and P6 -0.180, the two most important
  // crush parameters, and Table 14 (second order) for the same two. The side-by-side of all
  // parameters is verification/report_comparison.md; this case holds the signs the report's
  // conclusions rest on.
  start_case("report_sensitivity");
  const std::string models = std::string(RAILCRASH_SOURCE_DIR) + "/models/report/";
  const SensitivityDesign design = load_design(models + "sensitivity_design.yaml");
  SensitivityOptions options;
  options.jobs = 2;
  options.only = {"P6", "P7"};
  // With P6 and P7 only, the design's second-order runs 32-34 (P6 = 0.8, P7 = 0.8, both 1.2) are
  // kept and the form 1, P6, P7, P6^2, P6*P7, P7^2 is solved from 6 runs.
  const SensitivityResult result = run_sensitivity(models + "final_two_car.yaml", design, options);
  REQUIRE(result.base.ok);
  REQUIRE(result.derivatives.size() == 2);
  const double report_r1[2] = {-0.180, -0.225};  // Table 15: P6, P7
  for (std::size_t i = 0; i < 2; ++i) {
    const std::string name = result.runs[i].parameter;
    REQUIRE(result.runs[i].ok);
    const double derivative = result.derivatives[i][0];
    // Sign agreement is the requirement: the check passes when our derivative has the report's sign.
    check("report_sensitivity", "dR1/d" + name + " sign (ours " + std::to_string(derivative) + ", report " +
                                    std::to_string(report_r1[i]) + ")",
          -1.0, derivative < 0.0 ? -1.0 : 1.0, 0.0, false, "report Table 15");
  }
  // Second order (report Table 14): dR1/dP6 -0.207, dR1/dP7 -0.235, d2R1/dP6dP7 +0.175 at P = 1.
  REQUIRE(result.second_order_runs.size() == 3);
  REQUIRE(result.fit.determined());
  const double report_table14[3] = {-0.207, -0.235, 0.175};
  const char* const labels[3] = {"d/dP6", "d/dP7", "d2/dP6dP7"};
  for (std::size_t k = 0; k < 3; ++k) {
    const auto it = std::find_if(result.fit.derivatives.begin(), result.fit.derivatives.end(),
                                 [&](const SensitivityDerivative& d) { return d.label() == labels[k]; });
    REQUIRE(it != result.fit.derivatives.end());
    const double value = it->value[0];
    const double sign = report_table14[k] < 0.0 ? -1.0 : 1.0;
    check("report_sensitivity", std::string(labels[k]) + " R1 sign, second-order form (ours " + std::to_string(value) +
                                    ", report " + std::to_string(report_table14[k]) + ")",
          sign, value < 0.0 ? -1.0 : 1.0, 0.0, false, "report Table 14");
  }
}

namespace {

// What the shipped report model reached against the report's study (verification/
// report_comparison.md, from `railcrash sensitivity models/report/final_two_car.yaml`), as the
// distance from perfect agreement that the case below allows. R1's run 0 is calibrated.
constexpr double kReachedR1Error = 0.005;                 // rel (ours 1.2535)
// R2 and R3 from the largest vertical anticlimber force over every step and event (it was
// over the 1 ms rows, 0.661 and 1.914, before commit 5ec9569). Since issue 40 the anticlimber's
// misalignment is geometric (misalignment_geometry: face; the struck car's face 1 in above its
// point): run 0's R2 0.6699 -> 0.6537, R3 1.9234 -> 1.9072, R2 signs 9 -> 10 of 13, R2 rho
// 0.337 -> 0.433, R1 rho 0.19 -> 0.21, R2 top five 3 -> 4, goals 3 -> 4 (verification/
// report_comparison.md, "P9 and R2 after override").
constexpr double kReachedR2Error = 0.075;                 // rel (ours 0.6537: +7.16 %)
constexpr double kReachedR3Error = 0.025;                 // rel (ours 1.9072: +2.26 %)
// R2's changes below about 0.02 are within its numerical noise at the model's rtol 1e-5
// (run 9's R2 change is +0.0024 against the report's -0.009: noise; verification/
// report_comparison.md).
constexpr double kReachedSignShortfall[2] = {0.34, 0.24};  // 1 - share kept (R1 4 of 6, R2 10 of 13)
constexpr double kReachedRhoShortfall[2] = {0.82, 0.60};   // 1 - rho (R1 0.207, R2 0.433), less 0.03
constexpr double kReachedTopFiveMissing[2] = {1.0, 1.0};   // R1 4 of 5, R2 4 of 5
constexpr double kReachedGoals = 4.0;                      // R2 10 %, R3 5 %, R1 top five, R2 top five                      // R2 10 %, R3 5 %, R1 top five

}  // namespace

TEST_CASE("report reproduction: the shipped readings' whole study against Tables 11, 13 and 15-17", "[verification]") {
  // The report's final two-car model as shipped (printed values, the readings chosen by the
  // reading study: models/report/README.md) runs the report's whole 40-run study, scored as
  // `railcrash readings` scores it (include/railcrash/studies/readings.hpp). Each row compares with
  // perfect agreement (the report's own value, every sign, rho 1, all five of the top five);
  // the tolerance is what this build reached (verification/report_comparison.md), so a change
  // that loses agreement fails here, and one that gains it passes.
  start_case("report_reproduction");
  const std::string models = std::string(RAILCRASH_SOURCE_DIR) + "/models/report/";
  const SensitivityDesign design = load_design(models + "sensitivity_design.yaml");
  REQUIRE(design.reference.has_value());
  SensitivityOptions options;
  options.jobs = 2;
  const SensitivityResult result = run_sensitivity(models + "final_two_car.yaml", design, options);
  REQUIRE(result.base.ok);
  for (const SensitivityRun& run : result.runs) REQUIRE(run.ok);
  for (const SensitivityRun& run : result.second_order_runs) REQUIRE(run.ok);
  const Agreement agreement = score_agreement(result, design);
  const auto& r = agreement.responses;
  const std::string table11 = "report Table 11, run 0";
  check("report_reproduction", "R1 run 0 (reference crush calibrated to it)", 1.255, r[0].value, kReachedR1Error, true, table11);
  check("report_reproduction", "R2 run 0", 0.610, r[1].value, kReachedR2Error, true, table11);
  check("report_reproduction", "R3 run 0", 1.865, r[2].value, kReachedR3Error, true, table11);
  for (int k = 0; k < 2; ++k) {
    const ResponseAgreement& a = r[static_cast<std::size_t>(k)];
    const std::string name = "R" + std::to_string(k + 1);
    check("report_reproduction",
          name + " first-order changes with the report's sign (" + std::to_string(a.sign_agreements) + " of " +
              std::to_string(a.significant_runs) + " runs whose change is >= 0.005)",
          1.0, a.sign_share(), kReachedSignShortfall[k], false, "report Table 11");
    check("report_reproduction", name + " Spearman rho of the first-order changes", 1.0, a.spearman, kReachedRhoShortfall[k],
          false, "report Table 11");
    check("report_reproduction", name + " of the report's top five in ours", 5.0, a.top_five_shared, kReachedTopFiveMissing[k],
          false, k == 0 ? "report Table 15" : "report Table 16");
  }
  check("report_reproduction", "goals of issue 10 met (of 8)", 8.0, agreement.goals_met, 8.0 - kReachedGoals, false,
        "R2 10 %, R3 5 %, signs 80 %, rho 0.7, top five 4, for R1 and R2");
}
