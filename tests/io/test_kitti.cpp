#include <gtest/gtest.h>

#include <fstream>

#include "scfloam/error.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/se3.hpp"
#include "test_paths.hpp"

using namespace scfloam;
namespace fs = std::filesystem;

TEST(KittiReader, RealScansOfSequence05) {
  SCFLOAM_SHARED_DATA_OR_SKIP(dir, "kitti/scans/05");
  const KittiSequence seq = KittiSequence::open(dir);
  ASSERT_EQ(seq.size(), 10u);
  ASSERT_TRUE(seq.calib().has_Tr);
  ASSERT_TRUE(seq.ground_truth_camera().has_value());
  const Scan scan = seq.load(0);
  EXPECT_GT(scan.points.size(), 100000u);
  EXPECT_LT(scan.points.size(), 140000u);
  EXPECT_NEAR(seq.times()[1], 0.1042283, 1e-6);
  // The first ground-truth pose is the identity, in either frame.
  const PoseList lidar = seq.ground_truth_lidar();
  EXPECT_LT((lidar[0].matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-6);
  // The car drives forward: along camera z, which is lidar x.
  EXPECT_GT(lidar[9].translation().x(), 4.0);
  EXPECT_LT(std::abs(lidar[9].translation().y()), 0.5);
}

TEST(KittiReader, BinRoundTrip) {
  const auto dir = test::scratch_dir("kitti_bin_round_trip");
  std::vector<LidarPoint> pts(3);
  pts[1].x = 1.5f;
  pts[2].z = -2.25f;
  pts[2].intensity = 0.5f;
  write_kitti_bin(dir / "a.bin", pts);
  const auto back = read_kitti_bin(dir / "a.bin");
  ASSERT_EQ(back.size(), 3u);
  EXPECT_EQ(back[1].x, 1.5f);
  EXPECT_EQ(back[2].z, -2.25f);
  EXPECT_EQ(back[2].intensity, 0.5f);
}

TEST(KittiReader, ClearErrors) {
  const auto dir = test::scratch_dir("kitti_errors");
  auto expect_error = [](const fs::path& path, const std::string& needle, auto&& call) {
    try {
      call();
      FAIL() << "no error for " << path;
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(path.filename().string()), std::string::npos) << msg;
      EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    }
  };
  expect_error(dir / "nothing", "no such directory",
               [&] { KittiSequence::open(dir / "nothing"); });
  fs::create_directories(dir / "seq" / "velodyne");
  write_kitti_bin(dir / "seq" / "velodyne" / "000000.bin", std::vector<LidarPoint>(2));
  expect_error(dir / "seq" / "calib.txt", "missing", [&] { KittiSequence::open(dir / "seq"); });
  write_pcd(dir / "seq" / "velodyne" / "000001.pcd", std::vector<LidarPoint>(2), PcdEncoding::kBinary);
  expect_error(dir / "seq" / "velodyne", "both .bin and .pcd", [&] { KittiSequence::open(dir / "seq"); });
  {
    std::ofstream odd(dir / "odd.bin", std::ios::binary);
    odd << "0123456789";
  }
  expect_error(dir / "odd.bin", "multiple of 16", [&] { read_kitti_bin(dir / "odd.bin"); });
  {
    std::vector<LidarPoint> pts(2);
    pts[1].y = std::numeric_limits<float>::quiet_NaN();
    write_kitti_bin(dir / "nan.bin", pts);
  }
  expect_error(dir / "nan.bin", "NaN", [&] { read_kitti_bin(dir / "nan.bin"); });
}

TEST(KittiCalibration, CameraLidarRoundTrip) {
  const Eigen::Isometry3d Tr = kitti_default_Tr();
  PoseList lidar;
  for (int i = 0; i < 5; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = so3_exp(Eigen::Vector3d(0.01 * i, -0.02 * i, 0.3 * i));
    T.translation() = Eigen::Vector3d(3.0 * i, 0.5 * i, 0.1 * i);
    lidar.push_back(T);
  }
  const PoseList cam = lidar_to_camera_poses(lidar, Tr);
  // Forward in the lidar frame (x) is forward in the camera frame (z).
  EXPECT_NEAR(cam[1].translation().z(), lidar[1].translation().x(), 0.1);
  const PoseList back = camera_to_lidar_poses(cam, Tr);
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(back[i].isApprox(lidar[i], 1e-9));

  const auto dir = test::scratch_dir("kitti_calib");
  write_kitti_calib(dir / "calib.txt", Tr);
  const KittiCalib calib = read_kitti_calib(dir / "calib.txt");
  ASSERT_TRUE(calib.has_Tr);
  EXPECT_TRUE(calib.T_cam0_velo.isApprox(Tr, 1e-11));
}

TEST(Trajectory, KittiAndTumRoundTrip) {
  const auto dir = test::scratch_dir("trajectory_round_trip");
  StampedTrajectory traj;
  for (int i = 0; i < 4; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = so3_exp(Eigen::Vector3d(0.1, 0.2 * i, -0.3));
    T.translation() = Eigen::Vector3d(i, -2.0 * i, 0.5);
    traj.poses.push_back(T);
    traj.stamps_s.push_back(100.0 + 0.1 * i);
  }
  write_kitti_poses(dir / "k.txt", traj.poses);
  const PoseList k = read_kitti_poses(dir / "k.txt");
  write_tum(dir / "t.txt", traj);
  const StampedTrajectory t = read_tum(dir / "t.txt");
  ASSERT_EQ(k.size(), 4u);
  ASSERT_EQ(t.poses.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(k[i].isApprox(traj.poses[i], 1e-8));
    EXPECT_TRUE(t.poses[i].isApprox(traj.poses[i], 1e-8));
    EXPECT_NEAR(t.stamps_s[i], traj.stamps_s[i], 1e-9);
  }
}

TEST(Trajectory, MalformedLinesNameFileAndLine) {
  const auto dir = test::scratch_dir("trajectory_malformed");
  {
    std::ofstream f(dir / "bad.txt");
    f << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0\n";
  }
  try {
    read_kitti_poses(dir / "bad.txt");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt: line 2"), std::string::npos) << e.what();
  }
}
