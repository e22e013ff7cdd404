// Scans with nothing usable (empty, a handful of points, all NaN) in the middle of a real
// drive: no crash, no NaN, the motion model's prediction is the pose, the frame is reported
// degenerate, and registration recovers when real scans return.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "scfloam/io/kitti.hpp"
#include "scfloam/odometry/odometry.hpp"
#include "scfloam/se3.hpp"
#include "test_paths.hpp"

namespace scfloam {
namespace {

bool finite(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

std::vector<Scan> bad_scans() {
  std::vector<Scan> out(3);
  for (int i = 0; i < 7; ++i) out[1].points.push_back(LidarPoint{1.0f * i + 5, 2, 0, 0, 0, 0});
  const float nan = std::numeric_limits<float>::quiet_NaN();
  out[2].points.assign(1000, LidarPoint{nan, nan, nan, 0, 0, 0});
  return out;
}

TEST(BadScans, FirstFramesWithoutPointsGiveFiniteIdentityPoses) {
  Odometry odometry{OdometryConfig{}};
  for (const Scan& scan : bad_scans()) {
    const OdometryResult r = odometry.process(scan);
    EXPECT_TRUE(finite(r.T_world_lidar));
    EXPECT_TRUE(r.T_world_lidar.isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  }
}

TEST(BadScans, GapInARealDriveKeepsThePredictionAndRecovers) {
  SCFLOAM_SHARED_DATA_OR_SKIP(dir, "kitti/scans/05");
  const auto seq = KittiSequence::open(dir);
  const PoseList gt = seq.ground_truth_lidar();
  Odometry odometry{OdometryConfig{}};
  PoseList est;
  for (std::size_t i = 0; i < 3; ++i) est.push_back(odometry.process(seq.load(i)).T_world_lidar);
  // Frames 3, 4, 5 are lost (empty, 7 points, all NaN): each pose is the constant-velocity
  // extrapolation of the last.
  const Eigen::Isometry3d delta = est[1].inverse() * est[2];
  for (const Scan& scan : bad_scans()) {
    const OdometryResult r = odometry.process(scan);
    EXPECT_TRUE(finite(r.T_world_lidar));
    EXPECT_TRUE(r.degenerate);
    EXPECT_EQ(r.weak_directions, 6);
    EXPECT_TRUE(r.T_world_lidar.isApprox(est.back() * delta, 1e-9));
    est.push_back(r.T_world_lidar);
  }
  // Real scans again: frame 6 registers against the map of frames 0-2 from the prediction.
  for (std::size_t i = 6; i < seq.size(); ++i) {
    const OdometryResult r = odometry.process(seq.load(i));
    EXPECT_FALSE(r.degenerate) << "frame " << i;
    const Eigen::Isometry3d err = (gt[2].inverse() * gt[i]).inverse() * (est[2].inverse() * r.T_world_lidar);
    EXPECT_LT(err.translation().norm(), 0.1) << "frame " << i;
    EXPECT_LT(rotation_angle_rad(err.linear()) * 180 / M_PI, 0.2) << "frame " << i;
  }
}

}  // namespace
}  // namespace scfloam
