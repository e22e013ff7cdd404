// Moving objects: cars and pedestrians whose positions are functions of time, laid out
// along the ego car's own path so that every route (grid city, avenue, KITTI replay) gets
// traffic: oncoming cars in the opposite lane, a car leading and one following the ego car
// in its lane at a similar speed (the hard case for scan matching), and pedestrians
// walking on the sidewalks. Deterministic from the seed; the ground truth stays the ego's.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "scfloam/sim/route.hpp"
#include "scfloam/sim/world.hpp"

namespace scfloam::sim {

struct TrafficConfig {
  bool enabled = true;
  double oncoming_per_minute = 20;  // cars passing the ego car in the opposite lane
  double leader_fraction = 0.6;     // share of the time a car drives ahead in the ego lane
  double follower_fraction = 0.6;   // share of the time a car drives behind in the ego lane
  double pedestrians_per_minute = 8;
};

// A 2D path with cumulative arclength; pose(s) interpolates linearly.
struct ArcPath {
  std::vector<Eigen::Vector2d> points;
  std::vector<double> s_m;  // cumulative arclength, s_m[0] = 0
  double length() const { return s_m.empty() ? 0 : s_m.back(); }
  // Position and unit heading at arclength s (clamped to the path).
  void at(double s, Eigen::Vector2d* position, Eigen::Vector2d* heading) const;
};

struct Mover {
  enum class Kind : std::uint8_t { oncoming, leader, follower, pedestrian };
  Kind kind = Kind::oncoming;
  double t_on_s = 0, t_off_s = 0;  // present in [t_on, t_off]
  // oncoming / pedestrian: s(t) = s0 + v (t - t0) on the path offset by lateral_m (right +).
  // leader / follower: s(t) = s_ego(t) + gap(t), gap ramps from/to +-ramp_far_m at the ends.
  double s0_m = 0, t0_s = 0, speed_mps = 0, lateral_m = 0;
  double gap_m = 0, wobble_m = 0, wobble_rad_s = 0, wobble_phase = 0;
  // Shape: a body box and (cars) a cabin box, half extents and heights above the ground.
  double half_len_m = 2.2, half_width_m = 0.9, body_bottom_m = 0.3, body_top_m = 1.0;
  double cabin_half_len_m = 1.2, cabin_half_width_m = 0.8, cabin_top_m = 1.5;
  float reflectance = 0.4f;
};

class Traffic {
 public:
  // Plans movers along the ego trajectory; `world` gives the ground height and the sidewalks.
  Traffic(const SampledTrajectory& ego, const World& world, const TrafficConfig& config,
          std::uint64_t seed);
  Traffic() = default;

  const std::vector<Mover>& movers() const { return movers_; }
  // Ego arclength along its path at time t.
  double ego_arclength(double t_s) const;
  // Footprint center, heading and ground height of mover m at time t; false if absent.
  bool state(const Mover& m, double t_s, Eigen::Vector2d* center, Eigen::Vector2d* heading) const;
  // Appends the primitives of every mover present at t within radius_m of `near`.
  void primitives_at(double t_s, const Eigen::Vector2d& near, double radius_m,
                     std::vector<Primitive>* out) const;
  // Number of movers present at t whose center lies within radius_m of `near`.
  std::size_t count_near(double t_s, const Eigen::Vector2d& near, double radius_m) const;

 private:
  ArcPath ego_path_;             // the ego lane
  std::vector<double> ego_s_;    // ego arclength per trajectory sample
  double dt_s_ = 0.01;
  const World* world_ = nullptr;
  std::vector<Mover> movers_;
};

}  // namespace scfloam::sim
