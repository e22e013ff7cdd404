// The elevation offset from the road's shape: known answers on a synthetic road whose height
// profile and the sensor's offset are set by the test.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "scfloam/odometry/ground_elevation.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kMountM = 1.73;

// Road height (m) at world x; the road runs along x and is level across.
using Profile = std::function<double(double)>;

// A 56-beam sensor (-24 .. -2 deg every 0.4 deg, 0.5 deg of azimuth) 1.73 m above the road at
// world x = `at_x`, pitched nose-up by `pitch_deg`, whose beams all point `offset_deg` higher
// than their table: each ray is cast along its true direction and reported along the table's.
std::vector<LidarPoint> road_scan(const Profile& road, double at_x, double offset_deg, double pitch_deg = 0) {
  const Eigen::Matrix3d R = so3_exp(Eigen::Vector3d(0, -pitch_deg * kDeg, 0));
  const Eigen::Vector3d origin(at_x, 0, road(at_x) + kMountM);
  std::vector<LidarPoint> out;
  for (int beam = 0; beam < 56; ++beam) {
    const double table = (-24.0 + 0.4 * beam) * kDeg;
    for (int a = 0; a < 720; ++a) {
      const double azimuth = a * 0.5 * kDeg;
      const auto direction = [&](double elevation) {
        return Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                               std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      };
      const Eigen::Vector3d ray = R * direction(table + offset_deg * kDeg);
      // Bisection for the range where the ray meets the road (below it at 200 m, or no hit).
      const auto below = [&](double range) {
        const Eigen::Vector3d p = origin + range * ray;
        return p.z() < road(p.x());
      };
      double lo = 0, hi = 200;
      if (!below(hi)) continue;
      for (int i = 0; i < 50; ++i) (below(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
      const Eigen::Vector3d reported = hi * direction(table);
      out.push_back({static_cast<float>(reported.x()), static_cast<float>(reported.y()),
                     static_cast<float>(reported.z()), 0.f, 0.f, static_cast<std::int16_t>(beam)});
    }
  }
  return out;
}

// The pose of the sensor at `at_x`, as the odometry would have it (exact here).
Eigen::Isometry3d sensor_pose(const Profile& road, double at_x, double pitch_deg = 0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3_exp(Eigen::Vector3d(0, -pitch_deg * kDeg, 0));
  T.translation() = Eigen::Vector3d(at_x, 0, road(at_x) + kMountM);
  return T;
}

const Profile kFlat = [](double) { return 0.0; };
// A sag: the road curves up 1/1500 per metre both ways (a gentle valley, as on KITTI's roads).
const Profile kSag = [](double x) { return x * x / 3000.0; };

std::vector<Eigen::Vector3f> road_points(const std::vector<LidarPoint>& scan) {
  const GroundConeFit f = fit_ground_cone(scan, Eigen::Vector2d(1, 0));
  EXPECT_TRUE(f.ok);
  return f.road;
}

TEST(GroundCone, RecoversTheOffsetOnFlatGroundWhateverThePitch) {
  for (double offset : {0.22, -0.1, 0.0})
    for (double pitch : {0.0, 0.8}) {
      const GroundConeFit f = fit_ground_cone(road_scan(kFlat, 0, offset, pitch), Eigen::Vector2d(1, 0));
      ASSERT_TRUE(f.ok) << offset << " " << pitch;
      EXPECT_NEAR(-f.slope_rad / kDeg, offset, 0.01) << offset << " " << pitch;
      EXPECT_GT(f.ahead, 100);
      EXPECT_GT(f.behind, 100);
      EXPECT_EQ(f.road.size(), static_cast<std::size_t>(f.ahead + f.behind));
    }
}

TEST(GroundCone, ARoadsBendLooksLikeAnOffsetInOneScan) {
  // Why one scan is not enough: the sag alone reads as a large offset.
  const GroundConeFit f = fit_ground_cone(road_scan(kSag, 0, 0.0), Eigen::Vector2d(1, 0));
  ASSERT_TRUE(f.ok);
  EXPECT_GT(std::abs(f.slope_rad / kDeg), 0.1);
}

TEST(GroundCone, RefusesScansWithoutRoadOnBothSidesOrWithoutADirection) {
  std::vector<LidarPoint> ahead_only;
  for (const LidarPoint& p : road_scan(kFlat, 0, 0.2))
    if (p.x > 0) ahead_only.push_back(p);
  EXPECT_FALSE(fit_ground_cone(ahead_only, Eigen::Vector2d(1, 0)).ok);
  EXPECT_FALSE(fit_ground_cone(road_scan(kFlat, 0, 0.2), Eigen::Vector2d(0, 0)).ok);
  // Rough ground: every point 0-20 cm up at random is no road.
  std::vector<LidarPoint> rough = road_scan(kFlat, 0, 0.2);
  unsigned state = 12345;
  for (LidarPoint& p : rough) {
    state = state * 1664525u + 1013904223u;
    p.z += 0.2f * static_cast<float>(state >> 8) / static_cast<float>(1u << 24);
  }
  EXPECT_FALSE(fit_ground_cone(rough, Eigen::Vector2d(1, 0)).ok);
}

TEST(GroundOffset, TwoScansOfTheSameBendGiveTheOffset) {
  for (double offset : {0.205, -0.15, 0.0}) {
    const auto earlier = road_points(road_scan(kSag, 0, offset));
    const auto later = road_points(road_scan(kSag, 8, offset));
    const auto found = offset_between(earlier, later, sensor_pose(kSag, 0).inverse() * sensor_pose(kSag, 8));
    ASSERT_TRUE(found.has_value()) << offset;
    EXPECT_NEAR(*found / kDeg, offset, 0.01) << offset;
  }
}

TEST(GroundOffset, AnErrorOfTheRelativePoseIsNotTakenForAnOffset) {
  // The odometry's relative pose off by 0.05 deg of pitch, 0.03 deg of roll and 3 cm of
  // height: a tilt and a constant, not the step between the road ahead and behind.
  const auto earlier = road_points(road_scan(kSag, 0, 0.2));
  const auto later = road_points(road_scan(kSag, 9, 0.2));
  Eigen::Isometry3d error = Eigen::Isometry3d::Identity();
  error.linear() = so3_exp(Eigen::Vector3d(0.03 * kDeg, -0.05 * kDeg, 0));
  error.translation() = Eigen::Vector3d(0.01, 0, 0.03);
  const auto found =
      offset_between(earlier, later, error * sensor_pose(kSag, 0).inverse() * sensor_pose(kSag, 9));
  ASSERT_TRUE(found.has_value());
  EXPECT_NEAR(*found / kDeg, 0.2, 0.01);
}

TEST(GroundOffset, ScansThatDoNotOverlapGiveNothing) {
  const auto earlier = road_points(road_scan(kFlat, 0, 0.2));
  const auto later = road_points(road_scan(kFlat, 100, 0.2));
  EXPECT_FALSE(offset_between(earlier, later, sensor_pose(kFlat, 0).inverse() * sensor_pose(kFlat, 100)));
  EXPECT_FALSE(offset_between({}, later, Eigen::Isometry3d::Identity()));
}

TEST(GroundElevationEstimate, KeepsTheConfiguredValueUntilEnoughPairsThenFindsTheOffset) {
  // A drive at 1 m per frame over a road that rises and falls (a 0.8 m wave of 160 m), with
  // the beams 0.3 deg off and 0.1 deg configured.
  const Profile wave = [](double x) { return 0.8 * std::sin(2 * M_PI * x / 160.0); };
  GroundElevationEstimate estimate(0.1, 10, 1.0);
  const Eigen::Vector3d motion(1, 0, 0);
  double correction = 0.1;
  for (int frame = 0; frame < 70; ++frame) {
    const double x = frame;
    // The sensor follows the road's slope, as a car does.
    const double pitch = std::atan(0.8 * 2 * M_PI / 160.0 * std::cos(2 * M_PI * x / 160.0)) / kDeg;
    correction = estimate.update(road_scan(wave, x, 0.3, pitch), sensor_pose(wave, x, pitch), motion);
    if (estimate.pairs_used() < 10) {
      EXPECT_EQ(correction, 0.1) << frame;
    }
  }
  EXPECT_GE(estimate.pairs_used(), 30u);
  EXPECT_NEAR(correction, 0.3, 0.01);
  EXPECT_EQ(estimate.correction_deg(), correction);
}

TEST(GroundElevationEstimate, RefusesPairsBeyondItsLimitAndNeedsMotion) {
  // 0.3 deg in every pair where 0.1 deg of change is allowed: a mismatch, not the sensor.
  GroundElevationEstimate estimate(0.0, 3, 0.1);
  double correction = 0;
  for (int frame = 0; frame < 20; ++frame)
    correction = estimate.update(road_scan(kFlat, frame, 0.3), sensor_pose(kFlat, frame), {1, 0, 0});
  EXPECT_EQ(estimate.pairs_used(), 0u);
  EXPECT_EQ(correction, 0.0);
  GroundElevationEstimate parked(0.0, 1, 1.0);
  for (int frame = 0; frame < 20; ++frame)
    parked.update(road_scan(kFlat, 0, 0.3), sensor_pose(kFlat, 0), {0.05, 0, 0});
  EXPECT_EQ(parked.pairs_used(), 0u);
  EXPECT_EQ(parked.correction_deg(), 0.0);
}

}  // namespace
}  // namespace scfloam
