// Readers on malformed files: each gives a scfloam::Error naming the file and the problem, or
// (for input that is odd but legal) a well-defined result.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <string>

#include "scfloam/config.hpp"
#include "scfloam/error.hpp"
#include "scfloam/eval/trajectory_input.hpp"
#include "scfloam/io/bag_source.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/trajectory.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

namespace scfloam {
namespace {

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// The call must throw scfloam::Error whose message names `path` and contains `needle`.
void expect_error(const fs::path& path, const std::string& needle,
                  const std::function<void()>& call) {
  try {
    call();
    ADD_FAILURE() << "no error for " << path;
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path.filename().string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(needle), std::string::npos) << msg;
  }
}

const std::string kIdentityKitti = "1 0 0 0 0 1 0 0 0 0 1 0\n";

fs::path kitti_dir(const fs::path& dir, const std::vector<std::string>& scan_names) {
  fs::create_directories(dir / "velodyne");
  for (const auto& name : scan_names)
    write_kitti_bin(dir / "velodyne" / name, std::vector<LidarPoint>(3));
  write_text(dir / "calib.txt", "Tr: " + kIdentityKitti);
  return dir;
}

TEST(BadInput, EmptyKittiScanIsAnEmptyScan) {
  const auto dir = test::scratch_dir("bad_empty_bin");
  write_text(dir / "empty.bin", "");
  EXPECT_TRUE(read_kitti_bin(dir / "empty.bin").empty());
}

TEST(BadInput, KittiScanOfHugeCoordinatesIsReadAsIs) {
  // 1e30 is finite float: the reader keeps it, the range crop drops it (tests/pipeline).
  const auto dir = test::scratch_dir("bad_huge_bin");
  std::vector<LidarPoint> points(2);
  points[0].x = 1e30f;
  write_kitti_bin(dir / "huge.bin", points);
  EXPECT_EQ(read_kitti_bin(dir / "huge.bin")[0].x, 1e30f);
}

TEST(BadInput, GapInKittiNumberingIsAnErrorNamingTheMissingScan) {
  const auto dir = test::scratch_dir("bad_gap");
  kitti_dir(dir / "seq", {"000000.bin", "000001.bin", "000003.bin", "000004.bin"});
  expect_error(dir / "seq" / "velodyne" / "000002.bin", "missing",
               [&] { KittiSequence::open(dir / "seq"); });
  // Consecutive numbering opens.
  kitti_dir(dir / "ok", {"000000.bin", "000001.bin", "000002.bin"});
  EXPECT_EQ(KittiSequence::open(dir / "ok").size(), 3u);
}

TEST(BadInput, TimesFileCountOrOrderWrong) {
  const auto dir = test::scratch_dir("bad_times");
  const auto seq = kitti_dir(dir / "seq", {"000000.bin", "000001.bin", "000002.bin"});
  write_text(seq / "times.txt", "0.0\n0.1\n");
  expect_error(seq / "times.txt", "2 timestamps for 3 scans", [&] { KittiSequence::open(seq); });
  write_text(seq / "times.txt", "0.0\n0.2\n0.1\n");
  expect_error(seq / "times.txt", "backwards", [&] { KittiSequence::open(seq); });
  // Duplicate stamps are legal (non-decreasing): a recorder may stamp two scans alike.
  write_text(seq / "times.txt", "0.0\n0.1\n0.1\n");
  EXPECT_EQ(KittiSequence::open(seq).times().size(), 3u);
}

TEST(BadInput, TrajectoryFiles) {
  const auto dir = test::scratch_dir("bad_trajectories");
  write_text(dir / "empty.txt", "");
  expect_error(dir / "empty.txt", "no poses", [&] { read_kitti_poses(dir / "empty.txt"); });
  expect_error(dir / "empty.txt", "no poses",
               [&] { load_trajectory(dir / "empty.txt", TrajectoryFormat::kAuto); });
  write_text(dir / "nan.txt", "1 0 0 nan 0 1 0 0 0 0 1 0\n");
  expect_error(dir / "nan.txt", "line 1", [&] { read_kitti_poses(dir / "nan.txt"); });
  write_text(dir / "huge.txt", "1 0 0 1e400 0 1 0 0 0 0 1 0\n");
  expect_error(dir / "huge.txt", "non-finite", [&] { read_kitti_poses(dir / "huge.txt"); });
  write_text(dir / "scaled.txt", "2 0 0 0 0 2 0 0 0 0 2 0\n");
  expect_error(dir / "scaled.txt", "not a rotation", [&] { read_kitti_poses(dir / "scaled.txt"); });
  write_text(dir / "back.tum", "1.0 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 0 1\n");
  expect_error(dir / "back.tum", "backwards", [&] { read_tum(dir / "back.tum"); });
  write_text(dir / "quat.tum", "1.0 0 0 0 0 0 0 0\n");
  expect_error(dir / "quat.tum", "unit length", [&] { read_tum(dir / "quat.tum"); });
  write_text(dir / "seven.txt", "1 2 3 4 5 6 7\n");
  expect_error(dir / "seven.txt", "neither KITTI",
               [&] { load_trajectory(dir / "seven.txt", TrajectoryFormat::kAuto); });
  write_text(dir / "binary.txt", std::string("\x01\x02\xff\x00zz", 6));
  expect_error(dir / "binary.txt", "not a number", [&] { read_kitti_poses(dir / "binary.txt"); });
}

TEST(BadInput, CalibrationFile) {
  const auto dir = test::scratch_dir("bad_calib");
  write_text(dir / "short.txt", "Tr: 1 0 0\n");
  expect_error(dir / "short.txt", "12 numbers", [&] { read_kitti_calib(dir / "short.txt"); });
  write_text(dir / "shear.txt", "Tr: 1 5 0 0 0 1 0 0 0 0 1 0\n");
  expect_error(dir / "shear.txt", "rigid", [&] { read_kitti_calib(dir / "shear.txt"); });
  write_text(dir / "none.txt", "P0: 1 2 3\n");
  EXPECT_FALSE(read_kitti_calib(dir / "none.txt").has_Tr);
}

TEST(BadInput, ConfigErrorsNameTheKey) {
  const auto dir = test::scratch_dir("bad_config");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"odometry:\n  registration:\n    knn: [1, 2]\n", "odometry.registration.knn"},
      {"odometry:\n  registration:\n    knn: 2.5\n", "odometry.registration.knn"},
      {"odometry:\n  rings:\n    lidar: {a: 1}\n", "odometry.rings.lidar"},
      {"odometry: 3\n", "odometry"},
      {"odometry:\n  map:\n    radius_m: 1e400x\n", "odometry.map.radius_m"},
      {"loop_detection:\n  descriptor:\n    num_ringz: 20\n", "loop_detection.descriptor.num_ringz"},
      {"[1, 2, 3]\n", "top level"},
      {"odometry: {features: {edge_leaf_m: 0.4}\n", "not valid YAML"},
      {"? [a, b]\n: 1\n", "key"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto path = dir / ("case" + std::to_string(i) + ".yaml");
    write_text(path, cases[i].first);
    SCOPED_TRACE(cases[i].first);
    expect_error(path, cases[i].second, [&] { load_config(path); });
  }
}

TEST(BadInput, ConfigValuesOutOfRangeNameTheKey) {
  const auto dir = test::scratch_dir("bad_config_range");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"odometry:\n  features:\n    edge_leaf_m: 0\n", "odometry.features.edge_leaf_m"},
      {"odometry:\n  features:\n    plane_leaf_m: -1\n", "odometry.features.plane_leaf_m"},
      {"odometry:\n  registration:\n    knn: 0\n", "odometry.registration.knn"},
      {"odometry:\n  registration:\n    knn: 13\n", "odometry.registration.knn"},
      {"loop_registration:\n  knn: 2\n", "loop_registration.knn"},
      {"odometry:\n  registration:\n    num_threads: -2\n", "odometry.registration.num_threads"},
      {"odometry:\n  map:\n    max_points_per_cell: 0\n", "odometry.map.max_points_per_cell"},
      {"odometry:\n  registration:\n    max_neighbor_dist_m: .nan\n",
       "odometry.registration.max_neighbor_dist_m"},
      {"loop_detection:\n  descriptor:\n    num_sectors: 0\n", "loop_detection.descriptor.num_sectors"},
      {"pipeline:\n  max_loop_lag_frames: -2\n", "pipeline.max_loop_lag_frames"},
      {"odometry:\n  registration:\n    plane_min_spread_ratio: 1\n",
       "odometry.registration.plane_min_spread_ratio"},
      {"odometry:\n  registration:\n    edge_max_residual_m: -0.1\n",
       "odometry.registration.edge_max_residual_m"},
      {"odometry:\n  registration:\n    edge_view_tolerance_deg: 180\n",
       "odometry.registration.edge_view_tolerance_deg"},
      {"odometry:\n  registration:\n    plane_max_dist_m: 0\n", "odometry.registration.plane_max_dist_m"},
      {"loop_registration:\n  check_plane_max_dist_m: -0.2\n",
       "loop_registration.check_plane_max_dist_m"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto path = dir / ("case" + std::to_string(i) + ".yaml");
    write_text(path, cases[i].first);
    SCOPED_TRACE(cases[i].first);
    expect_error(path, cases[i].second, [&] { load_config(path); });
  }
}

// Size fields of 4 GB and more in headers: an Error (truncated / too large), never an attempt
// to allocate or read that much, never a crash.
TEST(BadInput, FourGigabyteSizeFieldsInHeaders) {
  const auto dir = test::scratch_dir("bad_4gb");
  const std::string points(48, '\0');  // three float32 x y z intensity points, all zero
  for (const char* count : {"4294967295", "4294967296", "18446744073709551615"}) {
    SCOPED_TRACE(count);
    write_text(dir / "big.pcd",
               std::string("VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\n"
                           "COUNT 1 1 1 1\nWIDTH ") + count + "\nHEIGHT 1\nPOINTS " + count +
                   "\nDATA binary\n" + points);
    expect_error(dir / "big.pcd", "", [&] { read_pcd(dir / "big.pcd"); });
    write_text(dir / "big.ply", std::string("ply\nformat binary_little_endian 1.0\nelement vertex ") +
                                    count +
                                    "\nproperty float x\nproperty float y\nproperty float z\n"
                                    "property float intensity\nend_header\n" + points);
    expect_error(dir / "big.ply", "", [&] { read_ply(dir / "big.ply"); });
  }
  // MCAP: a Header record claiming 2^40 bytes.
  std::string mcap = "\x89MCAP0\r\n";
  mcap += '\x01';
  for (int i = 0; i < 8; ++i) mcap += static_cast<char>(i == 5 ? 1 : 0);
  mcap += "\x89MCAP0\r\n";
  write_text(dir / "big.mcap", mcap);
  expect_error(dir / "big.mcap", "", [&] { open_bag_source(dir / "big.mcap", {}); });
  // ROS 1 bag: a record header length of 0xffffffff after the version line.
  write_text(dir / "big.bag", std::string("#ROSBAG V2.0\n\xff\xff\xff\xff", 17) + points);
  expect_error(dir / "big.bag", "", [&] { open_bag_source(dir / "big.bag", {}); });
}

}  // namespace
}  // namespace scfloam
