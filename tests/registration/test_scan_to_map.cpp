// Registration of a real KITTI scan against its own map from a known offset.
#include <gtest/gtest.h>

#include "scfloam/features/feature_extractor.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/registration/scan_to_map.hpp"
#include "scfloam/registration/voxel_filter.hpp"
#include "scfloam/se3.hpp"
#include "test_paths.hpp"

namespace scfloam {
namespace {

struct Features {
  FeatureCloud edges, planes;
};

Features features_of(const Scan& scan, const OdometryConfig& c) {
  FeatureExtractor extractor(c.preprocess, c.rings, c.features);
  FeatureCloud e, p;
  extractor.extract(scan.points, false, e, p);
  return {voxel_downsample(e, c.features.edge_leaf_m), voxel_downsample(p, c.features.plane_leaf_m)};
}

TEST(ScanToMap, RecoversAKnownMotionOfKitti05Frame0) {
  SCFLOAM_SHARED_DATA_OR_SKIP(dir, "kitti/scans/05");
  const auto seq = KittiSequence::open(dir);
  const OdometryConfig c;
  // Map: frame 0's full-density features (the map side of a match is dense in practice).
  FeatureExtractor extractor(c.preprocess, c.rings, c.features);
  FeatureCloud map_e, map_p;
  extractor.extract(seq.load(0).points, false, map_e, map_p);
  FeatureMap map(c.registration, c.map);
  map.insert(map_e, map_p, Eigen::Isometry3d::Identity());
  // Query: the same scan's downsampled features, registered from a start 0.3 m and 1 deg off.
  const Features f = features_of(seq.load(0), c);
  Eigen::Matrix<double, 6, 1> xi;
  xi << 0.0, 0.0, 1.0 * M_PI / 180, 0.3, -0.1, 0.05;
  const Eigen::Isometry3d T_init = left_perturb(xi, Eigen::Isometry3d::Identity());
  for (const double max_residual_m : {0.0, 0.1}) {
    SCOPED_TRACE(max_residual_m);
    RegistrationConfig rc = c.registration;
    rc.edge_max_residual_m = max_residual_m;
    const RegistrationResult r = register_features(f.edges, f.planes, map, T_init, rc, 12);
    EXPECT_LT(r.T_world_lidar.translation().norm(), 0.01);
    EXPECT_LT(rotation_angle_rad(r.T_world_lidar.linear()) * 180 / M_PI, 0.02);
    EXPECT_GT(r.plane_matches, 1000);
    // 8 neighbours (the default) must lie on one line within 1 m: 205 edges match here without
    // the residual cut, where F-LOAM's 5 matched over 300: the more neighbours, the stricter
    // the line test. The query edges are 0.4 m voxel centroids of edge points, and more than
    // half of them lie over 0.1 m from the line they find: 85 remain.
    EXPECT_GT(r.edge_matches, max_residual_m == 0 ? 150 : 60);
    EXPECT_FALSE(r.degenerate);
  }
}

TEST(ScanToMap, Kitti05FramePairMatchesGroundTruth) {
  SCFLOAM_SHARED_DATA_OR_SKIP(dir, "kitti/scans/05");
  const auto seq = KittiSequence::open(dir);
  const PoseList gt = seq.ground_truth_lidar();
  const OdometryConfig c;
  FeatureExtractor extractor(c.preprocess, c.rings, c.features);
  FeatureCloud map_e, map_p;
  extractor.extract(seq.load(4).points, false, map_e, map_p);
  FeatureMap map(c.registration, c.map);
  map.insert(map_e, map_p, gt[4]);
  const Features f = features_of(seq.load(5), c);
  const RegistrationResult r = register_features(f.edges, f.planes, map, gt[4], c.registration, 12);
  const Eigen::Isometry3d err = gt[5].inverse() * r.T_world_lidar;
  EXPECT_LT(err.translation().norm(), 0.05);
  EXPECT_LT(rotation_angle_rad(err.linear()) * 180 / M_PI, 0.1);
}

TEST(ScanToMap, FlatGroundOnlyIsDegenerate) {
  // A single plane constrains one translation direction: the solve must say so.
  FeatureCloud ground;
  for (int i = -20; i <= 20; ++i)
    for (int j = -20; j <= 20; ++j) ground.emplace_back(0.3f * i, 0.3f * j, -1.7f);
  const OdometryConfig c;
  FeatureMap map(c.registration, c.map);
  map.insert({}, ground, Eigen::Isometry3d::Identity());
  const RegistrationResult r =
      register_features({}, ground, map, Eigen::Isometry3d::Identity(), c.registration, 2);
  EXPECT_GT(r.plane_matches, 100);
  EXPECT_TRUE(r.degenerate);
  EXPECT_LT(std::abs(r.weakest_translation_dir.z()), 1e-6);
}

TEST(ScanToMap, PlaneSpreadRatioRejectsARingTraceButKeepsTheGround) {
  // A sparse sensor's ring crosses a far facade or a tree crown as one row of points: any plane
  // through the row fits it, so the match's normal is arbitrary. The ground is a true plane.
  FeatureCloud ground, traces;
  for (int i = -10; i <= 10; ++i)
    for (int j = -10; j <= 10; ++j) ground.emplace_back(0.3f * i, 0.3f * j, -1.7f);
  for (int row = 0; row < 4; ++row) {  // arcs of one ring's cone, 3 m apart in range
    const double r = 15.0 + 3.0 * row;
    for (int i = -20; i <= 20; ++i) {
      const double a = 0.3 * i / r;  // 0.3 m apart along the arc
      traces.emplace_back(static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)),
                          static_cast<float>(0.1 * r));
    }
  }
  FeatureCloud planes = ground;
  planes.insert(planes.end(), traces.begin(), traces.end());
  OdometryConfig c;
  c.map.plane_spacing_m = 0.0;  // keep every point: the neighbourhoods are the ones built here
  c.registration.knn = 5;       // the counts below are for five neighbours
  FeatureMap map(c.registration, c.map);
  map.insert({}, planes, Eigen::Isometry3d::Identity());
  auto plane_matches = [&](double ratio) {
    c.registration.plane_min_spread_ratio = ratio;
    return register_features({}, planes, map, Eigen::Isometry3d::Identity(), c.registration, 1)
        .plane_matches;
  };
  const int all = plane_matches(0.0), spread = plane_matches(0.2);
  // Off: the arcs match as planes too (all but their two end points, whose 4th neighbour is
  // farther than max_neighbor_dist_m).
  EXPECT_EQ(all, static_cast<int>(planes.size()) - 2 * 4);
  EXPECT_EQ(spread, static_cast<int>(ground.size()));  // on: only the ground does
}

TEST(ScanToMap, EdgeResidualCutRefusesAFarLineButKeepsANearOne) {
  // A trunk's face mapped from one side (a vertical line of points) and the scan's points on
  // its other face, 0.3 m away: within the search radius, so F-LOAM matches them to the line.
  FeatureCloud map_edges, near, far;
  for (int i = -10; i <= 10; ++i) {
    const float z = 0.1f * static_cast<float>(i);
    map_edges.emplace_back(5.0f, 0.0f, z);
    if (i > -5 && i < 5) {
      near.emplace_back(5.05f, 0.0f, z + 0.05f);
      far.emplace_back(5.3f, 0.0f, z + 0.05f);
    }
  }
  OdometryConfig c;
  c.map.edge_spacing_m = 0.0;  // keep every point: the neighbourhoods are the ones built here
  FeatureMap map(c.registration, c.map);
  map.insert(map_edges, {}, Eigen::Isometry3d::Identity());
  const auto edge_matches = [&](const FeatureCloud& queries, double max_residual_m) {
    c.registration.edge_max_residual_m = max_residual_m;
    ScanToMapRegistration registration(c.registration);
    return registration.count_matches(queries, {}, map, Eigen::Isometry3d::Identity()).first;
  };
  const int n = static_cast<int>(near.size());
  EXPECT_EQ(edge_matches(near, 0.0), n);
  EXPECT_EQ(edge_matches(near, 0.1), n);
  EXPECT_EQ(edge_matches(far, 0.0), n);  // F-LOAM's tests alone take the other face
  EXPECT_EQ(edge_matches(far, 0.1), 0);
  EXPECT_EQ(edge_matches(far, 0.35), n);
}

TEST(ScanToMap, ViewFilterMatchesALineOnlyFromAboutTheDirectionItWasSeenFrom) {
  // A vertical line of edge points at (5, 0), mapped once from the south (sensor at (5, -10):
  // a trunk's silhouette seen from there) and once from the west (the origin). The scan's
  // points on it are seen from the origin, looking east.
  FeatureCloud line_from_south, line_from_west, queries;
  for (int i = -10; i <= 10; ++i) {
    const float z = 0.1f * static_cast<float>(i);
    line_from_south.emplace_back(0.0f, 10.0f, z);  // in the southern sensor's frame
    line_from_west.emplace_back(5.0f, 0.0f, z);
    if (i > -5 && i < 5) queries.emplace_back(5.03f, 0.0f, z + 0.05f);
  }
  Eigen::Isometry3d south = Eigen::Isometry3d::Identity();
  south.translation() = Eigen::Vector3d(5, -10, 0);
  OdometryConfig c;
  const auto edge_matches = [&](bool seen_from_west, double view_tolerance_deg) {
    c.registration.edge_view_tolerance_deg = view_tolerance_deg;
    FeatureMap map(c.registration, c.map);
    if (seen_from_west) map.insert(line_from_west, {}, Eigen::Isometry3d::Identity());
    else map.insert(line_from_south, {}, south);
    ScanToMapRegistration registration(c.registration);
    return registration.count_matches(queries, {}, map, Eigen::Isometry3d::Identity()).first;
  };
  const int n = static_cast<int>(queries.size());
  EXPECT_EQ(edge_matches(false, 0.0), n);  // F-LOAM: any line within reach
  EXPECT_EQ(edge_matches(false, 20.0), 0);  // seen from 90 deg away: another silhouette
  EXPECT_EQ(edge_matches(false, 95.0), n);
  EXPECT_EQ(edge_matches(true, 20.0), n);
  EXPECT_EQ(edge_matches(true, 0.0), n);
}

TEST(ScanToMap, CountMatchesAtTheSolutionAreAlignsAndFollowTheFlatnessTest) {
  // A ground grid with a rough strip (every other row 0.25 m up): the strip's neighbourhoods
  // pass a 0.2 m flatness test and fail a 0.1 m one.
  FeatureCloud planes;
  for (int i = -10; i <= 10; ++i)
    for (int j = -10; j <= 10; ++j)
      planes.emplace_back(0.3f * i, 0.3f * j, (i > 3 && j % 2 == 0) ? -1.45f : -1.7f);
  OdometryConfig c;
  c.map.plane_spacing_m = 0.0;
  c.registration.knn = 5;  // the strip's neighbourhoods are built for five neighbours
  FeatureMap map(c.registration, c.map);
  map.insert({}, planes, Eigen::Isometry3d::Identity());
  const Eigen::Isometry3d T = Eigen::Isometry3d::Identity();  // the solution: align stays there
  for (const double flat_m : {0.2, 0.1}) {
    SCOPED_TRACE(flat_m);
    c.registration.plane_max_dist_m = flat_m;
    ScanToMapRegistration registration(c.registration);
    const auto [edges, plane_matches] = registration.count_matches({}, planes, map, T);
    EXPECT_EQ(edges, 0);
    EXPECT_EQ(plane_matches, register_features({}, planes, map, T, c.registration, 1).plane_matches);
    if (flat_m == 0.2) EXPECT_GT(plane_matches, static_cast<int>(planes.size()) * 9 / 10);
    else EXPECT_LT(plane_matches, static_cast<int>(planes.size()) * 3 / 4);
  }
}

}  // namespace
}  // namespace scfloam
