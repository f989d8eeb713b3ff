// Consists built from a two-car crash model: the scaling benchmark's trains.
//
// The template is a model of one striking car and one standing car whose bodies and
// elements are named `car1_*` (striking) and `car2_*` (standing), joined by interface
// elements with other names (the report's final two-car model: coupler faces and
// anticlimber). make_consist_model writes a model of N striking cars coupled behind each
// other, moving at the striking car's velocity, and N standing cars coupled behind the
// struck car:
//   striking car k (k = 1..N): the car1_* bodies and elements renamed s<k>_*, shifted by
//                              -(k-1) L in x, its bodies declaring `car: s<k>`;
//   standing car k:            the car2_* ones renamed t<k>_*, shifted by +(k-1) L, `car: t<k>`;
//   interface elements:        once, between s1 and t1 (car1_ -> s1_, car2_ -> t1_);
//   couplings:                 s<k>_coupling joins car k's coupler face (the template's
//                              coupler_faces point on its coupler) to car k-1's rear body, at
//                              the car's rear face: a coupler_end with coupled: true, no slack,
//                              faces touching (gap 0) at the start, the template's
//                              coupler_faces stiffness, free lengths and heights.
// A model with car types and trains (README "Car types and trains") is a template too: each of
// its trains is made N cars long, its listed cars repeated in turn, and every other key kept.
// L, the length over the coupler faces, follows from the template: the coupler faces meet
// at x = 0 (the interface coupler_end's two points lie free_length behind their faces), and
// the rear face is the front face mirrored about the centre body's centre of gravity,
// L = 2 |x_centre body|. The rear faces' height is the front coupler's. A car's rear end
// carries no draft gear of its own: the front coupler's draft gear, slider and leveler act
// for the coupling (a simplification of the benchmark trains, not a vehicle model).
#pragma once

#include <string>

namespace YAML {
class Node;
}

namespace railcrash {

/// Peak memory per car of writing a consist, and about the same of loading and running it
/// [bytes/car]: `/usr/bin/time -f %M railcrash consist models/report/final_two_car.yaml --cars N`
/// gave 23.8 MB at N = 10 and 86.4 MB at N = 50, 0.78 MB per car of the 2N (the largest shipped
/// template; `run` of the N = 50 model for 2 ms: 76.9 MB).
constexpr double kConsistBytesPerCar = 0.8e6;

/// The memory the system can still give [bytes]: MemAvailable of /proc/meminfo (infinity if unknown).
double available_memory_bytes();

/// Throws InputError when 2N cars at kConsistBytesPerCar would need more than `available_bytes`,
/// saying how much they would need.
void check_consist_memory(const std::string& template_path, int cars_per_consist, double available_bytes);

/// YAML text of the 2N-car model (N >= 1) built from a two-car template file (its size
/// checked first against the available memory). Throws InputError naming the template and
/// what is missing when it is not of the expected shape.
std::string make_consist_model(const std::string& template_path, int cars_per_consist);
/// Same, from a template already read (`template_path` names it in messages and comments).
std::string make_consist_model(const YAML::Node& root, const std::string& template_path, int cars_per_consist);

}  // namespace railcrash
