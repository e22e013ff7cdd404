// The patrol lap: a closed loop around one city block, driven with a speed profile that is
// periodic in the lap, so frame k + lap_frames has frame k's pose: a long-run benchmark can
// replay one simulated lap for hours (bench/long_run.sh).
#include <cmath>

#include "scfloam/error.hpp"
#include "scfloam/sim/degenerate.hpp"
#include "scfloam/sim/rng.hpp"

namespace scfloam::sim {
using Vec2 = Eigen::Vector2d;

namespace {
constexpr double kHalfX = 120, kHalfY = 70, kCornerRadius = 25;  // street centerline
constexpr double kLaneOffset = 1.6;  // right lane; driving counter-clockwise it is outside
constexpr double kMeanSpeed = 7.0, kSpeedWave = 1.0;  // m/s; <= 2.4 m/s^2 in the corners
constexpr int kSpeedWavesPerLap = 3;

// Counter-clockwise rounded rectangle, a point every ~step_m, closed (last != first).
std::vector<Vec2> rounded_rectangle(double hx, double hy, double radius, double step_m) {
  std::vector<Vec2> out;
  const Vec2 corners[4] = {{hx - radius, hy - radius}, {-(hx - radius), hy - radius},
                           {-(hx - radius), -(hy - radius)}, {hx - radius, -(hy - radius)}};
  for (int c = 0; c < 4; ++c) {
    const double a0 = c * M_PI / 2;
    const int arc_steps = std::max(4, static_cast<int>(radius * M_PI / 2 / step_m));
    for (int i = 0; i < arc_steps; ++i) {
      const double a = a0 + (M_PI / 2) * i / arc_steps;
      out.push_back(corners[c] + radius * Vec2(std::cos(a), std::sin(a)));
    }
    const Vec2 from = corners[c] + radius * Vec2(std::cos(a0 + M_PI / 2), std::sin(a0 + M_PI / 2));
    const Vec2 to = corners[(c + 1) % 4] + radius * Vec2(std::cos(a0 + M_PI / 2), std::sin(a0 + M_PI / 2));
    const int line_steps = std::max(1, static_cast<int>((to - from).norm() / step_m));
    for (int i = 0; i < line_steps; ++i) out.push_back(from + (to - from) * (double(i) / line_steps));
  }
  return out;
}

// Cyclic gaussian smoothing: the curvature ramps into the corners (smooth yaw rate).
std::vector<Vec2> smooth_closed(const std::vector<Vec2>& pts, int sigma_samples) {
  const int n = static_cast<int>(pts.size()), half = 3 * sigma_samples;
  std::vector<Vec2> out(n);
  for (int i = 0; i < n; ++i) {
    Vec2 acc = Vec2::Zero();
    double wsum = 0;
    for (int k = -half; k <= half; ++k) {
      const double w = std::exp(-0.5 * double(k) * k / (double(sigma_samples) * sigma_samples));
      acc += w * pts[((i + k) % n + n) % n];
      wsum += w;
    }
    out[i] = acc / wsum;
  }
  return out;
}

std::vector<Vec2> patrol_lane() {
  return smooth_closed(rounded_rectangle(kHalfX + kLaneOffset, kHalfY + kLaneOffset, kCornerRadius + kLaneOffset, 0.5), 12);
}

double closed_length(const std::vector<Vec2>& p) {
  double L = (p.front() - p.back()).norm();
  for (std::size_t i = 1; i < p.size(); ++i) L += (p[i] - p[i - 1]).norm();
  return L;
}
}  // namespace

std::size_t patrol_lap_frames(std::uint64_t /*seed: the loop's shape is fixed*/) {
  return static_cast<std::size_t>(std::lround(closed_length(patrol_lane()) / (kMeanSpeed * 0.1)));
}

Scenario make_patrol_scenario(std::uint64_t seed, std::size_t frames, double mount_height_m) {
  const std::size_t lap = patrol_lap_frames(seed);
  if (frames == 0) frames = lap;
  Rng rng(hash_combine(seed, 0xBA7201ULL));
  std::vector<Street> streets;
  Street block;
  block.centerline = rounded_rectangle(kHalfX, kHalfY, kCornerRadius, 2.0);
  block.centerline.push_back(block.centerline.front());
  block.half_width_m = 6.5;
  block.sidewalk_m = 3.0;
  block.tree_lined = rng.chance(0.5);
  block.parking = true;
  streets.push_back(block);
  // Side streets leaving the block outward from its long and short sides.
  for (const double u : {-0.45, 0.1, 0.45})
    for (const double side : {-1.0, 1.0}) {
      Street st;
      const Vec2 a(u * kHalfX * 1.6, side * kHalfY), b = a + Vec2(0, side * rng.uniform(80, 140));
      st.centerline = {a, b};
      st.half_width_m = rng.uniform(5.5, 7);
      st.parking = rng.chance(0.7);
      streets.push_back(st);
    }
  for (const double side : {-1.0, 1.0}) {
    Street st;
    const Vec2 a(side * kHalfX, 0), b = a + Vec2(side * rng.uniform(80, 140), 0);
    st.centerline = {a, b};
    st.half_width_m = rng.uniform(5.5, 7);
    streets.push_back(st);
  }
  Scenario sc;
  sc.world = build_city(streets, make_rolling_terrain(bounds_of(streets, 80), seed, 0.02), seed, &sc.stats);

  // s(t) = v0 t + A/w (cos(phi) - cos(w t + phi)), w = 2 pi * waves / T_lap: exactly one lap
  // length L every T_lap, so the lap repeats.
  const std::vector<Vec2> lane = patrol_lane();
  const double L = closed_length(lane), T_lap = lap * 0.1;
  const double v0 = L / T_lap, w = 2 * M_PI * kSpeedWavesPerLap / T_lap, phase = rng.uniform(0, 2 * M_PI);
  const double dt = 0.01;
  std::vector<double> s(static_cast<std::size_t>(std::ceil((frames + 1) * 0.1 / dt)) + 1);
  for (std::size_t k = 0; k < s.size(); ++k) {
    const double t = k * dt;
    s[k] = v0 * t + kSpeedWave / w * (std::cos(phase) - std::cos(w * t + phase));
  }
  const World& world = sc.world;
  sc.trajectory = drive_arclength(lane, true, s, dt, [&world](double x, double y) { return world.terrain_m.sample(x, y); },
                                  mount_height_m);
  sc.frames = frames;
  sc.route_length_m = 0;
  for (std::size_t k = 1; k < sc.frames; ++k)
    sc.route_length_m += (sc.frame_pose(k).translation() - sc.frame_pose(k - 1).translation()).norm();
  sc.description = "patrol: counter-clockwise laps of a " + std::to_string(static_cast<int>(2 * kHalfX)) + " x " +
                   std::to_string(static_cast<int>(2 * kHalfY)) + " m block, " + std::to_string(lap) +
                   " frames (" + std::to_string(static_cast<int>(L)) + " m) per lap";
  return sc;
}

}  // namespace scfloam::sim
