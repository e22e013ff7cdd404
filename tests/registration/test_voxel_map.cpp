#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

// Brute-force k nearest squared distances within radius r among `cloud`.
std::vector<float> brute_knn(const FeatureCloud& cloud, const Eigen::Vector3f& q, int k, float r) {
  std::vector<float> d2;
  for (const auto& p : cloud)
    if ((p - q).squaredNorm() < r * r) d2.push_back((p - q).squaredNorm());
  std::sort(d2.begin(), d2.end());
  if (d2.size() > static_cast<std::size_t>(k)) d2.resize(k);
  return d2;
}

TEST(VoxelMap, KnnStaysExactAcrossBricksAfterRemoveFarAndClear) {
  // Cells of 0.7 m grouped 8 x 8 x 8 into bricks: a cloud 40 m across, centred off the origin,
  // spans many bricks on both sides of zero; dropping far cells renumbers the rest and
  // rebuilds the bricks, clearing empties them. Every query must still see exactly the points
  // brute force sees.
  const float cell = 0.7f;
  VoxelMap map(cell, 0.0, 1000);
  FeatureCloud cloud = random_cloud(30000, 20.f, 3);
  for (auto& p : cloud) p += Eigen::Vector3f(3.3f, -1.7f, 0.4f);
  ASSERT_EQ(map.insert(cloud, Eigen::Isometry3d::Identity()), cloud.size());
  auto check = [&](const FeatureCloud& stored, unsigned seed) {
    FeatureCloud queries = random_cloud(400, 21.f, seed);
    for (auto& q : queries) q += Eigen::Vector3f(3.3f, -1.7f, 0.4f);
    VoxelMap::Neighbors nb;
    for (const auto& q : queries) {
      map.knn(q, 8, cell, nb);
      const std::vector<float> want = brute_knn(stored, q, 8, cell);
      ASSERT_EQ(nb.count, static_cast<int>(want.size()));
      for (int i = 0; i < nb.count; ++i) EXPECT_FLOAT_EQ(nb.sq_dist[i], want[i]);
    }
  };
  check(cloud, 4);

  const Eigen::Vector3d center(-6.0, 5.0, 0.0);
  map.remove_far(center, 12.0);
  const FeatureCloud kept = map.points();
  EXPECT_LT(kept.size(), cloud.size());
  EXPECT_GT(kept.size(), cloud.size() / 20);
  EXPECT_EQ(map.num_points(), kept.size());
  check(kept, 5);

  map.clear();
  EXPECT_EQ(map.num_points(), 0u);
  VoxelMap::Neighbors nb;
  map.knn(cloud[0], 8, cell, nb);
  EXPECT_EQ(nb.count, 0);
  ASSERT_EQ(map.insert(cloud, Eigen::Isometry3d::Identity()), cloud.size());
  check(cloud, 6);
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

TEST(VoxelMap, ViewsKeepPointsSeenFromElsewhereAndFilterQueries) {
  // One pole point at (10, 0, 0), seen from the origin (view 0 deg) and from (10, -10, 0)
  // (view 90 deg); tolerance 20 deg, spacing 0.5 m.
  VoxelMap map(1.0, 0.5, 10, 20.0 * M_PI / 180.0);
  ASSERT_TRUE(map.stores_views());
  Eigen::Isometry3d from_origin = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d from_south = Eigen::Isometry3d::Identity();
  from_south.translation() = Eigen::Vector3d(10, -10, 0);
  EXPECT_EQ(map.insert({Eigen::Vector3f(10, 0, 0)}, from_origin), 1u);
  // 10 cm away, seen from the same side: refused by the spacing; from the other view: kept.
  EXPECT_EQ(map.insert({Eigen::Vector3f(10.1f, 0, 0)}, from_origin), 0u);
  EXPECT_EQ(map.insert({Eigen::Vector3f(0.1f, 10, 0)}, from_south), 1u);  // world (10.1, 0, 0)
  EXPECT_EQ(map.num_points(), 2u);

  const Eigen::Vector3f q(10.05f, 0, 0);
  VoxelMap::Neighbors nb;
  map.knn(q, 5, 1.0f, nb);
  EXPECT_EQ(nb.count, 2);  // no filter: both
  const VoxelMap::View east = VoxelMap::view_of(Eigen::Vector3f(0, 0, 0), q);
  map.knn(q, 5, 1.0f, nb, &east);
  ASSERT_EQ(nb.count, 1);
  EXPECT_FLOAT_EQ(nb.points[0].x(), 10.f);
  const VoxelMap::View north = VoxelMap::view_of(Eigen::Vector3f(10, -10, 0), q);
  map.knn(q, 5, 1.0f, nb, &north);
  ASSERT_EQ(nb.count, 1);
  EXPECT_NEAR(nb.points[0].x(), 10.1f, 1e-5f);
  // 30 deg off either view: nothing.
  const VoxelMap::View between = VoxelMap::view_of(Eigen::Vector3f(0, 0, 0),
                                                   Eigen::Vector3f(std::cos(0.52f), std::sin(0.52f), 0));
  map.knn(q, 5, 1.0f, nb, &between);
  EXPECT_EQ(nb.count, 0);

  // Views wrap at +-180 deg: seen heading -179 deg, a query at +179 deg is 2 deg off.
  VoxelMap wrap(1.0, 0.5, 10, 5.0 * M_PI / 180.0);
  const Eigen::Vector3f west(-10, -0.17f, 0), query(-10, 0.17f, 0);
  wrap.insert({west}, Eigen::Isometry3d::Identity());
  const VoxelMap::View v = VoxelMap::view_of(Eigen::Vector3f(0, 0, 0), query);
  wrap.knn(query, 1, 1.0f, nb, &v);
  EXPECT_EQ(nb.count, 1);

  // remove_far moves the kept cells down over the dropped ones: views must move with them.
  VoxelMap moved(1.0, 0.5, 10, 20.0 * M_PI / 180.0);
  moved.insert({Eigen::Vector3f(-50, 0, 0)}, from_origin);  // the first cell, dropped below
  moved.insert({Eigen::Vector3f(10, 0, 0)}, from_origin);
  moved.insert({Eigen::Vector3f(0.1f, 10, 0)}, from_south);
  moved.remove_far(Eigen::Vector3d(10, 0, 0), 5.0);
  EXPECT_EQ(moved.num_points(), 2u);
  moved.knn(q, 5, 1.0f, nb, &north);
  ASSERT_EQ(nb.count, 1);
  EXPECT_NEAR(nb.points[0].x(), 10.1f, 1e-5f);
}

TEST(VoxelFilter, OneCentroidPerVoxel) {
  FeatureCloud in{{0.1f, 0.1f, 0.1f}, {0.3f, 0.3f, 0.3f}, {1.1f, 0.1f, 0.1f}, {-0.1f, 0.1f, 0.1f}};
  const FeatureCloud out = voxel_downsample(in, 1.0);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_TRUE(out[0].isApprox(Eigen::Vector3f(0.2f, 0.2f, 0.2f)));
  EXPECT_TRUE(out[1].isApprox(Eigen::Vector3f(1.1f, 0.1f, 0.1f)));
  EXPECT_TRUE(out[2].isApprox(Eigen::Vector3f(-0.1f, 0.1f, 0.1f)));
}


// Runs summed elsewhere (the feature extractor sums each ring's) give the centroids filter()
// gives for the same points in the same order, whether they fill one part or two.
TEST(VoxelFilter, RunsGiveTheCentroidsOfThePointsInFirstSeenOrder) {
  // A walk of small steps, so that consecutive points share voxels (runs of several points),
  // revisiting voxels from other "rings".
  std::mt19937 rng(5);
  std::normal_distribution<float> step(0.f, 0.05f);
  for (const std::size_t n : {500u, 60000u}) {  // one part; two halves on two threads
    FeatureCloud cloud(n);
    Eigen::Vector3f at(0.3f, -0.2f, 0.1f);
    for (auto& p : cloud) {
      at += Eigen::Vector3f(step(rng), step(rng), step(rng));
      p = at;
    }
    const double leaf = 0.8;
    std::vector<VoxelRuns> runs(7);  // uneven pieces, as rings are
    std::size_t begin = 0;
    for (std::size_t r = 0; r < runs.size(); ++r) {
      const std::size_t end = r + 1 == runs.size() ? n : begin + n / (8 + r);
      runs[r].append(cloud.data() + begin, cloud.data() + end, static_cast<float>(1.0 / leaf));
      begin = end;
    }
    std::size_t total_runs = 0, total_points = 0;
    for (const VoxelRuns& r : runs) {
      total_runs += r.keys.size();
      for (const auto& s : r.sums) total_points += static_cast<std::size_t>(s.w());
    }
    EXPECT_EQ(total_points, n);
    EXPECT_LT(total_runs, n / 2) << "consecutive points should share voxels";
    VoxelFilter by_runs, by_points;
    FeatureCloud a, b;
    by_runs.filter_runs(runs, a);
    by_points.filter(cloud, leaf, b);
    ASSERT_EQ(a.size(), b.size()) << n;
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_LT((a[i] - b[i]).norm(), 1e-5f) << i;
    FeatureCloud again;
    by_runs.filter_runs(runs, again);  // the tables are reset between calls
    EXPECT_EQ(again, a);
  }
}

// The runs' keys (four points at a time through SSE2, the rest one by one) are the voxels of
// voxel_coords: points on both sides of zero in every lane, on voxel faces, lengths not a
// multiple of four.
TEST(VoxelRuns, KeysAreThoseOfVoxelCoordsInEveryLane) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-40.f, 40.f);
  std::uniform_int_distribution<int> face(-50, 50);
  const float leaf = 0.8f, inv = 1.0f / leaf;
  for (const std::size_t n : {1u, 3u, 4u, 7u, 1001u}) {
    FeatureCloud cloud(n);
    for (std::size_t i = 0; i < n; ++i) {
      cloud[i] = Eigen::Vector3f(u(rng), u(rng), u(rng));
      if (i % 3 == 1) cloud[i][static_cast<int>(i % 7 % 3)] = static_cast<float>(face(rng)) * leaf;  // on a face
      if (i % 5 == 2) cloud[i] = Eigen::Vector3f(-1e-4f, 1e-4f, -0.f);  // just either side of zero
    }
    VoxelRuns runs;
    runs.append(cloud.data(), cloud.data() + n, inv);
    // The expected runs, point by point.
    std::vector<std::uint64_t> keys;
    std::vector<float> counts;
    for (const Eigen::Vector3f& p : cloud) {
      const Eigen::Vector3i c = voxel_coords(p, inv);
      const std::uint64_t key = voxel_key(c.x(), c.y(), c.z());
      if (keys.empty() || keys.back() != key) {
        keys.push_back(key);
        counts.push_back(0);
      }
      counts.back() += 1;
    }
    ASSERT_EQ(runs.keys, keys) << n;
    ASSERT_EQ(runs.sums.size(), counts.size());
    for (std::size_t r = 0; r < counts.size(); ++r) EXPECT_EQ(runs.sums[r].w(), counts[r]) << r;
  }
  // Known voxels: floor, not truncation, below zero.
  const FeatureCloud known{{-0.1f, 0.1f, 0.9f}, {0.79f, -0.81f, -1.5f}, {1.7f, 0.f, -0.f}, {-2.3f, 2.3f, 0.4f}, {0.5f, 0.5f, 0.5f}};
  VoxelRuns runs;
  runs.append(known.data(), known.data() + known.size(), inv);
  ASSERT_EQ(runs.keys.size(), 5u);
  EXPECT_EQ(runs.keys[0], voxel_key(-1, 0, 1));
  EXPECT_EQ(runs.keys[1], voxel_key(0, -2, -2));
  EXPECT_EQ(runs.keys[2], voxel_key(2, 0, 0));
  EXPECT_EQ(runs.keys[3], voxel_key(-3, 2, 0));
  EXPECT_EQ(runs.keys[4], voxel_key(0, 0, 0));
}

}  // namespace
}  // namespace scfloam

namespace scfloam {
namespace {

// The flat key table behind the voxel filter, the local map and map.pcd: every key stored is
// found with its first value, at either load, through growth from empty and after a reset.
TEST(FlatKeyIndex, StoresAndFindsEveryKeyAtEitherLoad) {
  for (const auto load : {FlatKeyIndex::MaxLoad::kHalf, FlatKeyIndex::MaxLoad::kThreeQuarters}) {
    FlatKeyIndex index(load);
    EXPECT_EQ(index.find(voxel_key(0, 0, 0)), FlatKeyIndex::kNone);  // empty, never reset
    for (int round = 0; round < 2; ++round) {
      std::uint32_t next = 0;
      for (int x = -30; x < 30; ++x)
        for (int y = -30; y < 30; ++y)
          for (int z = -5; z < 5; ++z, ++next) ASSERT_EQ(index.insert(voxel_key(x, y, z), next), next);
      EXPECT_EQ(index.size(), 36000u);
      // A key already there keeps its first value.
      EXPECT_EQ(index.insert(voxel_key(-30, -30, -5), 999999u), 0u);
      EXPECT_EQ(index.size(), 36000u);
      std::uint32_t expected = 0;
      for (int x = -30; x < 30; ++x)
        for (int y = -30; y < 30; ++y)
          for (int z = -5; z < 5; ++z) ASSERT_EQ(index.find(voxel_key(x, y, z)), expected++);
      EXPECT_EQ(index.find(voxel_key(30, 0, 0)), FlatKeyIndex::kNone);
      EXPECT_EQ(index.find(voxel_key(0, 0, -6)), FlatKeyIndex::kNone);
      index.reset(100);  // empty again, for the second round
      EXPECT_EQ(index.size(), 0u);
      EXPECT_EQ(index.find(voxel_key(1, 2, 3)), FlatKeyIndex::kNone);
    }
  }
}

}  // namespace
}  // namespace scfloam
