// Facade detail: the same wall cast with plain boxes and with windows, ledges and glass.
#include <gtest/gtest.h>

#include <cmath>

#include "scfloam/sim/world.hpp"

namespace scfloam::sim {
namespace {

// A 40 m wide, 20 m tall building whose front face is the plane x = 20 (facing -x), seen
// from a sensor at the origin 1.7 m up; rays on a grid of azimuths and elevations.
struct WallScan {
  int rays = 0, returns = 0, on_plane = 0, recessed = 0, in_front = 0, deep = 0;
  double max_recess_m = 0, max_front_m = 0;
};

WallScan scan_wall(bool detail, std::uint32_t building_index) {
  World w;
  w.terrain_m.reset(-100, -100, 4.0, 51, 51, 0.0f);
  w.road_edge_distance.reset(-100, -100, 1.0, 201, 201, -5.0f);
  for (std::uint32_t i = 0; i < building_index; ++i)  // filler so the wall gets this index
    w.primitives.push_back(make_box(-90, -90, 0, 0.1, 0.1, 0, 0.1, SurfaceKind::pole, 0.3f));
  w.primitives.push_back(make_box(28, 0, 0, 8, 20, -3, 20, SurfaceKind::building, 0.4f));
  w.facade_detail = detail;
  w.build_index();
  WallScan out;
  const Eigen::Vector3d origin(0, 0, 1.7);
  for (double az = -0.6; az <= 0.6; az += 0.004)
    for (double el = -0.05; el <= 0.6; el += 0.004) {
      const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      const double t_plane = 20 / d.x();
      const Eigen::Vector3d p = origin + t_plane * d;
      if (std::abs(p.y()) > 19 || p.z() < 0.2 || p.z() > 19) continue;  // stay on the face
      ++out.rays;
      RayHit hit;
      const std::uint64_t seed = static_cast<std::uint64_t>((az + 1) * 1e6) * 7919 + static_cast<std::uint64_t>((el + 1) * 1e6);
      if (!w.cast(origin, d, 120, seed, &hit)) continue;
      ++out.returns;
      const double depth_m = (hit.range_m - t_plane) * d.x();  // behind the face plane
      if (std::abs(depth_m) < 1e-6) ++out.on_plane;
      else if (depth_m > 0 && depth_m <= 0.31) ++out.recessed, out.max_recess_m = std::max(out.max_recess_m, depth_m);
      else if (depth_m < 0) ++out.in_front, out.max_front_m = std::max(out.max_front_m, -depth_m);
      else ++out.deep;  // through glass into the room
      RayHit again;
      EXPECT_TRUE(w.cast(origin, d, 120, seed, &again));
      EXPECT_EQ(again.range_m, hit.range_m);  // the same ray always sees the same thing
    }
  return out;
}

TEST(FacadeDetail, PlainWallIsOnePlane) {
  const WallScan s = scan_wall(false, 0);
  ASSERT_GT(s.rays, 10000);
  EXPECT_EQ(s.returns, s.rays);
  EXPECT_EQ(s.on_plane, s.rays);
}

TEST(FacadeDetail, WindowsRecessLedgesStandOutGlassLosesReturns) {
  // Over several buildings' styles: recesses up to 30 cm, ledges up to 25 cm out, panes
  // that return nothing or return from inside, and most of the wall still the plane.
  int styles_with_windows = 0, styles_with_ledges = 0;
  for (std::uint32_t index = 0; index < 12; ++index) {
    const WallScan s = scan_wall(true, index);
    EXPECT_LE(s.returns, s.rays);
    EXPECT_LE(s.max_recess_m, 0.31);
    EXPECT_LE(s.max_front_m, 0.26);
    EXPECT_GT(s.on_plane, 0.1 * s.rays);  // curtain walls are mostly glass
    if (s.recessed > 0.05 * s.rays && s.returns < s.rays && s.deep > 0) ++styles_with_windows;
    if (s.in_front > 0.01 * s.rays) ++styles_with_ledges;
  }
  EXPECT_GE(styles_with_windows, 6);
  EXPECT_GE(styles_with_ledges, 2);
}

}  // namespace
}  // namespace scfloam::sim
