// Degenerate scan-to-map problems: a corridor leaves the along-corridor translation
// unconstrained, and the solve must keep the initial guess (the motion model) there.
#include <gtest/gtest.h>

#include "scfloam/registration/scan_to_map.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

// Walls at y = +-2 m and a floor at z = -1.7 m, along x in [-20, 20] m, as plane points;
// `cross_wall` adds a wall across the corridor at x = 12 m, which pins the x translation.
FeatureCloud corridor(bool cross_wall) {
  FeatureCloud pts;
  constexpr float kStep = 0.25f;
  for (float x = -20; x <= 20; x += kStep) {
    for (float z = -1.7f; z <= 2.0f; z += kStep) {
      pts.emplace_back(x, -2.0f, z);
      pts.emplace_back(x, 2.0f, z);
    }
    for (float y = -1.9f; y <= 1.9f; y += kStep) pts.emplace_back(x, y, -1.7f);
  }
  if (cross_wall)
    for (float y = -1.9f; y <= 1.9f; y += kStep)
      for (float z = -1.6f; z <= 2.0f; z += kStep) pts.emplace_back(12.0f, y, z);
  return pts;
}

RegistrationResult solve(const FeatureCloud& scene, const Eigen::Isometry3d& T_init,
                         bool fallback) {
  OdometryConfig c;
  c.registration.degeneracy_fallback = fallback;
  FeatureMap map(c.registration, c.map);
  map.insert({}, scene, Eigen::Isometry3d::Identity());
  // The scan is the scene itself: the true pose is the identity.
  return register_features({}, scene, map, T_init, c.registration, 12);
}

// The synthetic scene converges to ~0.1 deg from a 0.66 deg start (points near the wall/floor
// corners fit slanted planes); the real KITTI scans reach 0.03 deg (tests/odometry).
constexpr double kRotationTolDeg = 0.2;

Eigen::Isometry3d offset_guess() {
  Eigen::Matrix<double, 6, 1> xi;
  xi << 0.005, -0.004, 0.01, 0.4, 0.15, -0.1;  // rad, m: off in every direction
  return left_perturb(xi, Eigen::Isometry3d::Identity());
}

TEST(Degeneracy, CorridorKeepsThePredictionAlongTheCorridor) {
  const Eigen::Isometry3d T_init = offset_guess();
  const RegistrationResult r = solve(corridor(false), T_init, true);
  EXPECT_TRUE(r.degenerate);
  EXPECT_TRUE(r.fallback_applied);
  EXPECT_EQ(r.weak_translation_dirs, 1);
  EXPECT_EQ(r.weak_rotation_dirs, 0);
  EXPECT_GT(std::abs(r.weakest_translation_dir.x()), 0.999);
  // Along x: exactly the guess. Across: the walls and the floor pull y, z and the rotation in.
  EXPECT_NEAR(r.T_world_lidar.translation().x(), T_init.translation().x(), 1e-3);
  EXPECT_LT(std::abs(r.T_world_lidar.translation().y()), 0.02);
  EXPECT_LT(std::abs(r.T_world_lidar.translation().z()), 0.02);
  EXPECT_LT(rotation_angle_rad(r.T_world_lidar.linear()) * 180 / M_PI, kRotationTolDeg);
  EXPECT_GT(r.translation_eigenvalues[1], 1000);
}

TEST(Degeneracy, CorridorWithoutFallbackIsStillReportedButMovesFreely) {
  const RegistrationResult r = solve(corridor(false), offset_guess(), false);
  EXPECT_TRUE(r.degenerate);
  EXPECT_FALSE(r.fallback_applied);
  EXPECT_EQ(r.weak_translation_dirs, 1);
}

TEST(Degeneracy, ACrossWallRemovesTheWeakDirection) {
  const RegistrationResult r = solve(corridor(true), offset_guess(), true);
  EXPECT_FALSE(r.degenerate);
  EXPECT_FALSE(r.fallback_applied);
  EXPECT_EQ(r.weak_translation_dirs + r.weak_rotation_dirs, 0);
  EXPECT_LT(r.T_world_lidar.translation().norm(), 0.03);
  EXPECT_LT(rotation_angle_rad(r.T_world_lidar.linear()) * 180 / M_PI, kRotationTolDeg);
}

TEST(Degeneracy, OpenFieldKeepsPlanarMotionAndYaw) {
  // Ground only: z, roll and pitch are constrained; x, y and yaw keep the guess.
  FeatureCloud ground;
  for (int i = -60; i <= 60; ++i)
    for (int j = -60; j <= 60; ++j) ground.emplace_back(0.25f * i, 0.25f * j, -1.7f);
  const Eigen::Isometry3d T_init = offset_guess();
  const RegistrationResult r = solve(ground, T_init, true);
  EXPECT_TRUE(r.degenerate);
  EXPECT_EQ(r.weak_translation_dirs, 2);
  EXPECT_EQ(r.weak_rotation_dirs, 1);
  EXPECT_NEAR(r.T_world_lidar.translation().x(), T_init.translation().x(), 1e-3);
  EXPECT_NEAR(r.T_world_lidar.translation().y(), T_init.translation().y(), 1e-3);
  EXPECT_LT(std::abs(r.T_world_lidar.translation().z()), 0.01);
  // Yaw as guessed; roll and pitch back to level (the up axis is vertical again).
  const Eigen::Vector3d up = r.T_world_lidar.linear() * Eigen::Vector3d::UnitZ();
  EXPECT_LT(std::acos(std::min(1.0, up.z())) * 180 / M_PI, 0.05);
  const Eigen::Vector3d fwd = r.T_world_lidar.linear() * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d fwd_init = T_init.linear() * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::atan2(fwd.y(), fwd.x()), std::atan2(fwd_init.y(), fwd_init.x()), 1e-3);
}

TEST(Degeneracy, NoMatchesKeepsTheGuess) {
  const OdometryConfig c;
  FeatureMap map(c.registration, c.map);
  const Eigen::Isometry3d T_init = offset_guess();
  const FeatureCloud few{{1, 2, 3}, {4, 5, 6}}, none;
  for (const FeatureCloud* scan : {&few, &none}) {
    const RegistrationResult r = register_features({}, *scan, map, T_init, c.registration, 3);
    EXPECT_TRUE(r.degenerate);
    EXPECT_TRUE(r.T_world_lidar.isApprox(T_init, 1e-12));
  }
}

}  // namespace
}  // namespace scfloam
