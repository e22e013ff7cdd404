// The registration's basin in steady state: a sudden change of motion (a jolt, a turn taken
// harder than the constant-velocity model predicts) leaves the prediction a few degrees off.
// The odometry's per-frame rounds must still pull the pose back, or the error stays in the
// map for good (KITTI-00's replay lost 16 deg in one turn this way, docs/odometry.md).
#include <gtest/gtest.h>

#include "scfloam/features/feature_extractor.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/registration/scan_to_map.hpp"
#include "scfloam/registration/voxel_filter.hpp"
#include "scfloam/se3.hpp"
#include "test_paths.hpp"

namespace scfloam {
namespace {

// Frame 5 of the real KITTI-05 scans against a map of frames 0-4 (ground-truth poses), from a
// start off by `yaw_deg` about the vertical and `forward_m` along the heading, with the
// steady-state number of rounds (not the first frame's 12).
Eigen::Isometry3d error_after_registration(const std::filesystem::path& dir, double yaw_deg,
                                          double forward_m) {
  const auto seq = KittiSequence::open(dir);
  const PoseList gt = seq.ground_truth_lidar();
  const OdometryConfig c;
  FeatureExtractor extractor(c.preprocess, c.rings, c.features);
  FeatureMap map(c.registration, c.map);
  for (std::size_t i = 0; i < 5; ++i) {
    FeatureCloud e, p;
    extractor.extract(seq.load(i).points, false, e, p);
    map.insert(e, p, gt[i]);
  }
  FeatureCloud e, p;
  extractor.extract(seq.load(5).points, false, e, p);
  const FeatureCloud edges = voxel_downsample(e, c.features.edge_leaf_m);
  const FeatureCloud planes = voxel_downsample(p, c.features.plane_leaf_m);
  Eigen::Matrix<double, 6, 1> xi;  // in the lidar frame: z up, x forward
  xi << 0.0, 0.0, yaw_deg * M_PI / 180, forward_m, 0.0, 0.0;
  const Eigen::Isometry3d T_init = gt[5] * left_perturb(xi, Eigen::Isometry3d::Identity());
  const RegistrationResult r = register_features(edges, planes, map, T_init, c.registration,
                                                 c.registration.outer_iterations);
  return gt[5].inverse() * r.T_world_lidar;
}

TEST(RegistrationBasin, SteadyStateRoundsRecoverATwoDegreeJolt) {
  SCFLOAM_SHARED_DATA_OR_SKIP(dir, "kitti/scans/05");
  const Eigen::Isometry3d err = error_after_registration(dir, 2.0, 0.25);
  EXPECT_LT(err.translation().norm(), 0.05);
  EXPECT_LT(rotation_angle_rad(err.linear()) * 180 / M_PI, 0.1);
}

TEST(RegistrationBasin, SteadyStateRoundsRecoverAJoltTheOtherWay) {
  SCFLOAM_SHARED_DATA_OR_SKIP(dir, "kitti/scans/05");
  const Eigen::Isometry3d err = error_after_registration(dir, -2.0, -0.25);
  EXPECT_LT(err.translation().norm(), 0.05);
  EXPECT_LT(rotation_angle_rad(err.linear()) * 180 / M_PI, 0.1);
}

}  // namespace
}  // namespace scfloam
