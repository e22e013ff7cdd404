// The online elevation offset: known answers on a synthetic room, where every plane is known
// and the offset is the only error, and the filter's limits.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "scfloam/odometry/elevation_calibration.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

constexpr double kDeg = M_PI / 180.0;

struct Plane {
  Eigen::Vector3d normal;
  double offset;  // normal . x + offset = 0
};

// A street-like box around the sensor: ground 1.73 m below, walls left, right, ahead and
// behind. Each of 16 beams (-15 .. +15 deg) is fired every 3 deg of azimuth with its true
// elevation `bias_rad` above its nominal one, and the return is reported along the nominal
// direction (as a sensor with an elevation offset does). The matches hold the true planes.
std::vector<PlaneMatch> room_matches(double bias_rad) {
  const std::vector<Plane> planes = {{{0, 0, 1}, 1.73},  {{1, 0, 0}, -30.0}, {{-1, 0, 0}, -25.0},
                                     {{0, 1, 0}, -7.0},  {{0, -1, 0}, -8.5}};
  std::vector<PlaneMatch> out;
  for (int beam = 0; beam < 16; ++beam) {
    const double nominal = (-15.0 + 2.0 * beam) * kDeg;
    for (int a = 0; a < 120; ++a) {
      const double azimuth = a * 3.0 * kDeg;
      const auto direction = [&](double elevation) {
        return Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                               std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      };
      const Eigen::Vector3d truth = direction(nominal + bias_rad);
      double range = 1e9;
      const Plane* hit = nullptr;
      for (const Plane& p : planes) {
        const double r = -p.offset / p.normal.dot(truth);  // where the ray's line meets it
        if (r > 0 && r < range) range = r, hit = &p;
      }
      if (!hit) continue;
      out.push_back({range * direction(nominal), hit->normal, hit->offset});
    }
  }
  return out;
}

Eigen::Isometry3d pose(const Eigen::Vector3d& rotation_rad, const Eigen::Vector3d& translation) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3_exp(rotation_rad);
  T.translation() = translation;
  return T;
}

TEST(ElevationStep, RecoversAKnownOffsetAtTheTruePose) {
  for (double bias_deg : {0.22, -0.1, 0.5}) {
    const ElevationStep s = elevation_step(room_matches(bias_deg * kDeg), Eigen::Isometry3d::Identity(), 1.0);
    EXPECT_GT(s.information, 0);
    EXPECT_NEAR(s.step_rad / kDeg, bias_deg, 0.02 * std::abs(bias_deg)) << bias_deg;
  }
}

TEST(ElevationStep, APoseErrorIsNotTakenForAnOffset) {
  // The step is the joint [pose; offset] one: a pose off by 0.3 deg of pitch and 5 cm gives
  // (nearly) no offset when there is none, and the right one when there is.
  const Eigen::Isometry3d off = pose({0.004, 0.005, 0.002}, {0.05, -0.03, 0.04});
  EXPECT_NEAR(elevation_step(room_matches(0.0), off, 1.0).step_rad / kDeg, 0.0, 0.01);
  EXPECT_NEAR(elevation_step(room_matches(0.22 * kDeg), off, 1.0).step_rad / kDeg, 0.22, 0.015);
}

TEST(ElevationStep, NothingMatchedIsNoInformation) {
  const ElevationStep s = elevation_step({}, Eigen::Isometry3d::Identity(), 0.1);
  EXPECT_EQ(s.information, 0);
  EXPECT_EQ(s.step_rad, 0);
}

TEST(ElevationCalibration, MovesByAtMostTheStepLimitAndStaysNearTheConfiguredValue) {
  // A 0.5 deg offset seen in full every frame: 0.05 deg per frame at most, and never more
  // than max_change_deg from where it started.
  ElevationCalibration calibration(0.0, 1.0, 0.3);
  const std::vector<PlaneMatch> matches = room_matches(0.5 * kDeg);
  double last = 0;
  for (int frame = 0; frame < 20; ++frame) {
    const double now = calibration.update(matches, Eigen::Isometry3d::Identity());
    EXPECT_LE(now - last, 0.05 + 1e-12);
    EXPECT_GE(now, last);
    last = now;
  }
  EXPECT_NEAR(last, 0.3, 1e-12);
}

TEST(ElevationCalibration, ConvergesOnAConsistentOffset) {
  // Each update sees the offset left after the previous correction, as a frame would if its
  // map were exact (the real map lags): the estimate approaches 0.22 deg and settles there.
  ElevationCalibration calibration(0.0, 0.5, 1.0);
  double correction = 0;
  for (int frame = 0; frame < 60; ++frame)
    correction = calibration.update(room_matches((0.22 - correction) * kDeg), Eigen::Isometry3d::Identity());
  EXPECT_NEAR(correction, 0.22, 0.002);
}

}  // namespace
}  // namespace scfloam
