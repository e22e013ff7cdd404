#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "scfloam/registration/voxel_filter.hpp"
#include "scfloam/registration/voxel_map.hpp"

namespace scfloam {
namespace {

FeatureCloud random_cloud(std::size_t n, float extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent);
  FeatureCloud c(n);
  for (auto& p : c) p = Eigen::Vector3f(u(rng), u(rng), u(rng));
  return c;
}

TEST(VoxelMap, KnnMatchesBruteForce) {
  // Spacing 0 and room for everything: the map stores every point, so brute force is exact.
  VoxelMap map(1.0, 0.0, 1000);
  const FeatureCloud cloud = random_cloud(20000, 8.f, 1);
  EXPECT_EQ(map.insert(cloud, Eigen::Isometry3d::Identity()), cloud.size());
  const FeatureCloud queries = random_cloud(500, 8.5f, 2);
  VoxelMap::Neighbors nb;
  for (const auto& q : queries) {
    map.knn(q, 5, 1.0f, nb);
    std::vector<float> d2;
    for (const auto& p : cloud)
      if ((p - q).squaredNorm() < 1.0f) d2.push_back((p - q).squaredNorm());
    std::sort(d2.begin(), d2.end());
    ASSERT_EQ(nb.count, static_cast<int>(std::min<std::size_t>(5, d2.size())));
    for (int i = 0; i < nb.count; ++i) EXPECT_FLOAT_EQ(nb.sq_dist[i], d2[i]);
  }
}

TEST(VoxelMap, SpacingBoundsDensityAndRemoveFarDropsCells) {
  VoxelMap map(1.0, 0.5, 20);
  FeatureCloud line;
  for (int i = 0; i < 1000; ++i) line.emplace_back(0.01f * i, 0.2f, 0.2f);  // 10 m at 1 cm
  const std::size_t stored = map.insert(line, Eigen::Isometry3d::Identity());
  EXPECT_LE(stored, 30u);  // about one point per 0.5 m per 1 m cell
  EXPECT_GE(stored, 10u);
  const FeatureCloud all = map.points();
  for (std::size_t i = 0; i < all.size(); ++i)
    for (std::size_t j = i + 1; j < all.size(); ++j)
      if (std::floor(all[i].x()) == std::floor(all[j].x())) {  // same cell
        EXPECT_GE((all[i] - all[j]).norm(), 0.5f);
      }
  map.remove_far(Eigen::Vector3d(0, 0, 0), 3.0);
  for (const auto& p : map.points()) EXPECT_LT(p.x(), 4.0f);
  EXPECT_EQ(map.num_points(), map.points().size());
}

TEST(VoxelMap, InsertAppliesThePose) {
  VoxelMap map(1.0, 0.0, 10);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(100, 0, 0);
  map.insert({Eigen::Vector3f(1, 2, 3)}, T);
  VoxelMap::Neighbors nb;
  map.knn(Eigen::Vector3f(101, 2, 3), 1, 0.5f, nb);
  ASSERT_EQ(nb.count, 1);
  EXPECT_FLOAT_EQ(nb.sq_dist[0], 0.f);
}

TEST(VoxelFilter, OneCentroidPerVoxel) {
  FeatureCloud in{{0.1f, 0.1f, 0.1f}, {0.3f, 0.3f, 0.3f}, {1.1f, 0.1f, 0.1f}, {-0.1f, 0.1f, 0.1f}};
  const FeatureCloud out = voxel_downsample(in, 1.0);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_TRUE(out[0].isApprox(Eigen::Vector3f(0.2f, 0.2f, 0.2f)));
  EXPECT_TRUE(out[1].isApprox(Eigen::Vector3f(1.1f, 0.1f, 0.1f)));
  EXPECT_TRUE(out[2].isApprox(Eigen::Vector3f(-0.1f, 0.1f, 0.1f)));
}

}  // namespace
}  // namespace scfloam
