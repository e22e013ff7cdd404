// Sensor geometry: beam tables of the presets, range limits, and ranges to a known wall.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>

#include "scfloam/error.hpp"
#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/sensor.hpp"
#include "scfloam/sim/simulate.hpp"
#include "scfloam/sim/world.hpp"

namespace scfloam::sim {
namespace {

World flat_world(double half_size_m) {
  World w;
  w.terrain_m.reset(-half_size_m, -half_size_m, 4.0, static_cast<int>(half_size_m / 2) + 1,
                    static_cast<int>(half_size_m / 2) + 1, 0.0f);
  w.road_edge_distance.reset(-half_size_m, -half_size_m, 4.0, static_cast<int>(half_size_m / 2) + 1,
                             static_cast<int>(half_size_m / 2) + 1, -10.0f);  // all road
  return w;
}

BeamCalibration perfect(const SensorModel& s) {
  BeamCalibration c;
  c.elevation_offset_rad.assign(s.beams(), 0);
  c.azimuth_offset_rad.assign(s.beams(), 0);
  c.range_bias_m.assign(s.beams(), 0);
  return c;
}

SweepPoses sensor_at_height(double h) {
  SweepPoses p;
  p.T_world_lidar = Pose::Identity();
  p.T_world_lidar.translation().z() = h;
  return p;
}

TEST(SensorPresets, Hdl64HasTwoBlocksFromPlus2ToMinus24_9) {
  const SensorModel s = sensor_preset("hdl64");
  ASSERT_EQ(s.beams(), 64);
  EXPECT_DOUBLE_EQ(s.elevations_deg.front(), 2.0);
  EXPECT_NEAR(s.elevations_deg.back(), -24.9, 1e-9);
  EXPECT_NEAR(s.elevations_deg[31], -8.333, 1e-3);
  for (int i = 1; i < 32; ++i) EXPECT_NEAR(s.elevations_deg[i - 1] - s.elevations_deg[i], 1.0 / 3.0, 1e-9);
  for (int i = 33; i < 64; ++i) EXPECT_NEAR(s.elevations_deg[i - 1] - s.elevations_deg[i], 0.517, 0.01);
  EXPECT_NEAR(s.azimuth_step_deg(), 0.1728, 1e-3);
  EXPECT_DOUBLE_EQ(s.max_range_m, 120);
  EXPECT_DOUBLE_EQ(s.mount_height_m, 1.73);
}

TEST(SensorPresets, OtherLayouts) {
  const SensorModel vlp = sensor_preset("vlp16");
  ASSERT_EQ(vlp.beams(), 16);
  EXPECT_DOUBLE_EQ(vlp.elevations_deg.front(), 15);
  EXPECT_DOUBLE_EQ(vlp.elevations_deg.back(), -15);
  EXPECT_NEAR(vlp.elevations_deg[0] - vlp.elevations_deg[1], 2.0, 1e-9);
  const SensorModel hdl32 = sensor_preset("hdl32");
  ASSERT_EQ(hdl32.beams(), 32);
  EXPECT_NEAR(hdl32.elevations_deg.front(), 10.67, 1e-9);
  EXPECT_NEAR(hdl32.elevations_deg.back(), -30.67, 1e-9);
  const SensorModel os64 = sensor_preset("os1-64");
  ASSERT_EQ(os64.beams(), 64);
  EXPECT_NEAR(os64.elevations_deg.front(), 16.6, 1e-9);
  EXPECT_NEAR(os64.elevations_deg.back(), -16.6, 1e-9);
  const SensorModel os = sensor_preset("os1-128");
  ASSERT_EQ(os.beams(), 128);
  EXPECT_NEAR(os.elevations_deg.front(), 22.5, 1e-9);
  EXPECT_NEAR(os.elevations_deg.back(), -22.5, 1e-9);
  // VLP-32C: non-uniform, no ring table of the odometry's matches it (features/beam_layout).
  const SensorModel v32 = sensor_preset("vlp32c");
  ASSERT_EQ(v32.beams(), 32);
  EXPECT_DOUBLE_EQ(v32.elevations_deg.front(), 15);
  EXPECT_DOUBLE_EQ(v32.elevations_deg.back(), -25);
  EXPECT_TRUE(std::is_sorted(v32.elevations_deg.rbegin(), v32.elevations_deg.rend()));
  EXPECT_THROW(sensor_preset("hdl65"), Error);
}

TEST(SensorScan, RangesToAKnownWallAreWithinNoise) {
  World w = flat_world(200);
  // A wall facing the sensor, its face at x = 20 m.
  w.primitives.push_back(make_box(20.5, 0, 0, 0.5, 30, -1, 20, SurfaceKind::building, 0.4f));
  w.build_index();
  SensorModel s = sensor_preset("hdl64");
  s.dropout_prob = 0;
  const Scan scan = render_scan(w, s, perfect(s), sensor_at_height(1.73), 7, 0);
  double sum = 0, sum2 = 0;
  int n = 0;
  for (const auto& p : scan.points) {
    if (p.x < 15 || std::abs(p.y) > 3 || p.z < -1.0) continue;  // the wall in front, above ground
    sum += p.x - 20;
    sum2 += (p.x - 20) * (p.x - 20);
    ++n;
  }
  ASSERT_GT(n, 500);
  const double mean = sum / n, rms = std::sqrt(sum2 / n);
  EXPECT_NEAR(mean, 0, 0.005);
  EXPECT_NEAR(rms, s.range_noise_m, 0.006);  // the wall's x error is the range noise (cos ~ 1)
}

TEST(SensorScan, NoReturnBeyondMaxRangeOrFromTheSky) {
  World w = flat_world(400);
  w.build_index();
  SensorModel s = sensor_preset("vlp16");
  const Scan scan = render_scan(w, s, draw_beam_calibration(s, 3), sensor_at_height(1.73), 3, 0);
  ASSERT_GT(scan.points.size(), 1000u);
  int rings_seen[16] = {};
  for (const auto& p : scan.points) {
    const double r = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    EXPECT_LE(r, s.max_range_m);
    EXPECT_GE(r, s.min_range_m);
    EXPECT_LT(p.z, -1.6);  // only the ground returns; upward beams see sky
    ASSERT_GE(p.ring, 0);
    ++rings_seen[p.ring];
  }
  // Beams above the horizon (rings 0-7: +15..+1 deg) never return.
  for (int b = 0; b < 8; ++b) EXPECT_EQ(rings_seen[b], 0) << "ring " << b;
  // The lowest beam (-15 deg) meets the ground 6.5 m away all around.
  EXPECT_GT(rings_seen[15], 1000);
}

TEST(SensorScan, RingsAreInOrderAndElevationsMatchTheTable) {
  World w = flat_world(200);
  for (int k = 0; k < 72; ++k) {  // a circular wall of boxes 15 m away
    const double a = k * 2 * M_PI / 72;
    w.primitives.push_back(make_box(15.5 * std::cos(a), 15.5 * std::sin(a), a, 0.5, 0.75, -1, 40, SurfaceKind::building, 0.4f));
  }
  w.build_index();
  SensorModel s = sensor_preset("hdl64");
  s.range_noise_m = 0;
  s.dropout_prob = 0;
  const Scan scan = render_scan(w, s, perfect(s), sensor_at_height(1.73), 1, 0);
  int prev_ring = -1;
  for (const auto& p : scan.points) {
    ASSERT_GE(p.ring, prev_ring);  // ring-major order
    prev_ring = p.ring;
    const double el = std::atan2(p.z, std::hypot(p.x, p.y)) * 180 / M_PI;
    EXPECT_NEAR(el, s.elevations_deg[p.ring], 1e-3);
  }
  EXPECT_EQ(prev_ring, 63);
}

}  // namespace
}  // namespace scfloam::sim

namespace scfloam::sim {
namespace {

// KITTI's common elevation error: a flat road seen through it bends down with range like a
// shallow cone (z = -h sin(el) / sin(el + bias)), and without it stays flat.
TEST(SensorScan, ElevationBiasBendsTheGroundDownWithRange) {
  SensorModel s = sensor_preset("hdl64");
  EXPECT_NEAR(s.elevation_bias_deg, 0.205, 1e-12);
  s.range_noise_m = 0;
  s.dropout_prob = 0;
  s.beam_elevation_error_deg = s.beam_azimuth_error_deg = s.beam_range_bias_m = 0;
  World w = flat_world(100);
  w.build_index();
  auto mean_z_at = [&](double bias_deg, double r_lo, double r_hi) {
    s.elevation_bias_deg = bias_deg;
    const Scan scan = render_scan(w, s, draw_beam_calibration(s, 1), sensor_at_height(1.73), 1, 0);
    double sum = 0;
    int n = 0;
    for (const auto& p : scan.points) {
      const double r = std::hypot(p.x, p.y);
      if (r > r_lo && r < r_hi) sum += p.z, ++n;
    }
    EXPECT_GT(n, 100);
    return sum / n;
  };
  EXPECT_NEAR(mean_z_at(0, 19, 21), -1.73, 0.005);
  // At 20 m the beam is ~4.9 deg down: z = -1.73 * sin(4.9) / sin(4.7) ~ -1.80.
  EXPECT_NEAR(mean_z_at(0.205, 19, 21), -1.73 - 20 * std::tan(0.205 * M_PI / 180), 0.02);
  EXPECT_NEAR(mean_z_at(0.205, 4, 6), -1.73 - 5 * std::tan(0.205 * M_PI / 180), 0.01);
}

// `simulate --beam-elevation-error/--beam-azimuth-error/--beam-range-bias` override the
// preset's per-beam calibration errors: 0 gives a perfectly calibrated sensor (the common
// elevation bias stays separate), negative keeps the preset's.
TEST(SensorScan, BeamCalibrationErrorsFollowTheSimConfig) {
  SimConfig config;
  config.sensor = "vlp16";
  const SensorModel preset = sensor_for(config);
  EXPECT_GT(preset.beam_elevation_error_deg, 0);
  EXPECT_GT(preset.beam_range_bias_m, 0);
  const BeamCalibration drawn = draw_beam_calibration(preset, 4);
  double spread = 0;
  for (double v : drawn.range_bias_m) spread += std::abs(v);
  EXPECT_GT(spread, 0);

  config.beam_elevation_error_deg = config.beam_azimuth_error_deg = config.beam_range_bias_m = 0;
  const BeamCalibration perfect_sensor = draw_beam_calibration(sensor_for(config), 4);
  for (int b = 0; b < preset.beams(); ++b) {
    EXPECT_EQ(perfect_sensor.elevation_offset_rad[b], 0.0) << b;
    EXPECT_EQ(perfect_sensor.azimuth_offset_rad[b], 0.0) << b;
    EXPECT_EQ(perfect_sensor.range_bias_m[b], 0.0) << b;
  }

  config.beam_elevation_error_deg = 0.5;
  const SensorModel wide = sensor_for(config);
  EXPECT_DOUBLE_EQ(wide.beam_elevation_error_deg, 0.5);
  double rms = 0;
  for (double v : draw_beam_calibration(wide, 4).elevation_offset_rad) rms += v * v;
  rms = std::sqrt(rms / wide.beams()) * 180 / M_PI;
  EXPECT_GT(rms, 0.2);  // 16 draws of sigma 0.5 deg
  EXPECT_LT(rms, 1.0);
}

}  // namespace
}  // namespace scfloam::sim
