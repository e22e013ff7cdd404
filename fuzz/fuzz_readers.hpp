// What each fuzz target does with its input file, shared with the regression test
// (tests/io/test_fuzz_regressions.cpp) that replays saved crash inputs in the normal build.
// A reader may fail only with scfloam::Error (swallowed here); any other exception, and a
// broken promise of a reader (thrown as std::logic_error), escapes: libFuzzer reports it as a
// crash and the test as a failure, like a sanitizer finding.
#pragma once

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>

#include "scfloam/config.hpp"
#include "scfloam/error.hpp"
#include "scfloam/eval/trajectory_input.hpp"
#include "scfloam/io/bag_source.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/pointcloud2.hpp"
#include "scfloam/io/trajectory.hpp"

namespace scfloam::fuzz {

template <typename F>
void expect_clean(F&& call) {
  try {
    call();
  } catch (const scfloam::Error&) {
  }
}

inline void promise(bool ok, const char* what) {
  if (!ok) throw std::logic_error(std::string("reader broke its promise: ") + what);
}

inline void read_kitti_bin_input(const std::filesystem::path& path) {
  expect_clean([&] {
    const auto points = read_kitti_bin(path);
    promise(points.size() == std::filesystem::file_size(path) / 16, "one point per 16 bytes");
  });
}

inline void read_kitti_calib_input(const std::filesystem::path& path) {
  expect_clean([&] {
    const auto calib = read_kitti_calib(path);
    promise(!calib.has_Tr || calib.T_cam0_velo.matrix().allFinite(), "finite Tr");
  });
}

// The files `scfloam eval` reads: KITTI poses, TUM, times, format detection, and pairing a
// trajectory with itself (by index, or by timestamp for TUM).
inline void read_trajectory_input(const std::filesystem::path& path) {
  expect_clean([&] { read_kitti_poses(path); });
  expect_clean([&] { read_tum(path); });
  expect_clean([&] { read_times(path); });
  expect_clean([&] {
    const LoadedTrajectory t = load_trajectory(path, TrajectoryFormat::kAuto);
    for (const auto& T : t.poses) promise(T.matrix().allFinite(), "finite poses");
    const AssociatedTrajectories a = associate_trajectories(t, t, 0.02);
    promise(a.gt.size() == a.est.size(), "pairs of poses");
  });
}

inline void read_config_input(const std::filesystem::path& path) {
  expect_clean([&] { load_config(path); });
}

inline void check_scan(const Scan& scan) {
  for (const auto& p : scan.points)
    promise(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), "finite points");
}

inline void read_pcd_input(const std::filesystem::path& path) {
  expect_clean([&] {
    const PointCloudFile f = read_pcd(path);
    promise(f.scan.points.size() <= f.declared_points, "no more points than declared");
    check_scan(f.scan);
  });
}

inline void read_ply_input(const std::filesystem::path& path) {
  expect_clean([&] {
    const PointCloudFile f = read_ply(path);
    promise(f.scan.points.size() <= f.declared_points, "no more points than declared");
    check_scan(f.scan);
  });
}

// A bag file of any kind (the suffix picks the reader): `scfloam info`'s inspection, then the
// scan source over its PointCloud2 topic, reading up to 16 scans.
inline void read_bag_input(const std::filesystem::path& path) {
  expect_clean([&] { inspect_bag(path, ScanSourceOptions{}); });
  expect_clean([&] {
    const auto source = open_bag_source(path, ScanSourceOptions{});
    for (std::size_t i = 0; i < std::min<std::size_t>(source->size(), 16); ++i)
      check_scan(source->load(i));
  });
}

// One serialized sensor_msgs/PointCloud2 message: the first byte picks ROS 1 or CDR.
inline void read_pointcloud2_input(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.empty()) return;
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data()) + 1;
  const std::size_t size = bytes.size() - 1;
  expect_clean([&] {
    const PointCloud2View view = (bytes[0] & 1) ? decode_cdr_pointcloud2(data, size, "fuzz")
                                                : decode_ros1_pointcloud2(data, size, "fuzz");
    promise(view.data_size == 0 || (view.data >= data && view.data + view.data_size <= data + size),
            "point bytes inside the message");
    check_scan(pointcloud2_to_scan(view, "fuzz"));
  });
}

// Target name (fuzz/<name>_fuzz.cpp) -> what it runs on one input file.
inline const std::map<std::string, std::function<void(const std::filesystem::path&)>>& readers() {
  static const std::map<std::string, std::function<void(const std::filesystem::path&)>> table{
      {"kitti_bin", read_kitti_bin_input},
      {"kitti_calib", read_kitti_calib_input},
      {"trajectory", read_trajectory_input},
      {"config", read_config_input},
      {"pcd", read_pcd_input},
      {"ply", read_ply_input},
      {"ros1_bag", read_bag_input},
      {"ros2_sqlite", read_bag_input},
      {"mcap", read_bag_input},
      {"pointcloud2", read_pointcloud2_input},
  };
  return table;
}

}  // namespace scfloam::fuzz
