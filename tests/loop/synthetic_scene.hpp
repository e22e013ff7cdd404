// Random "places" for the loop tests: vertical structures (poles, trunks, wall pieces) of
// random heights on flat ground, seen from a sensor pose (no occlusion).
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace scfloam::test {

// World points of one place within +-extent_m of the origin: `structures` thin vertical
// segments (poles, trunks) and `walls` facades of random length, heading and height.
inline std::vector<Eigen::Vector3f> random_place(std::uint32_t seed, int structures = 200,
                                                 int walls = 40, double extent_m = 80.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> xy(-extent_m, extent_m), height(0.5, 15.0),
      wall_length(5.0, 30.0), heading(0.0, M_PI);
  std::vector<Eigen::Vector3f> points;
  const double ground_z = -2.0;  // sensor 2 m above the ground, as the default config assumes
  auto column = [&](double x, double y, double h) {
    for (double z = 0.0; z <= h; z += 0.5)
      points.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(ground_z + z));
  };
  for (int s = 0; s < structures; ++s) column(xy(rng), xy(rng), height(rng));
  for (int w = 0; w < walls; ++w) {
    const double x = xy(rng), y = xy(rng), h = height(rng), length = wall_length(rng), a = heading(rng);
    for (double u = 0.0; u <= length; u += 0.5) column(x + u * std::cos(a), y + u * std::sin(a), h);
  }
  for (double x = -extent_m; x <= extent_m; x += 2.0)
    for (double y = -extent_m; y <= extent_m; y += 2.0)
      points.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(ground_z));
  return points;
}

// The world points seen from T_world_lidar, in the lidar frame.
inline std::vector<Eigen::Vector3f> view_from(const std::vector<Eigen::Vector3f>& world,
                                              const Eigen::Isometry3d& T_world_lidar) {
  const Eigen::Isometry3f T_lidar_world = T_world_lidar.inverse().cast<float>();
  std::vector<Eigen::Vector3f> out;
  out.reserve(world.size());
  for (const auto& p : world) out.push_back(T_lidar_world * p);
  return out;
}

inline Eigen::Isometry3d pose_xy_yaw(double x, double y, double yaw_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0.0);
  return T;
}

}  // namespace scfloam::test
