// Ray casting against each primitive, the ground and the curb, with known answers.
#include <gtest/gtest.h>

#include <cmath>

#include "scfloam/sim/world.hpp"

namespace scfloam::sim {
namespace {

World flat_world() {
  World w;
  w.terrain_m.reset(-100, -100, 4.0, 51, 51, 0.0f);
  w.road_edge_distance.reset(-100, -100, 0.5, 401, 401, 0.0f);
  // Road for x < 10, sidewalk (raised by the curb) beyond.
  for (int iy = 0; iy < 401; ++iy)
    for (int ix = 0; ix < 401; ++ix) w.road_edge_distance.at(ix, iy) = static_cast<float>(-100 + ix * 0.5 - 10);
  return w;
}

TEST(WorldCast, RotatedBoxFaceDistanceAndNormal) {
  World w = flat_world();
  // A box rotated by 30 deg; cast along its local -x axis toward its +x face.
  const double yaw = M_PI / 6;
  w.primitives.push_back(make_box(0, 0, yaw, 2, 1, 0, 10, SurfaceKind::building, 0.5f));
  w.build_index();
  const Eigen::Vector3d axis(std::cos(yaw), std::sin(yaw), 0);
  RayHit hit;
  ASSERT_TRUE(w.cast(axis * 8 + Eigen::Vector3d(0, 0, 1), -axis, 100, 1, &hit));
  EXPECT_NEAR(hit.range_m, 6.0, 1e-9);
  EXPECT_NEAR(hit.normal.dot(axis), 1.0, 1e-9);
  EXPECT_EQ(hit.kind, SurfaceKind::building);
}

TEST(WorldCast, CylinderSideAndTopCap) {
  World w = flat_world();
  w.primitives.push_back(make_cylinder(5, 0, 0.5, 0, 3, SurfaceKind::pole, 0.3f));
  w.build_index();
  RayHit hit;
  ASSERT_TRUE(w.cast(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::UnitX(), 100, 1, &hit));
  EXPECT_NEAR(hit.range_m, 4.5, 1e-9);
  EXPECT_EQ(hit.kind, SurfaceKind::pole);
  ASSERT_TRUE(w.cast(Eigen::Vector3d(5.2, 0, 10), -Eigen::Vector3d::UnitZ(), 100, 1, &hit));
  EXPECT_NEAR(hit.range_m, 7.0, 1e-9);
  EXPECT_NEAR(hit.normal.z(), 1.0, 1e-12);
}

TEST(WorldCast, FoliageIsPartlyPenetrated) {
  World w = flat_world();
  w.primitives.push_back(make_ellipsoid(6, 0, 5, 3, 2, SurfaceKind::vegetation, 0.5f, 1.0f));
  w.build_index();
  int hits = 0, deep = 0;
  for (std::uint64_t seed = 0; seed < 2000; ++seed) {
    RayHit hit;
    if (w.cast(Eigen::Vector3d(0, 0, 5), Eigen::Vector3d::UnitX(), 100, seed, &hit) &&
        hit.kind == SurfaceKind::vegetation) {
      ++hits;
      EXPECT_GE(hit.range_m, 3.0 - 1e-9);
      EXPECT_LE(hit.range_m, 9.0 + 1e-9);
      if (hit.range_m > 4.0) ++deep;
    }
  }
  // Chord 6 m, mean free path 1 m: P(cross) = e^-6, P(return deeper than 1 m) = e^-1.
  EXPECT_GT(hits, 1980);
  EXPECT_NEAR(deep / double(hits), std::exp(-1.0), 0.04);
}

TEST(WorldCast, GroundAndCurbFace) {
  World w = flat_world();
  w.build_index();
  RayHit hit;
  // 45 deg down from 2 m: the road 2 m ahead (x = 2 < 10).
  const Eigen::Vector3d down = Eigen::Vector3d(1, 0, -1).normalized();
  ASSERT_TRUE(w.cast(Eigen::Vector3d(0, 0, 2), down, 100, 1, &hit));
  EXPECT_NEAR(hit.range_m, 2 * std::sqrt(2.0), 1e-3);
  EXPECT_EQ(hit.kind, SurfaceKind::road);
  // Horizontal at 7 cm: the 15 cm curb face at x = 10.
  ASSERT_TRUE(w.cast(Eigen::Vector3d(0, 0, 0.07), Eigen::Vector3d::UnitX(), 100, 1, &hit));
  EXPECT_NEAR(hit.range_m, 10.0, 0.03);
  EXPECT_EQ(hit.kind, SurfaceKind::curb);
  EXPECT_NEAR(hit.normal.x(), -1.0, 1e-6);
  // A shallow ray lands on the raised sidewalk, at height 0.15.
  const Eigen::Vector3d shallow = Eigen::Vector3d(1, 0, -0.1).normalized();
  ASSERT_TRUE(w.cast(Eigen::Vector3d(0, 0, 1.5), shallow, 100, 1, &hit));
  EXPECT_NEAR(1.5 + hit.range_m * shallow.z(), 0.15, 0.01);
  EXPECT_EQ(hit.kind, SurfaceKind::sidewalk);
  // Straight up: sky, no return.
  EXPECT_FALSE(w.cast(Eigen::Vector3d(0, 0, 2), Eigen::Vector3d::UnitZ(), 100, 1, &hit));
}

TEST(WorldCast, NearestOfManyPrimitivesAcrossGridCells) {
  World w = flat_world();
  for (int k = 0; k < 20; ++k)
    w.primitives.push_back(make_box(10 + 7 * k, 3.0 * (k % 3) - 3, 0, 0.5, 0.5, 0, 5, SurfaceKind::wall, 0.3f));
  w.primitives.push_back(make_box(40, 0, 0, 0.5, 5, 0, 5, SurfaceKind::wall, 0.3f));
  w.build_index(4.0);
  RayHit hit;
  // Along y = 0 at 1 m: boxes with k % 3 == 1 (x = 17, 38, ...) block first.
  ASSERT_TRUE(w.cast(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::UnitX(), 200, 1, &hit));
  EXPECT_NEAR(hit.range_m, 16.5, 1e-9);
  // Along y = 1.5 nothing small is hit; the wide wall at x = 40 is.
  ASSERT_TRUE(w.cast(Eigen::Vector3d(0, 1.5, 1), Eigen::Vector3d::UnitX(), 200, 1, &hit));
  EXPECT_NEAR(hit.range_m, 39.5, 1e-9);
}

}  // namespace
}  // namespace scfloam::sim
