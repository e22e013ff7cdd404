#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <random>

#include "scfloam/features/deskew.hpp"
#include "scfloam/features/feature_extractor.hpp"
#include "scfloam/registration/voxel_filter.hpp"

namespace scfloam {
namespace {

TEST(Curvature, ZeroOnALineLargeAtACorner) {
  std::vector<Eigen::Vector3f> line, corner;
  for (int i = 0; i < 21; ++i) {
    line.emplace_back(0.1f * i, 5.f, 0.f);
    // An L: along x up to the middle, then along y.
    corner.emplace_back(i <= 10 ? 0.1f * i : 1.f, i <= 10 ? 0.f : 0.1f * (i - 10), 0.f);
  }
  std::vector<float> c_line(21), c_corner(21);
  ring_curvature(line.data(), 21, 5, c_line.data());
  ring_curvature(corner.data(), 21, 5, c_corner.data());
  for (int i = 5; i < 16; ++i) EXPECT_NEAR(c_line[i], 0.f, 1e-6f);
  // At the apex: sum of neighbours - 10 p = (-1.5, 1.5, 0) -> 4.5 m^2.
  EXPECT_NEAR(c_corner[10], 4.5f, 1e-4f);
  EXPECT_EQ(c_line[0], 0.f);  // ends without a full window
}

// Uneven spacing is not shape: a line with a dropped sample stays at zero curvature (F-LOAM's
// plain sum would give the gap's shift, here (0.1 x 4)^2 = 0.16 m^2 next to it, above its 0.1
// edge threshold), while a corner with a dropped sample still reads as a corner.
TEST(Curvature, ADroppedSampleOnALineIsNotCurvature) {
  std::vector<Eigen::Vector3f> line, corner;
  for (int i = 0; i < 22; ++i) {
    if (i == 12) continue;  // the dropped return
    line.emplace_back(0.1f * i, 30.f, -1.7f);
    corner.emplace_back(i <= 10 ? 0.1f * i : 1.f, i <= 10 ? 0.f : 0.1f * (i - 10), 0.f);
  }
  std::vector<float> c_line(21), c_corner(21);
  ring_curvature(line.data(), 21, 5, c_line.data());
  ring_curvature(corner.data(), 21, 5, c_corner.data());
  for (int i = 5; i < 16; ++i) EXPECT_NEAR(c_line[i], 0.f, 1e-5f) << i;
  EXPECT_GT(c_corner[10], 2.f);
}

// The vectorized curvature (four points at a time, scalar tail) against the definition in
// double, on a noisy ring far from the origin (90 m: where float sums of positions would lose
// centimetres), at every length around the vector width and window.
TEST(Curvature, MatchesTheDefinitionInDoubleAtAnyRingLength) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0, 0.02);
  for (int hw : {1, 3, 5}) {
    for (int n = 2 * hw; n <= 2 * hw + 13; ++n) {
      std::vector<Eigen::Vector3f> ring;
      for (int i = 0; i < n; ++i) {
        const double az = 0.003 * i;
        const double r = i % 7 == 3 ? 60.0 : 90.0;  // depth jumps: real corners
        ring.emplace_back(float(r * std::cos(az) + noise(rng)), float(r * std::sin(az) + noise(rng)),
                          float(-1.7 + noise(rng)));
      }
      std::vector<float> got(n, -1.f);
      ring_curvature(ring.data(), n, hw, got.data());
      for (int i = 0; i < n; ++i) {
        if (i < hw || i >= n - hw) {
          EXPECT_EQ(got[i], 0.f) << "n " << n << " i " << i;  // no full window
          continue;
        }
        Eigen::Vector3d left = Eigen::Vector3d::Zero(), right = Eigen::Vector3d::Zero();
        const Eigen::Vector3d pi = ring[i].cast<double>();
        for (int j = 1; j <= hw; ++j) {
          left += ring[i - j].cast<double>() - pi;
          right += ring[i + j].cast<double>() - pi;
        }
        Eigen::Vector3d d = left + right;
        const Eigen::Vector3d chord = right - left;
        d -= (d.dot(chord) / chord.squaredNorm()) * chord;
        const double want = d.squaredNorm();
        EXPECT_NEAR(got[i], want, 1e-4 * want + 1e-7) << "hw " << hw << " n " << n << " i " << i;
      }
    }
  }
}

LidarPoint ring_point(const Eigen::Vector3d& p, int ring) {
  LidarPoint lp;
  lp.x = float(p.x()), lp.y = float(p.y()), lp.z = float(p.z());
  lp.ring = static_cast<std::int16_t>(ring);
  return lp;
}

// Known answers from sorting, on values with many ties (zeros, as on exact lines) and without.
TEST(KthSmallest, EqualsTheSortedValueWithAndWithoutTies) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + static_cast<int>(rng() % 700);
    std::vector<float> v(static_cast<std::size_t>(n));
    std::exponential_distribution<float> e(1.0f);
    const unsigned distinct = trial % 3 == 0 ? 4u : 0u;  // a few distinct values, or all distinct
    for (float& x : v) x = distinct ? static_cast<float>(rng() % distinct) : e(rng);
    std::vector<float> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    const int k = static_cast<int>(rng() % static_cast<unsigned>(n));
    std::vector<float> work = v;
    ASSERT_EQ(kth_smallest(work.data(), n, k), sorted[static_cast<std::size_t>(k)]) << trial;
    std::sort(work.begin(), work.end());
    ASSERT_EQ(work, sorted) << "the values are only reordered";
  }
}

// A 64-beam scan of a room corner seen from inside: two walls meeting at a vertical edge.
std::vector<LidarPoint> corner_room_scan() {
  std::vector<LidarPoint> pts;
  for (int ring = 0; ring < 64; ++ring) {
    const double elev = (2.0 - ring * 0.4) * M_PI / 180.0;
    for (int col = 0; col < 1800; ++col) {
      const double az = col * 2 * M_PI / 1800;
      const Eigen::Vector3d dir(std::cos(elev) * std::cos(az), std::cos(elev) * std::sin(az),
                                std::sin(elev));
      // Walls x = 10 and y = 10 (first quadrant), far walls at -20 elsewhere.
      double t = 1e9;
      if (dir.x() > 1e-9) t = std::min(t, 10.0 / dir.x());
      if (dir.y() > 1e-9) t = std::min(t, 10.0 / dir.y());
      if (dir.x() < -1e-9) t = std::min(t, -20.0 / dir.x());
      if (dir.y() < -1e-9) t = std::min(t, -20.0 / dir.y());
      pts.push_back(ring_point(t * dir, ring));
    }
  }
  return pts;
}

TEST(FeatureExtractor, CornerSceneEdgesOnTheCornersPlanesOnTheWalls) {
  OdometryConfig c;
  c.preprocess.max_range_m = 100;
  c.preprocess.elevation_correction_deg = 0;  // the scene's exact geometry (next test: with it)
  FeatureExtractor extractor(c.preprocess, c.rings, c.features);
  FeatureCloud edges, planes;
  extractor.extract(corner_room_scan(), /*use_ring_field=*/true, edges, planes);
  EXPECT_EQ(extractor.stats().rings_used, 64);
  ASSERT_FALSE(edges.empty());
  ASSERT_GT(planes.size(), 50000u);
  // The room's four vertical corners are at (10,10), (-20,10), (-20,-20), (10,-20): every edge
  // lies within a few samples of one of them; plane points lie on the walls.
  const Eigen::Vector2f corners[4] = {{10, 10}, {-20, 10}, {-20, -20}, {10, -20}};
  for (const auto& e : edges) {
    float best = 1e9f;
    for (const auto& k : corners) best = std::min(best, (e.head<2>() - k).norm());
    EXPECT_LT(best, 0.5f) << e.transpose();
  }
  for (std::size_t i = 0; i < planes.size(); i += 97) {
    const auto& p = planes[i];
    const float to_wall = std::min({std::abs(p.x() - 10), std::abs(p.y() - 10),
                                    std::abs(p.x() + 20), std::abs(p.y() + 20)});
    EXPECT_LT(to_wall, 1e-3f);
  }
  // At most 20 edges per sector, 6 sectors, 64 rings.
  EXPECT_LE(edges.size(), 64u * 6u * 20u);
}

// The extractor's plane runs, summed ring by ring in its parallel pass, downsample to what the
// voxel filter makes of its plane cloud: the odometry's path equals the plain one.
TEST(FeatureExtractor, PlaneRunsDownsampleLikeTheFilterOfThePlanes) {
  OdometryConfig c;
  c.preprocess.max_range_m = 100;  // with the default elevation correction (applied before the runs)
  FeatureExtractor extractor(c.preprocess, c.rings, c.features);
  FeatureCloud edges, planes, by_runs, by_points, again;
  extractor.extract(corner_room_scan(), true, edges, planes);
  VoxelFilter filter;
  filter.filter_runs(extractor.plane_runs(), by_runs);
  by_points = voxel_downsample(planes, c.features.plane_leaf_m);
  ASSERT_GT(by_points.size(), 100u);
  ASSERT_EQ(by_runs.size(), by_points.size());
  for (std::size_t i = 0; i < by_runs.size(); ++i) ASSERT_LT((by_runs[i] - by_points[i]).norm(), 1e-4f) << i;
  // Without the plane cloud the runs are the same.
  FeatureCloud edges2;
  extractor.extract(corner_room_scan(), true, edges2, nullptr);
  EXPECT_EQ(edges2.size(), edges.size());
  filter.filter_runs(extractor.plane_runs(), again);
  ASSERT_EQ(again.size(), by_runs.size());
  for (std::size_t i = 0; i < again.size(); ++i) ASSERT_EQ(again[i], by_runs[i]) << i;
  // A scan whose rings are too short for features leaves no runs of the last scan behind.
  std::vector<LidarPoint> sparse = corner_room_scan();
  std::vector<LidarPoint> few;
  for (std::size_t i = 0; i < sparse.size(); i += 200) few.push_back(sparse[i]);  // 9 a ring
  extractor.extract(few, true, edges2, nullptr);
  for (const VoxelRuns& runs : extractor.plane_runs()) EXPECT_TRUE(runs.keys.empty() && runs.sums.empty());
  filter.filter_runs(extractor.plane_runs(), again);
  EXPECT_TRUE(again.empty());
}

// LOAM's occlusion test: where a near wall ends in front of a far one, the far wall's points
// next to the depth jump (on either side of the near wall) are never edges; without the test
// they are the strongest edges of their sector.
std::vector<LidarPoint> wall_behind_wall_scan() {
  std::vector<LidarPoint> pts;
  for (int ring = 0; ring < 64; ++ring) {
    const double elev = (1.0 - ring * 0.2) * M_PI / 180.0;  // near level: walls, no ground
    for (int k = 0; k < 450; ++k) {  // 0.2 deg steps over 90 deg
      const double az = k * 0.2 * M_PI / 180.0;
      const Eigen::Vector3d dir(std::cos(elev) * std::cos(az), std::cos(elev) * std::sin(az), std::sin(elev));
      const bool far = k >= 150 && k < 300;  // the near wall x = 10 has a gap from 30 to 60 deg
      pts.push_back(ring_point((far ? 30.0 : 10.0) / dir.x() * dir, ring));
    }
  }
  return pts;
}

int far_edges_next_to_the_jumps(bool reject_occluded) {
  OdometryConfig c;
  c.preprocess.max_range_m = 100;
  c.preprocess.elevation_correction_deg = 0;
  c.features.reject_occluded = reject_occluded;
  FeatureExtractor extractor(c.preprocess, c.rings, c.features);
  FeatureCloud edges, planes;
  extractor.extract(wall_behind_wall_scan(), /*use_ring_field=*/true, edges, planes);
  const int hw = c.features.curvature_half_window;
  int count = 0;
  for (const auto& e : edges) {
    if (std::abs(e.x() - 30.0f) > 0.01f) continue;  // not on the far wall
    const double az_deg = std::atan2(e.y(), e.x()) * 180.0 / M_PI;
    const double margin = (hw + 1) * 0.2 + 0.01;
    count += (az_deg - 30.0 < margin) || (60.0 - az_deg < margin);
  }
  return count;
}

TEST(FeatureExtractor, OcclusionTestKeepsEdgesOffTheFarSideOfADepthJump) {
  EXPECT_EQ(far_edges_next_to_the_jumps(true), 0);
  EXPECT_GE(far_edges_next_to_the_jumps(false), 64);  // at least one per ring without the test
}

// The elevation correction is applied to the selected features, after ring assignment and
// selection: the same features as without it, each rotated up in its own vertical plane.
TEST(FeatureExtractor, ElevationCorrectionRotatesTheSelectedFeaturesUp) {
  OdometryConfig c;
  c.preprocess.max_range_m = 100;
  c.preprocess.elevation_correction_deg = 0;
  FeatureExtractor plain(c.preprocess, c.rings, c.features);
  c.preprocess.elevation_correction_deg = 0.22;
  FeatureExtractor corrected(c.preprocess, c.rings, c.features);
  FeatureCloud e0, p0, e1, p1;
  plain.extract(corner_room_scan(), true, e0, p0);
  corrected.extract(corner_room_scan(), true, e1, p1);
  ASSERT_EQ(e0.size(), e1.size());
  ASSERT_EQ(p0.size(), p1.size());
  const double angle = 0.22 * M_PI / 180.0;
  for (std::size_t i = 0; i < p0.size(); i += 37) {
    const Eigen::Vector3d a = p0[i].cast<double>(), b = p1[i].cast<double>();
    // Same bearing and range, elevation up by the angle.
    EXPECT_NEAR(std::atan2(b.y(), b.x()), std::atan2(a.y(), a.x()), 1e-5);
    EXPECT_NEAR(b.norm(), a.norm(), 1e-4 * a.norm());
    const double up = std::atan2(b.z(), b.head<2>().norm()) - std::atan2(a.z(), a.head<2>().norm());
    EXPECT_NEAR(up, angle, 1e-5);
  }
  for (std::size_t i = 0; i < e0.size(); ++i) {
    const Eigen::Vector3d a = e0[i].cast<double>(), b = e1[i].cast<double>();
    EXPECT_NEAR(std::atan2(b.z(), b.head<2>().norm()) - std::atan2(a.z(), a.head<2>().norm()), angle, 1e-5);
  }
}

// Flat ground all around, seen with 2 cm range noise, and one vertical corner of two walls
// (x = 12 and y = 12, first quadrant) standing on it.
std::vector<LidarPoint> noisy_ground_and_corner_scan() {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<LidarPoint> pts;
  for (int ring = 0; ring < 64; ++ring) {
    const double elev = (ring <= 31 ? 2.0 - ring / 3.0 : -8.87 - (ring - 32) * 0.52) * M_PI / 180.0;
    for (int col = 0; col < 2000; ++col) {
      const double az = col * 2 * M_PI / 2000;
      const Eigen::Vector3d dir(std::cos(elev) * std::cos(az), std::cos(elev) * std::sin(az), std::sin(elev));
      double t = dir.z() < -1e-9 ? -1.73 / dir.z() : 1e9;  // the ground, 1.73 m below
      if (dir.x() > 1e-9 && dir.y() > 0) {
        const double tw = 12.0 / dir.x();
        if (tw * dir.y() <= 12.0) t = std::min(t, tw);
      }
      if (dir.y() > 1e-9 && dir.x() > 0) {
        const double tw = 12.0 / dir.y();
        if (tw * dir.x() <= 12.0) t = std::min(t, tw);
      }
      if (t > 80) continue;  // no return
      pts.push_back(ring_point((t + noise(rng)) * dir, ring));
    }
  }
  return pts;
}

// Range noise alone makes F-LOAM's curvature pass 0.1 on about one near ground point in ten;
// those "edges" follow the rings, so they move with the sensor. The ring-median noise floor
// (edge_noise_factor) removes them and keeps the corner.
TEST(FeatureExtractor, RangeNoiseOnFlatGroundMakesNoEdgesButTheCornerStays) {
  auto count = [](double factor, std::size_t* ground, std::size_t* at_corner) {
    OdometryConfig c;
    c.preprocess.elevation_correction_deg = 0;
    c.features.edge_noise_factor = factor;
    FeatureExtractor extractor(c.preprocess, c.rings, c.features);
    FeatureCloud edges, planes;
    extractor.extract(noisy_ground_and_corner_scan(), true, edges, planes);
    *ground = *at_corner = 0;
    for (const auto& e : edges) {
      if ((e.head<2>() - Eigen::Vector2f(12, 12)).norm() < 0.5f) ++*at_corner;
      else if (e.z() < -1.5f) ++*ground;
    }
  };
  std::size_t ground_plain, corner_plain, ground_floor, corner_floor;
  count(0.0, &ground_plain, &corner_plain);
  count(40.0, &ground_floor, &corner_floor);
  std::printf("ground edges %zu -> %zu, corner edges %zu -> %zu\n", ground_plain, ground_floor,
              corner_plain, corner_floor);
  EXPECT_GT(ground_plain, 1000u);              // without the floor: noise edges everywhere
  EXPECT_LT(ground_floor, ground_plain / 50);  // with it: almost none
  EXPECT_GE(corner_floor, 10u);                // the corner, seen by ~30 rings, stays
  EXPECT_GE(corner_floor, corner_plain / 2);
}

TEST(FeatureExtractor, RangeCropDropsNearFarAndNonFinitePoints) {
  OdometryConfig c;
  FeatureExtractor extractor(c.preprocess, c.rings, c.features);
  std::vector<LidarPoint> pts = corner_room_scan();
  pts[0].x = std::nanf("");
  pts[1].x = 1.0f, pts[1].y = 0.f, pts[1].z = 0.f;  // inside min range 3 m
  FeatureCloud edges, planes;
  extractor.extract(pts, true, edges, planes);
  for (const auto& p : planes) {
    ASSERT_TRUE(p.allFinite());
    const float r = p.head<2>().norm();
    EXPECT_GE(r, 3.f);
    EXPECT_LE(r, 90.f);
  }
  // The far walls beyond 90 m horizontal range cannot appear (corner at 28 m is kept).
  EXPECT_LT(extractor.stats().kept_points, extractor.stats().input_points);
}

TEST(FeatureExtractor, RingsFromElevationMatchRingField) {
  OdometryConfig c;
  c.rings.lidar = "hdl64";
  FeatureExtractor a(c.preprocess, c.rings, c.features), b(c.preprocess, c.rings, c.features);
  std::vector<LidarPoint> pts;
  for (int ring = 0; ring < 64; ++ring) {
    // Beam centres nudged 0.05 deg inwards: the table's ends (+2, -24.33) are exclusive.
    const double elev = (ring <= 32 ? 2.0 - ring / 3.0 : -8.83 - (ring - 32) * 0.5) + (ring == 63 ? 0.05 : -0.05);
    for (int col = 0; col < 1000; ++col) {
      const double az = col * 2 * M_PI / 1000, r = 20 + 3 * std::sin(5 * az);
      LidarPoint p;
      p.x = float(r * std::cos(elev * M_PI / 180) * std::cos(az));
      p.y = float(r * std::cos(elev * M_PI / 180) * std::sin(az));
      p.z = float(r * std::sin(elev * M_PI / 180));
      p.ring = static_cast<std::int16_t>(ring);
      pts.push_back(p);
    }
  }
  FeatureCloud e1, p1, e2, p2;
  a.extract(pts, false, e1, p1);
  b.extract(pts, true, e2, p2);
  EXPECT_EQ(e1.size(), e2.size());
  EXPECT_EQ(p1.size(), p2.size());
}

// Rings from elevation (four points at a time, scalar for a block's last few) against the ring
// field, with invalid points (NaN, inf, too near) at every lane position and an odd total: the
// same points survive and the same features come out, point for point.
TEST(FeatureExtractor, RingsFromElevationMatchRingFieldAroundInvalidPoints) {
  OdometryConfig c;
  c.rings.lidar = "hdl64";
  FeatureExtractor a(c.preprocess, c.rings, c.features), b(c.preprocess, c.rings, c.features);
  std::vector<LidarPoint> pts;
  int k = 0;
  for (int ring = 0; ring < 64; ++ring) {
    const double elev = (ring <= 32 ? 2.0 - ring / 3.0 : -8.83 - (ring - 32) * 0.5) + (ring == 63 ? 0.05 : -0.05);
    for (int col = 0; col < 997; ++col, ++k) {
      const double az = col * 2 * M_PI / 997, r = 20 + 3 * std::sin(5 * az) + (col % 50 == 7 ? 4 : 0);
      LidarPoint p;
      p.x = float(r * std::cos(elev * M_PI / 180) * std::cos(az));
      p.y = float(r * std::cos(elev * M_PI / 180) * std::sin(az));
      p.z = float(r * std::sin(elev * M_PI / 180));
      p.ring = static_cast<std::int16_t>(ring);
      if (k % 37 == 0) p.x = std::nanf("");
      if (k % 41 == 1) p.z = std::numeric_limits<float>::infinity();
      if (k % 43 == 2) p.y = -std::numeric_limits<float>::infinity();
      if (k % 47 == 3) p.x *= 0.05f, p.y *= 0.05f;  // inside the minimum range
      pts.push_back(p);
    }
  }
  for (int extra = 0; extra < 3; ++extra) pts.push_back(pts[pts.size() - 997]);  // a scalar tail
  ASSERT_NE(pts.size() % 4, 0u);
  FeatureCloud e1, p1, e2, p2;
  a.extract(pts, false, e1, p1);
  b.extract(pts, true, e2, p2);
  EXPECT_EQ(a.stats().kept_points, b.stats().kept_points);
  EXPECT_LT(a.stats().kept_points, static_cast<int>(pts.size()) * 95 / 100);  // invalid ones went
  ASSERT_EQ(e1.size(), e2.size());
  ASSERT_EQ(p1.size(), p2.size());
  for (std::size_t i = 0; i < e1.size(); ++i) EXPECT_EQ(e1[i], e2[i]) << i;
  for (std::size_t i = 0; i < p1.size(); ++i) ASSERT_EQ(p1[i], p2[i]) << i;
}

// correct_elevation (four points at a time, scalar tail) against the rotation in double: each
// point turns up by the angle in its own vertical plane; a point on the axis stays.
TEST(FeatureExtractor, ElevationCorrectionMatchesTheRotationInDouble) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-60, 60);
  FeatureCloud cloud;
  for (int i = 0; i < 4 * 25 + 3; ++i) cloud.emplace_back(float(u(rng)), float(u(rng)), float(u(rng) / 10));
  cloud[5] = Eigen::Vector3f(0, 0, 2);  // on the axis, in a vector lane
  FeatureCloud corrected = cloud;
  correct_elevation(corrected, 0.22);
  const double a = 0.22 * M_PI / 180;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = cloud[i].cast<double>();
    const double h = p.head<2>().norm();
    Eigen::Vector3d want = p;
    if (h >= 1e-3) {
      const double nh = h * std::cos(a) - p.z() * std::sin(a);
      want << p.x() * nh / h, p.y() * nh / h, p.z() * std::cos(a) + h * std::sin(a);
    }
    EXPECT_LT((corrected[i].cast<double>() - want).norm(), 2e-5) << i;
  }
}

TEST(Deskew, ConstantVelocityMovesPointsToTheReferenceTime) {
  std::vector<LidarPoint> pts(1);
  pts[0].x = 10, pts[0].y = 0, pts[0].z = 0, pts[0].time_s = 0.05f;
  // Moving forward at 10 m/s: a point seen 0.05 s later was measured 0.5 m further along.
  deskew_constant_velocity(pts, Eigen::Vector3d::Zero(), Eigen::Vector3d(10, 0, 0));
  EXPECT_NEAR(pts[0].x, 10.5f, 1e-5f);
  // Yawing at 1 rad/s: rotate by 0.05 rad.
  pts[0].x = 10, pts[0].y = 0;
  deskew_constant_velocity(pts, Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::Zero());
  EXPECT_NEAR(pts[0].x, 10 * std::cos(0.05), 1e-4);
  EXPECT_NEAR(pts[0].y, 10 * std::sin(0.05), 3e-4);  // third-order term |wt|^3 / 6 * range
}

TEST(Deskew, AReferenceTimeIsWherePointsAreMovedTo) {
  // A sweep stamped at its start (times 0 ... 0.1 s) solved at its middle: a point seen at
  // 0.08 s is 0.03 s after the reference, 0.3 m further along at 10 m/s.
  std::vector<LidarPoint> pts(1);
  pts[0].x = 10, pts[0].y = 0, pts[0].z = 0, pts[0].time_s = 0.08f;
  deskew_constant_velocity(pts, Eigen::Vector3d::Zero(), Eigen::Vector3d(10, 0, 0), 0.05);
  EXPECT_NEAR(pts[0].x, 10.3f, 1e-5f);
  EXPECT_EQ(pts[0].time_s, 0.08f);  // times stay relative to the stamp
  // The same as times counted from the reference, turning as well.
  std::vector<LidarPoint> a(2), b(2);
  a[0].x = 4, a[0].y = -7, a[0].z = 1, a[0].time_s = 0.01f;
  a[1].x = -20, a[1].y = 3, a[1].z = -1.5f, a[1].time_s = 0.097f;
  for (int i = 0; i < 2; ++i) b[i] = a[i], b[i].time_s -= 0.05f;
  const Eigen::Vector3d w(0.01, -0.02, 0.6), v(8, 0.3, -0.1);
  deskew_constant_velocity(a, w, v, 0.05);
  deskew_constant_velocity(b, w, v);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(a[i].x, b[i].x, 1e-5f) << i;
    EXPECT_NEAR(a[i].y, b[i].y, 1e-5f) << i;
    EXPECT_NEAR(a[i].z, b[i].z, 1e-5f) << i;
  }
}

}  // namespace
}  // namespace scfloam
