// Format detection, KITTI/TUM round trips, timestamp association and its error messages.
#include <gtest/gtest.h>

#include <fstream>

#include "scfloam/error.hpp"
#include "scfloam/eval/eval_plots.hpp"
#include "scfloam/eval/trajectory_input.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/se3.hpp"
#include "test_paths.hpp"

namespace scfloam {
namespace {

PoseList some_poses(std::size_t n) {
  PoseList poses;
  for (std::size_t i = 0; i < n; ++i) {
    Pose T = Pose::Identity();
    T.linear() = so3_exp(Eigen::Vector3d(0.01, 0.02 * static_cast<double>(i), -0.01));
    T.translation() = Eigen::Vector3d(0.5 * i, -0.1 * i, 1.0 * i);
    poses.push_back(T);
  }
  return poses;
}

void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(TrajectoryInput, DetectsFormatsAndRoundTrips) {
  const auto dir = test::scratch_dir("eval_input_roundtrip");
  const PoseList poses = some_poses(20);
  write_kitti_poses(dir / "k.txt", poses);
  StampedTrajectory tum;
  tum.poses = poses;
  for (std::size_t i = 0; i < poses.size(); ++i) tum.stamps_s.push_back(100.0 + 0.1 * i);
  write_tum(dir / "t.txt", tum);

  EXPECT_EQ(detect_trajectory_format(dir / "k.txt"), TrajectoryFormat::kKitti);
  EXPECT_EQ(detect_trajectory_format(dir / "t.txt"), TrajectoryFormat::kTum);
  const auto k = load_trajectory(dir / "k.txt", TrajectoryFormat::kAuto);
  const auto t = load_trajectory(dir / "t.txt", TrajectoryFormat::kAuto);
  ASSERT_EQ(k.poses.size(), 20u);
  ASSERT_EQ(t.poses.size(), 20u);
  EXPECT_FALSE(k.has_stamps());
  EXPECT_TRUE(t.has_stamps());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_TRUE(k.poses[i].isApprox(poses[i], 1e-8));
    EXPECT_TRUE(t.poses[i].isApprox(poses[i], 1e-7));
    EXPECT_NEAR(t.stamps_s[i], 100.0 + 0.1 * i, 1e-9);
  }
  write_text(dir / "bad.txt", "1 2 3 4 5\n");
  EXPECT_NE(message_of([&] { detect_trajectory_format(dir / "bad.txt"); }).find("neither KITTI"),
            std::string::npos);
  EXPECT_THROW(parse_trajectory_format("csv"), Error);
}

TEST(TrajectoryInput, KittiPairsByIndexAndNamesBothFilesOnMismatch) {
  const auto dir = test::scratch_dir("eval_input_mismatch");
  write_kitti_poses(dir / "gt.txt", some_poses(20));
  write_kitti_poses(dir / "est.txt", some_poses(18));
  const auto gt = load_trajectory(dir / "gt.txt", TrajectoryFormat::kAuto);
  const auto est = load_trajectory(dir / "est.txt", TrajectoryFormat::kAuto);
  const std::string msg = message_of([&] { associate_trajectories(gt, est, 0.02); });
  EXPECT_NE(msg.find("gt.txt"), std::string::npos) << msg;
  EXPECT_NE(msg.find("est.txt"), std::string::npos) << msg;
  EXPECT_NE(msg.find("20"), std::string::npos) << msg;
  EXPECT_NE(msg.find("18"), std::string::npos) << msg;

  const auto same = associate_trajectories(gt, gt, 0.02);
  EXPECT_EQ(same.gt.size(), 20u);
  EXPECT_EQ(same.method, "by index");
}

TEST(TrajectoryInput, TimestampAssociationNearestWithinTolerance) {
  const auto dir = test::scratch_dir("eval_input_assoc");
  const PoseList poses = some_poses(30);
  write_kitti_poses(dir / "gt.txt", poses);
  std::string times;
  for (std::size_t i = 0; i < poses.size(); ++i) times += std::to_string(0.1 * i) + "\n";
  write_text(dir / "times.txt", times);
  // Estimate: every 2nd frame, stamps 5 ms late, plus one stamp far from any gt stamp.
  StampedTrajectory est;
  for (std::size_t i = 0; i < poses.size(); i += 2) {
    est.stamps_s.push_back(0.1 * i + 0.005);
    est.poses.push_back(poses[i]);
  }
  est.stamps_s.push_back(99.0);
  est.poses.push_back(Pose::Identity());
  write_tum(dir / "est.tum", est);

  const auto gt = load_trajectory(dir / "gt.txt", TrajectoryFormat::kAuto, dir / "times.txt");
  const auto e = load_trajectory(dir / "est.tum", TrajectoryFormat::kAuto);
  const auto a = associate_trajectories(gt, e, 0.02);
  ASSERT_EQ(a.gt.size(), 15u);  // the 99 s stamp has no partner
  for (std::size_t k = 0; k < a.gt.size(); ++k) {
    EXPECT_EQ(a.gt_index[k], 2 * k);
    EXPECT_EQ(a.est_index[k], k);
    EXPECT_TRUE(a.gt[k].isApprox(a.est[k], 1e-7));
  }
  EXPECT_EQ(a.gt_total, 30u);
  EXPECT_EQ(a.est_total, 16u);

  // Two estimates next to one gt stamp: only the closer one is kept (one to one).
  StampedTrajectory twin;
  twin.stamps_s = {0.295, 0.301};
  twin.poses = {poses[3], poses[3]};
  write_tum(dir / "twin.tum", twin);
  const auto t = associate_trajectories(gt, load_trajectory(dir / "twin.tum", TrajectoryFormat::kAuto), 0.02);
  ASSERT_EQ(t.gt.size(), 1u);
  EXPECT_EQ(t.gt_index[0], 3u);
  EXPECT_EQ(t.est_index[0], 1u);
}

TEST(TrajectoryInput, ClearErrorsForMissingTimesAndDisjointStamps) {
  const auto dir = test::scratch_dir("eval_input_errors");
  const PoseList poses = some_poses(10);
  write_kitti_poses(dir / "gt.txt", poses);
  StampedTrajectory est;
  est.poses = poses;
  for (std::size_t i = 0; i < poses.size(); ++i) est.stamps_s.push_back(1e9 + i);
  write_tum(dir / "est.tum", est);
  const auto gt = load_trajectory(dir / "gt.txt", TrajectoryFormat::kAuto);
  const auto e = load_trajectory(dir / "est.tum", TrajectoryFormat::kAuto);
  EXPECT_NE(message_of([&] { associate_trajectories(gt, e, 0.02); }).find("--gt-times"),
            std::string::npos);

  write_text(dir / "times.txt", "0\n0.1\n0.2\n");
  EXPECT_NE(message_of([&] { load_trajectory(dir / "gt.txt", TrajectoryFormat::kAuto, dir / "times.txt"); })
                .find("3 timestamps"),
            std::string::npos);
  std::string times;
  for (std::size_t i = 0; i < poses.size(); ++i) times += std::to_string(0.1 * i) + "\n";
  write_text(dir / "times.txt", times);
  const auto g = load_trajectory(dir / "gt.txt", TrajectoryFormat::kAuto, dir / "times.txt");
  const std::string msg = message_of([&] { associate_trajectories(g, e, 0.02); });
  EXPECT_NE(msg.find("within 0.02 s"), std::string::npos) << msg;
}

TEST(TrajectoryInput, KittiTimesFileMatchesTheSharedSequence) {
  SCFLOAM_SHARED_DATA_OR_SKIP(seq, "kitti/scans/00");
  const auto t = load_trajectory(seq / "poses.txt", TrajectoryFormat::kAuto, seq / "times.txt");
  EXPECT_EQ(t.format, TrajectoryFormat::kKitti);
  EXPECT_EQ(t.stamps_s.size(), t.poses.size());
  EXPECT_DOUBLE_EQ(t.stamps_s[0], 0.0);
}

TEST(LoopsCsv, ReadsAcceptedRowsAndReindexes) {
  const auto dir = test::scratch_dir("eval_loops_csv");
  write_text(dir / "loops.csv",
             "current_frame,loop_frame,sc_distance,verdict\n"
             "120,3,0.12,accepted\n"
             "130,4,0.31,rejected_distance\n"
             "140,5,0.10,accepted\n");
  const auto loops = read_accepted_loops(dir / "loops.csv");
  ASSERT_EQ(loops.size(), 2u);
  EXPECT_EQ(loops[0].current_frame, 120u);
  EXPECT_EQ(loops[1].loop_frame, 5u);
  // Estimate rows 3, 5, 120 evaluated (pairs 0, 1, 2); row 140 missing -> second loop dropped.
  const auto pairs = loops_to_pairs(loops, {3, 5, 120});
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].current_frame, 2u);
  EXPECT_EQ(pairs[0].loop_frame, 0u);

  write_text(dir / "bad.csv", "frame,loop_frame,verdict\n1,2,accepted\n");
  EXPECT_NE(message_of([&] { read_accepted_loops(dir / "bad.csv"); }).find("current_frame"),
            std::string::npos);
  write_text(dir / "bad2.csv", "current_frame,loop_frame,verdict\nx,2,accepted\n");
  EXPECT_NE(message_of([&] { read_accepted_loops(dir / "bad2.csv"); }).find("line 2"),
            std::string::npos);
}

}  // namespace
}  // namespace scfloam
