// Simbody 3.7 counterpart of railcrash's verification model verification/cases/slider_crank.yaml
// (the slider-crank of SUNDIALS' idasSlCrank_dns), for bench/simbody/compare.py.
//
//   simbody_mechanisms slider_crank --accuracy 1e-6 --t-end 10 --output-interval 0.4 --out FILE
//
// Integrates with Simbody's Runge-Kutta-Merson (its default explicit integrator, error control
// at the given accuracy, constraints projected to the same accuracy) or CPodes (--integrator
// cpodes, implicit BDF), writes one CSV row per output time (t, crank angle, rod angle, slider
// position, interpolated within the integrator's steps; formatted with printf like
// railcrash's rows) and prints the steps taken. The
// whole process is what the comparison times: set-up, integration and output.
#include <Simbody.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>

using namespace SimTK;

namespace {

struct Options {
  std::string mechanism;
  std::string integrator = "rkm";  // rkm or cpodes
  double accuracy = 1e-6;          // Simbody's relative accuracy
  double t_end = 10.0;             // [s]
  double output_interval = 0.4;    // [s]
  std::string out = "simbody.csv";
};

[[noreturn]] void usage(const char* why) {
  std::fprintf(stderr,
               "simbody_mechanisms: %s\nusage: simbody_mechanisms slider_crank [--integrator rkm|cpodes] "
               "[--accuracy A] [--t-end T] [--output-interval H] [--out FILE]\n",
               why);
  std::exit(2);
}

Options parse(int argc, char** argv) {
  if (argc < 2) usage("no mechanism");
  Options options;
  options.mechanism = argv[1];
  for (int i = 2; i < argc; i += 2) {
    if (i + 1 >= argc) usage("an option without its value");
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--integrator") options.integrator = value;
    else if (key == "--accuracy") options.accuracy = std::atof(value.c_str());
    else if (key == "--t-end") options.t_end = std::atof(value.c_str());
    else if (key == "--output-interval") options.output_interval = std::atof(value.c_str());
    else if (key == "--out") options.out = value;
    else usage(("unknown option " + key).c_str());
  }
  if (options.mechanism != "slider_crank" && options.mechanism != "andrews_squeezer") usage(("unknown mechanism " + options.mechanism).c_str());
  if (options.integrator != "rkm" && options.integrator != "cpodes") usage("--integrator is rkm or cpodes");
  if (!(options.accuracy > 0.0) || !(options.t_end > 0.0) || !(options.output_interval > 0.0))
    usage("--accuracy, --t-end and --output-interval must be positive");
  return options;
}

/// What a mechanism gives the integration loop: the header and one CSV row of a state.
struct Mechanism {
  std::string header;
  std::function<void(const State&, std::FILE*)> write_row;
};

/// The slider-crank, as in verification/cases/slider_crank.yaml (SI units, no gravity).
Mechanism slider_crank(MultibodySystem& system, SimbodyMatterSubsystem& matter, GeneralForceSubsystem& forces,
                       State& state) {
  const double crank_length = 0.5;   // [m] pivot to crank pin
  const double rod_length = 1.0;     // [m] crank pin to slider (the rod's centre of mass)
  const double crank_inertia = 1.0;  // [kg m^2] about the pivot (centre of mass at the pivot)
  const double rod_mass = 1.0;       // [kg] at the slider
  const double rod_inertia = 2.0;    // [kg m^2] about its centre of mass
  const double spring_stiffness = 1.0, spring_free_length = 1.0;  // [N/m], [m]
  const double damping = 1.0;        // [N s/m]
  const double end_force = 1.0;      // [N] horizontal, one rod length beyond the slider

  // Planar motion about z: the in-plane moments of inertia only have to be valid, not right.
  const Body::Rigid crank_body(MassProperties(1.0, Vec3(0), Inertia(crank_inertia, crank_inertia, crank_inertia)));
  const Body::Rigid rod_body(MassProperties(rod_mass, Vec3(0), Inertia(rod_inertia / 2, rod_inertia / 2, rod_inertia)));
  MobilizedBody::Pin crank(matter.Ground(), Transform(), crank_body, Transform());
  MobilizedBody::Pin rod(crank, Transform(Vec3(crank_length, 0, 0)), rod_body, Transform(Vec3(-rod_length, 0, 0)));
  // The slider: the rod's centre of mass stays on the ground's x axis.
  Constraint::PointInPlane slider(matter.Ground(), UnitVec3(0, 1, 0), 0.0, rod, Vec3(0));
  const Vec3 crank_mid(crank_length / 2, 0, 0), rod_mid(-rod_length / 2, 0, 0);
  Force::TwoPointLinearSpring(forces, crank, crank_mid, rod, rod_mid, spring_stiffness, spring_free_length);
  Force::TwoPointLinearDamper(forces, crank, crank_mid, rod, rod_mid, damping);
  // A force that keeps its direction in the ground frame, applied at a point of the rod.
  Force::ConstantForce(forces, rod, Vec3(rod_length, 0, 0), Vec3(end_force, 0, 0));

  system.realizeTopology();
  state = system.getDefaultState();
  const double crank_angle = Pi / 2, rod_angle = -std::asin(crank_length / rod_length);  // absolute [rad]
  crank.setOneQ(state, 0, crank_angle);
  rod.setOneQ(state, 0, rod_angle - crank_angle);  // the rod's pin is relative to the crank
  return {"t,crank.theta,rod.theta,slider.x", [&system, crank, rod](const State& s, std::FILE* out) {
            system.realize(s, Stage::Position);
            const double crank_theta = crank.getOneQ(s, 0);
            std::fprintf(out, "%.12g,%.12g,%.12g,%.12g\n", s.getTime(), crank_theta, crank_theta + rod.getOneQ(s, 0),
                         rod.getBodyOriginLocation(s)[0]);
          }};
}

/// Andrews' squeezer, as in verification/cases/andrews_squeezer.yaml (Hairer and Wanner's data;
/// body frames at the centres of mass, joint points as offsets along the body's axes).
Mechanism andrews_squeezer(MultibodySystem& system, SimbodyMatterSubsystem& matter, GeneralForceSubsystem& forces,
                           State& state) {
  const double xa = -.06934, ya = -.00227, xb = -.03635, yb = .03273, xc = .014, yc = .072;  // fixed points [m]
  const double d = 28e-3, da = 115e-4, e = 2e-2, ea = 1421e-5, rr = 7e-3, ra = 92e-5;          // [m]
  const double ss = 35e-3, sa = 1874e-5, sb = 1043e-5, sc = 18e-3, sd = 2e-2;                  // [m]
  const double ta = 2308e-5, tb = 916e-5, u = 4e-2, ua = 1228e-5, ub = 449e-5, zf = 2e-2, zt = 4e-2, fa = 1421e-5;
  const double drive_moment = 0.033;                            // [N m] on the crank
  const double spring_stiffness = 4530.0, free_length = 0.07785;  // [N/m], [m]
  const double mass[7] = {.04325, .00365, .02373, .00706, .07050, .00706, .05498};               // [kg]
  const double inertia[7] = {2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5};  // [kg m^2]
  const auto body = [&](int k) {
    return Body::Rigid(MassProperties(mass[k], Vec3(0), Inertia(inertia[k] / 2, inertia[k] / 2, inertia[k])));
  };
  const auto at = [](double x, double y) { return Transform(Vec3(x, y, 0)); };
  MobilizedBody::Pin crank(matter.Ground(), at(0, 0), body(0), at(-ra, 0));
  MobilizedBody::Pin rod(crank, at(rr - ra, 0), body(1), at(da, 0));
  MobilizedBody::Pin lever(matter.Ground(), at(xb, yb), body(2), at(-sb, sa));
  MobilizedBody::Pin rocker5(matter.Ground(), at(xa, ya), body(4), at(-ta, -tb));
  MobilizedBody::Pin link4(rocker5, at(zt - ta, -tb), body(3), at(0, e - ea));
  MobilizedBody::Pin rocker7(matter.Ground(), at(xa, ya), body(6), at(ub, ua));
  MobilizedBody::Pin link6(rocker7, at(ub, -(u - ua)), body(5), at(-(zf - fa), 0));
  // The loop closures at point E (the z rows are redundant; Simbody's projection allows that).
  const Vec3 rod_e(-(d - da), 0, 0);
  Constraint::Ball(rod, rod_e, lever, Vec3(-sb, -(ss - sa), 0));
  Constraint::Ball(rod, rod_e, link4, Vec3(0, -ea, 0));
  Constraint::Ball(rod, rod_e, link6, Vec3(fa, 0, 0));
  Force::TwoPointLinearSpring(forces, lever, Vec3(sd - sb, sa - sc, 0), matter.Ground(), Vec3(xc, yc, 0),
                              spring_stiffness, free_length);
  Force::ConstantTorque(forces, crank, Vec3(0, 0, drive_moment));

  system.realizeTopology();
  state = system.getDefaultState();
  // The test set's consistent angles (beta, Theta, gamma, Phi, delta, Omega, epsilon): each
  // pin's angle is relative to its parent, as the test set's Theta, Phi and Omega are.
  crank.setOneQ(state, 0, -0.0617138900142764496358948458001);
  rod.setOneQ(state, 0, 0.0);
  lever.setOneQ(state, 0, 0.455279819163070380255912382449);
  link4.setOneQ(state, 0, 0.222668390165885884674473185609);
  rocker5.setOneQ(state, 0, 0.487364979543842550225598953530);
  link6.setOneQ(state, 0, -0.222668390165885884674473185609);
  rocker7.setOneQ(state, 0, 1.23054744454982119249735015568);
  return {"t,crank.theta,rod.theta,lever.theta", [&system, crank, rod, lever](const State& s, std::FILE* out) {
            system.realize(s, Stage::Position);
            const double beta = crank.getOneQ(s, 0);
            std::fprintf(out, "%.12g,%.12g,%.12g,%.12g\n", s.getTime(), beta, beta + rod.getOneQ(s, 0), lever.getOneQ(s, 0));
          }};
}

}  // namespace

int main(int argc, char** argv) {
  const Options options = parse(argc, argv);
  MultibodySystem system;
  SimbodyMatterSubsystem matter(system);
  GeneralForceSubsystem forces(system);
  State state;
  const Mechanism mechanism = options.mechanism == "slider_crank" ? slider_crank(system, matter, forces, state)
                                                                   : andrews_squeezer(system, matter, forces, state);

  std::unique_ptr<Integrator> integrator;
  if (options.integrator == "rkm") integrator = std::make_unique<RungeKuttaMersonIntegrator>(system);
  else integrator = std::make_unique<CPodesIntegrator>(system, CPodes::BDF, CPodes::Newton);
  integrator->setAccuracy(options.accuracy);
  // Output rows are interpolated within the integrator's steps (as railcrash's are), not
  // steps forced to end at every output time.
  integrator->setAllowInterpolation(true);
  integrator->setFinalTime(options.t_end);
  integrator->initialize(state);

  std::FILE* out = std::fopen(options.out.c_str(), "w");
  if (!out) {
    std::fprintf(stderr, "simbody_mechanisms: cannot write %s\n", options.out.c_str());
    return 2;
  }
  std::fprintf(out, "%s\n", mechanism.header.c_str());
  mechanism.write_row(integrator->getState(), out);
  const long rows = std::lround(options.t_end / options.output_interval);
  for (long k = 1; k <= rows; ++k) {
    const double t_report = std::min(options.t_end, static_cast<double>(k) * options.output_interval);
    // (The first call only reports the start of the continuous interval, at t = 0.)
    while (integrator->getTime() < t_report) integrator->stepTo(t_report, options.t_end);
    mechanism.write_row(integrator->getState(), out);
  }
  std::fclose(out);
  std::printf("steps %d\n", integrator->getNumStepsTaken());
  return 0;
}
