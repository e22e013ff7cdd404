// Degenerate scenes for robustness tests (issue 8): places and faults where scan matching is
// poorly constrained or the data stream misbehaves, each with exact ground truth.
//
//   tunnel      a long straight tunnel (smooth walls, two emergency bays) between city streets
//   open-field  flat open ground with a handful of far objects (barns, trees)
//   stationary  the car stops and stands still (60 s by default) while traffic moves around it
//   gap         a city drive with 10 frames (1 s) missing: stamps jump, the car keeps moving
//   half-beams  a city drive whose scans lose every other beam, then the upper half of them
//   patrol      a closed loop around one block driven with a periodic speed profile, so that
//               frame `lap_frames` has exactly frame 0's pose: laps can be replayed forever
//
//   Scenario sc = make_degenerate_scenario("tunnel", seed, /*frames=*/0);  // 0: natural length
//   // sc.degenerate_first_frame .. sc.degenerate_end_frame: the hard part
//
// `scfloam simulate --scenario NAME` writes them like any other route.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "scfloam/sim/scenario.hpp"
#include "scfloam/types.hpp"

namespace scfloam::sim {

std::vector<std::string> degenerate_scenario_names();

// frames = 0: the scene's natural length (tunnel 300 m, stationary 60 s standing, ...);
// otherwise the scene is laid out to fit (see docs/degenerate.md). Error for unknown names.
Scenario make_degenerate_scenario(const std::string& name, std::uint64_t seed, std::size_t frames,
                                  double mount_height_m = 1.73);

// The patrol lap: frames per lap (pose of frame k + lap_frames == pose of frame k).
std::size_t patrol_lap_frames(std::uint64_t seed);

// Drives a dense 2D lane (closed: it wraps around) along arclengths s(t) given every dt_s
// (s_m[k] at t = k dt_s, non-decreasing): speed and acceleration come from s, heading and
// yaw rate from the lane, roll and pitch from the terrain plus squat/dive and body roll.
// A car whose s stands still stands still exactly.
SampledTrajectory drive_arclength(const std::vector<Eigen::Vector2d>& lane, bool closed,
                                  const std::vector<double>& s_m, double dt_s,
                                  const std::function<double(double, double)>& ground_height,
                                  double mount_height_m);

// s(t) every dt_s for t in [0, duration_s] by integrating speed_mps(t) (midpoint rule).
std::vector<double> integrate_speed(const std::function<double(double)>& speed_mps,
                                    double duration_s, double dt_s);

// A smooth speed change from v0 at t0 to v1 at t1 (half a cosine: continuous acceleration
// at neither end, peak |v1 - v0| * pi / (2 (t1 - t0))).
double ease(double t, double t0, double t1, double v0, double v1);

// Removes the scenario's missing rings of `frame` from a scan rendered with `beams` beams
// (its points carry their ring).
void apply_beam_losses(const Scenario& scenario, std::size_t frame, int beams, Scan* scan);

}  // namespace scfloam::sim
