// The KITTI devkit metric against hand-computed cases.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "scfloam/error.hpp"
#include "scfloam/eval/kitti_metric.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

// A straight drive along +z (KITTI camera forward) at step_m per frame.
PoseList straight_path(std::size_t frames, double step_m) {
  PoseList poses;
  for (std::size_t i = 0; i < frames; ++i) {
    Pose T = Pose::Identity();
    T.translation() = Eigen::Vector3d(0, 0, step_m * static_cast<double>(i));
    poses.push_back(T);
  }
  return poses;
}

// A gently curving drive: yaw (about camera y) changes by yaw_rate_rad per frame, 1 m per frame.
PoseList curved_path(std::size_t frames, double yaw_rate_rad) {
  PoseList poses;
  Pose T = Pose::Identity();
  Pose step = Pose::Identity();
  step.linear() = so3_exp(Eigen::Vector3d(0, yaw_rate_rad, 0));
  step.translation() = Eigen::Vector3d(0, 0, 1.0);
  for (std::size_t i = 0; i < frames; ++i) {
    poses.push_back(T);
    T = T * step;
  }
  return poses;
}

TEST(KittiMetric, IdentityGivesZero) {
  const PoseList gt = curved_path(1200, 0.002);
  const KittiMetric m = kitti_metric(gt, gt);
  ASSERT_GT(m.segments, 0u);
  EXPECT_NEAR(m.t_err_pct, 0.0, 1e-9);
  EXPECT_NEAR(m.r_err_deg_per_100m, 0.0, 1e-9);
  for (const auto& pl : m.per_length) EXPECT_GT(pl.segments, 0u) << pl.length_m;
}

TEST(KittiMetric, OnePercentScaleErrorGivesOnePercent) {
  const PoseList gt = curved_path(1200, 0.003);
  PoseList est = gt;
  for (auto& T : est) T.translation() *= 1.01;
  const KittiMetric m = kitti_metric(gt, est);
  // Relative motions are scaled by 1.01 in translation, unchanged in rotation, so
  // E = delta_est^-1 delta_gt has ||t(E)|| = 0.01 ||t(delta_gt)|| (the chord of the segment).
  EXPECT_NEAR(m.r_err_deg_per_100m, 0.0, 1e-9);
  EXPECT_GT(m.t_err_pct, 0.9);  // long segments of the curve have chords well under their length
  EXPECT_LT(m.t_err_pct, 1.01);
  for (const auto& s : m.segment_errors) {
    const double chord_m = (gt[s.last_frame].translation() - gt[s.first_frame].translation()).norm();
    EXPECT_NEAR(s.t_err_ratio, 0.01 * chord_m / s.length_m, 1e-12);
  }

  const PoseList line = straight_path(1000, 1.0);
  PoseList line_est = line;
  for (auto& T : line_est) T.translation() *= 1.01;
  const KittiMetric ml = kitti_metric(line, line_est);
  // Segment first->last covers (last - first) m where last is the first frame past `len`,
  // i.e. len + 1 m: t_err = 0.01 * (len + 1) / len for each length.
  double expected = 0;
  std::size_t count = 0;
  for (double len : kKittiSegmentLengthsM) {
    const std::size_t n = ml.per_length[count].segments;
    EXPECT_NEAR(ml.per_length[count].t_err_pct, 100 * 0.01 * (len + 1) / len, 1e-9);
    expected += n * 100 * 0.01 * (len + 1) / len;
    ++count;
  }
  EXPECT_NEAR(ml.t_err_pct, expected / static_cast<double>(ml.segments), 1e-9);
}

TEST(KittiMetric, ConstantYawRateErrorGivesExpectedRotationError) {
  // gt straight at 1 m/frame; the estimate turns by an extra 0.001 rad each frame but keeps
  // the translations of each step. E's rotation over a segment of k frames is k * 0.001 rad
  // (all rotations about one axis), so r_err = k * 0.001 / len with k = len + 1.
  const double rate_rad = 0.001;
  const PoseList gt = straight_path(1000, 1.0);
  PoseList est;
  Pose T = Pose::Identity();
  Pose step = Pose::Identity();
  step.linear() = so3_exp(Eigen::Vector3d(0, rate_rad, 0));
  step.translation() = Eigen::Vector3d(0, 0, 1.0);
  for (std::size_t i = 0; i < gt.size(); ++i) {
    est.push_back(T);
    T = T * step;
  }
  const KittiMetric m = kitti_metric(gt, est);
  for (const auto& pl : m.per_length) {
    const double expected_deg_per_100m = 100.0 * (pl.length_m + 1) * rate_rad / pl.length_m * 180.0 / M_PI;
    EXPECT_NEAR(pl.r_err_deg_per_100m, expected_deg_per_100m, 1e-9) << pl.length_m;
  }
  for (const auto& s : m.segment_errors) {
    const double k = static_cast<double>(s.last_frame - s.first_frame);
    EXPECT_NEAR(s.r_err_rad_per_m, k * rate_rad / s.length_m, 1e-12);
  }
}

TEST(KittiMetric, SegmentSelectionFollowsTheDevkit) {
  // Hand-made distances: strictly greater than first + length, first frame counts.
  const std::vector<double> dist = {0, 40, 100, 100.5, 150, 220, 260};
  EXPECT_EQ(last_frame_from_segment_length(dist, 0, 100), 3);  // 100 is not > 100
  EXPECT_EQ(last_frame_from_segment_length(dist, 0, 200), 5);
  EXPECT_EQ(last_frame_from_segment_length(dist, 1, 100), 4);  // 150 > 140
  EXPECT_EQ(last_frame_from_segment_length(dist, 2, 200), -1); // needs > 300
  EXPECT_EQ(last_frame_from_segment_length(dist, 7, 100), -1); // beyond the end

  const PoseList poses = straight_path(4, 2.0);
  const auto d = trajectory_distances_m(poses);
  ASSERT_EQ(d.size(), 4u);
  EXPECT_DOUBLE_EQ(d[0], 0.0);
  EXPECT_DOUBLE_EQ(d[3], 6.0);

  // 1 m per frame, 250 frames (249 m): first frames 0, 10, ..., 240. 100 m segments exist for
  // first <= 148 (need a frame > first + 100 within 249): first in {0..140} -> 15 segments;
  // 200 m segments for first <= 48: {0..40} -> 5; no 300 m segments.
  const KittiMetric m = kitti_metric(straight_path(250, 1.0), straight_path(250, 1.0));
  EXPECT_EQ(m.per_length[0].segments, 15u);
  EXPECT_EQ(m.per_length[1].segments, 5u);
  EXPECT_EQ(m.per_length[2].segments, 0u);
  EXPECT_TRUE(std::isnan(m.per_length[2].t_err_pct));
  EXPECT_EQ(m.segments, 20u);
  ASSERT_FALSE(m.segment_errors.empty());
  EXPECT_EQ(m.segment_errors.front().first_frame, 0u);
  EXPECT_EQ(m.segment_errors.front().last_frame, 101u);
}

TEST(KittiMetric, ShortPathHasNoSegments) {
  const PoseList gt = straight_path(90, 1.0);  // 89 m
  const KittiMetric m = kitti_metric(gt, gt);
  EXPECT_EQ(m.segments, 0u);
  EXPECT_FALSE(m.has_segments());
  EXPECT_TRUE(std::isnan(m.t_err_pct));
  EXPECT_TRUE(std::isnan(m.r_err_deg_per_100m));
  EXPECT_NE(m.note.find("shorter than"), std::string::npos) << m.note;
  EXPECT_NEAR(m.path_length_m, 89.0, 1e-9);
}

TEST(KittiMetric, MismatchedLengthsThrow) {
  try {
    kitti_metric(straight_path(10, 1.0), straight_path(9, 1.0));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("10"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("9"), std::string::npos);
  }
}

}  // namespace
}  // namespace scfloam

namespace scfloam {
namespace {

TEST(KittiMetric, ConvertingBothTrajectoriesToCameraKeepsRotationError) {
  // E' = Tr E Tr^-1 for both converted: same rotation angle per segment; translation differs
  // by the lever arm (I - R(E)) t_Tr, and a segment's end may move by a frame because distances
  // are measured along the camera's path instead of the lidar's. Both effects are tiny.
  PoseList gt, est;
  Pose T = Pose::Identity(), U = Pose::Identity();
  for (int i = 0; i < 600; ++i) {
    gt.push_back(T);
    est.push_back(U);
    Pose step = Pose::Identity();
    step.linear() = so3_exp(Eigen::Vector3d(0, 0, 0.004 * std::sin(0.01 * i)));  // lidar z up
    step.translation() = Eigen::Vector3d(1.0, 0, 0);                             // x forward
    T = T * step;
    Pose est_step = step;
    est_step.linear() = so3_exp(Eigen::Vector3d(0.0002, 0, 0.0005)) * step.linear();
    est_step.translation() *= 1.01;
    U = U * est_step;
  }
  const KittiMetric lidar = kitti_metric(gt, est);
  const KittiMetric camera =
      kitti_metric(lidar_to_camera_poses(gt, kitti_default_Tr()), lidar_to_camera_poses(est, kitti_default_Tr()));
  EXPECT_NEAR(camera.r_err_deg_per_100m, lidar.r_err_deg_per_100m, 0.01 * lidar.r_err_deg_per_100m);
  EXPECT_NEAR(camera.t_err_pct, lidar.t_err_pct, 0.01 * lidar.t_err_pct);
  // Mixing conventions is not a small change: lidar estimate against camera ground truth.
  const KittiMetric mixed = kitti_metric(lidar_to_camera_poses(gt, kitti_default_Tr()), est);
  EXPECT_GT(mixed.t_err_pct, 100.0);  // forward (z) compared with forward (x): ~141 %
}

}  // namespace
}  // namespace scfloam

namespace scfloam {
namespace {

// A climb of 1 cm per metre driven added to the estimate (its rotations exact): every segment's
// error is vertical, 1 % of the distance driven in it; a 1 % scale across the plane of motion
// is horizontal. The split does not depend on how the world is turned.
TEST(KittiMetricSplit, VerticalAndHorizontalErrorsAlongTheGroundTruthsUp) {
  Pose turn = Pose::Identity();
  turn.linear() = so3_exp(Eigen::Vector3d(0.4, -0.9, 0.3));
  for (const bool turned : {false, true}) {
    PoseList gt = curved_path(1200, 0.003);  // KITTI camera axes: up is -y
    const std::vector<double> dist = trajectory_distances_m(gt);
    PoseList climb = gt, wide = gt;
    for (std::size_t i = 0; i < gt.size(); ++i) {
      climb[i].translation().y() -= 0.01 * dist[i];
      wide[i].translation().x() *= 1.01;
      wide[i].translation().z() *= 1.01;
    }
    if (turned)
      for (PoseList* list : {&gt, &climb, &wide})
        for (Pose& T : *list) T = turn * T;
    const std::optional<Eigen::Vector3d> up = ground_truth_up(gt);
    ASSERT_TRUE(up.has_value());
    const Eigen::Matrix3d R = turned ? Eigen::Matrix3d(turn.linear()) : Eigen::Matrix3d::Identity();
    EXPECT_NEAR(std::abs(up->dot(R * Eigen::Vector3d::UnitY())), 1.0, 1e-9);

    const KittiMetric v = kitti_metric(gt, climb);
    ASSERT_GT(v.segments, 0u);
    for (const auto& s : v.segment_errors) {
      EXPECT_NEAR(s.vertical_ratio, 0.01 * (dist[s.last_frame] - dist[s.first_frame]) / s.length_m, 1e-9);
      EXPECT_NEAR(s.horizontal_ratio, 0.0, 1e-9);
    }
    EXPECT_NEAR(v.t_err_vertical_pct, v.t_err_pct, 1e-9);
    EXPECT_GT(v.t_err_vertical_pct, 1.0);  // segments run a frame past their length
    EXPECT_NEAR(v.t_err_horizontal_pct, 0.0, 1e-9);

    const KittiMetric h = kitti_metric(gt, wide);
    for (const auto& s : h.segment_errors) {
      EXPECT_NEAR(s.vertical_ratio, 0.0, 1e-9);
      EXPECT_NEAR(s.horizontal_ratio, s.t_err_ratio, 1e-9);
    }
    EXPECT_NEAR(h.t_err_horizontal_pct, h.t_err_pct, 1e-9);
    EXPECT_GT(h.t_err_horizontal_pct, 0.9);
  }
}

TEST(KittiMetricSplit, ARotationErrorIsSplitInTheWorldsAxes) {
  // The estimate pitched by theta about camera 0's x at every pose of a level drive:
  // t(delta_est) = Q^T t(delta_gt), so the error d = (I - Q^T) t(delta_gt) has |t_z| sin(theta)
  // along up (y) and |t_z| (1 - cos(theta)) across it, in the first frame's axes, which a yaw
  // leaves. Turning t(E) by the wrong pose (the last instead of first * delta_est) misses the
  // horizontal part by ~1e-5 per segment.
  const double theta = 0.01;
  const PoseList gt = curved_path(1200, 0.003);
  PoseList est = gt;
  Pose Q = Pose::Identity();
  Q.linear() = so3_exp(Eigen::Vector3d(theta, 0, 0));
  for (Pose& T : est) T = T * Q;
  const KittiMetric m = kitti_metric(gt, est);
  ASSERT_GT(m.segments, 0u);
  for (const auto& s : m.segment_errors) {
    const double tz = std::abs((gt[s.first_frame].inverse() * gt[s.last_frame]).translation().z());
    EXPECT_NEAR(s.vertical_ratio, std::sin(theta) * tz / s.length_m, 1e-12);
    EXPECT_NEAR(s.horizontal_ratio, (1 - std::cos(theta)) * tz / s.length_m, 1e-12);
  }
}

TEST(KittiMetricSplit, AStraightRoadOverACrestGivesNoUp) {
  // Its positions span a vertical plane (8 m of climb and descent, no lateral spread): the
  // plane's normal is the car's lateral axis, and the drive never turns about it.
  PoseList gt = straight_path(1500, 1.0);
  for (std::size_t i = 0; i < gt.size(); ++i)
    gt[i].translation().y() = -8.0 * std::sin(M_PI * static_cast<double>(i) / 1500.0);
  EXPECT_FALSE(ground_truth_up(gt).has_value());
  EXPECT_TRUE(std::isnan(kitti_metric(gt, gt).t_err_vertical_pct));
}

TEST(KittiMetricSplit, AStraightDriveGivesNoUp) {
  const PoseList gt = straight_path(1500, 1.0);
  EXPECT_FALSE(ground_truth_up(gt).has_value());
  PoseList est = gt;
  for (auto& T : est) T.translation() *= 1.01;
  const KittiMetric m = kitti_metric(gt, est);
  ASSERT_GT(m.segments, 0u);
  EXPECT_NEAR(m.t_err_pct, 1.0, 0.01);  // segments run a frame past their length
  EXPECT_TRUE(std::isnan(m.t_err_vertical_pct));
  EXPECT_TRUE(std::isnan(m.t_err_horizontal_pct));
  EXPECT_TRUE(std::isnan(m.segment_errors.front().vertical_ratio));
}

}  // namespace
}  // namespace scfloam
