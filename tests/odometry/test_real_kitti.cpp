// Real KITTI HDL-64E frames: frame-to-frame motion against the ground truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scfloam/io/kitti.hpp"
#include "scfloam/odometry/odometry.hpp"
#include "scfloam/se3.hpp"
#include "test_paths.hpp"

namespace scfloam {
namespace {

struct FrameErrors {
  double max_translation_m = 0;
  double max_rotation_deg = 0;
};

FrameErrors run_sequence(const std::filesystem::path& dir) {
  const auto seq = KittiSequence::open(dir);
  const PoseList gt = seq.ground_truth_lidar();
  EXPECT_EQ(gt.size(), seq.size());
  Odometry odometry{OdometryConfig{}};
  PoseList est;
  for (std::size_t i = 0; i < seq.size(); ++i) est.push_back(odometry.process(seq.load(i)).T_world_lidar);
  FrameErrors e;
  for (std::size_t i = 1; i < seq.size(); ++i) {
    const Eigen::Isometry3d d_gt = gt[i - 1].inverse() * gt[i];
    const Eigen::Isometry3d d_est = est[i - 1].inverse() * est[i];
    const Eigen::Isometry3d err = d_gt.inverse() * d_est;
    const double t = err.translation().norm();
    const double r = rotation_angle_rad(err.linear()) * 180.0 / M_PI;
    const Eigen::Vector3d tg = d_gt.translation(), te = d_est.translation();
    std::printf("  %s frame %zu: t_gt (%.3f %.3f %.3f) t_est (%.3f %.3f %.3f), t_err %.4f m, r_err %.4f deg\n",
                dir.filename().c_str(), i, tg.x(), tg.y(), tg.z(), te.x(), te.y(), te.z(), t, r);
    e.max_translation_m = std::max(e.max_translation_m, t);
    e.max_rotation_deg = std::max(e.max_rotation_deg, r);
  }
  return e;
}

TEST(RealKitti, Sequence05FrameToFrameWithin5cmAnd0p1deg) {
  SCFLOAM_SHARED_DATA_OR_SKIP(dir, "kitti/scans/05");
  const FrameErrors e = run_sequence(dir);
  EXPECT_LE(e.max_translation_m, 0.05);
  EXPECT_LE(e.max_rotation_deg, 0.1);
}

TEST(RealKitti, Sequence08FrameToFrameWithin5cmAnd0p1deg) {
  SCFLOAM_SHARED_DATA_OR_SKIP(dir, "kitti/scans/08");
  const FrameErrors e = run_sequence(dir);
  EXPECT_LE(e.max_translation_m, 0.05);
  EXPECT_LE(e.max_rotation_deg, 0.1);
}

// 00's first frames carry a known ground-truth offset: report the errors, bound them loosely.
TEST(RealKitti, Sequence00ReportedOnly) {
  SCFLOAM_SHARED_DATA_OR_SKIP(dir, "kitti/scans/00");
  const FrameErrors e = run_sequence(dir);
  std::printf("  00: max t_err %.4f m, max r_err %.4f deg (ground truth offset known)\n",
              e.max_translation_m, e.max_rotation_deg);
  EXPECT_LE(e.max_translation_m, 0.5);
}

}  // namespace
}  // namespace scfloam
