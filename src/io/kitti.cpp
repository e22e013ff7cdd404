#include "scfloam/io/kitti.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "scfloam/atomic_file.hpp"
#include "scfloam/error.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/trajectory.hpp"

namespace scfloam {
namespace fs = std::filesystem;

Eigen::Isometry3d kitti_default_Tr() {
  // calib.txt of KITTI's 2011-10-03 drives.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.matrix().topRows<3>() << 4.276802385584e-04, -9.999672484946e-01, -8.084491683471e-03,
      -1.198459927713e-02, -7.210626507497e-03, 8.081198471645e-03, -9.999413164504e-01,
      -5.403984729748e-02, 9.999738645903e-01, 4.859485810390e-04, -7.206933692422e-03,
      -2.921968648686e-01;
  return T;
}

KittiCalib read_kitti_calib(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw file_error(path, "cannot open the calibration file");
  KittiCalib calib;
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, colon);
    if (key != "Tr" && key != "Tr_velo_to_cam") continue;
    const auto v = parse_numbers(line.substr(colon + 1), path, line_no);
    if (v.size() != 12)
      throw file_error(path, "line " + std::to_string(line_no) + ": `" + key +
                                 ":` needs 12 numbers, found " + std::to_string(v.size()));
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) calib.T_cam0_velo.matrix()(r, c) = v[r * 4 + c];
    const Eigen::Matrix3d R = calib.T_cam0_velo.linear();
    if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-3)
      throw file_error(path, "line " + std::to_string(line_no) + ": `Tr` is not a rigid transform");
    calib.has_Tr = true;
  }
  return calib;
}

void write_kitti_calib(const fs::path& path, const Eigen::Isometry3d& T_cam0_velo) {
  write_file_atomic(path, [&](std::ostream& out) {
    // P0..P3 of the 2011-10-03 drives: tools that read calib.txt expect them to exist.
    const char* projections[] = {
        "7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 0.000000000000e+00 "
        "0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 "
        "0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00",
        "7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 -3.861448000000e+02 "
        "0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 "
        "0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00",
        "7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 4.538225000000e+01 "
        "0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 -1.130887000000e-01 "
        "0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 3.779761000000e-03",
        "7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 -3.372877000000e+02 "
        "0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 2.369057000000e+00 "
        "0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 4.915215000000e-03"};
    for (int i = 0; i < 4; ++i) out << "P" << i << ": " << projections[i] << "\n";
    char buf[32];
    out << "Tr:";
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) {
        std::snprintf(buf, sizeof buf, " %.12e", T_cam0_velo.matrix()(r, c));
        out << buf;
      }
    out << "\n";
  });
}

std::vector<LidarPoint> read_kitti_bin(const fs::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw file_error(path, "cannot open the scan");
  const std::streamoff size = in.tellg();
  if (size % 16 != 0)
    throw file_error(path, "size " + std::to_string(size) +
                               " bytes is not a multiple of 16 (float32 x, y, z, reflectance)");
  const std::size_t n = static_cast<std::size_t>(size / 16);
  std::vector<float> raw(n * 4);
  in.seekg(0);
  if (n > 0 && !in.read(reinterpret_cast<char*>(raw.data()), size))
    throw file_error(path, "read failed");
  std::vector<LidarPoint> points(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float* v = &raw[i * 4];
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]) ||
        !std::isfinite(v[3]))
      throw file_error(path, "point " + std::to_string(i) + " is NaN or infinite (corrupt scan?)");
    points[i].x = v[0];
    points[i].y = v[1];
    points[i].z = v[2];
    points[i].intensity = v[3];
  }
  return points;
}

void write_kitti_bin(const fs::path& path, const std::vector<LidarPoint>& points) {
  std::vector<float> raw(points.size() * 4);
  for (std::size_t i = 0; i < points.size(); ++i) {
    raw[i * 4 + 0] = points[i].x;
    raw[i * 4 + 1] = points[i].y;
    raw[i * 4 + 2] = points[i].z;
    raw[i * 4 + 3] = points[i].intensity;
  }
  write_file_atomic(path, std::string_view(reinterpret_cast<const char*>(raw.data()),
                                           raw.size() * sizeof(float)));
}

PoseList lidar_to_camera_poses(const PoseList& T_velo, const Eigen::Isometry3d& Tr) {
  PoseList out;
  out.reserve(T_velo.size());
  // KITTI's Tr is only nearly orthonormal: invert the full matrix, as the devkit does.
  const Eigen::Matrix4d Tr_inv = Tr.matrix().inverse();
  for (const auto& T : T_velo) out.emplace_back(Tr.matrix() * T.matrix() * Tr_inv);
  return out;
}

PoseList camera_to_lidar_poses(const PoseList& T_cam, const Eigen::Isometry3d& Tr) {
  PoseList out;
  out.reserve(T_cam.size());
  const Eigen::Matrix4d Tr_inv = Tr.matrix().inverse();
  for (const auto& T : T_cam) out.emplace_back(Tr_inv * T.matrix() * Tr.matrix());
  return out;
}

namespace {

// A missing scan in the numbering is an error, not skipped: times.txt and poses.txt are
// indexed by line, so every scan after a gap would get its neighbour's time and ground truth.
void check_no_gaps(const std::vector<fs::path>& sorted_scans) {
  long long previous = -1;
  for (const auto& path : sorted_scans) {
    const std::string stem = path.stem().string();
    if (stem.empty() || stem.size() > 12 ||
        stem.find_first_not_of("0123456789") != std::string::npos)
      return;  // not KITTI's numbering: nothing to check
    const long long number = std::stoll(stem);
    if (previous >= 0 && number != previous + 1) {
      char missing[32];
      std::snprintf(missing, sizeof missing, "%0*lld%s", static_cast<int>(stem.size()),
                    previous + 1, path.extension().string().c_str());
      throw file_error(path.parent_path() / missing,
                       "missing: the scans jump from " + std::to_string(previous) + " to " +
                           std::to_string(number) +
                           " (times.txt and poses.txt lines would no longer match the scans)");
    }
    previous = number;
  }
}

}  // namespace

KittiSequence KittiSequence::open(const fs::path& dir) {
  if (!fs::exists(dir)) throw file_error(dir, "no such directory");
  if (!fs::is_directory(dir)) throw file_error(dir, "not a directory (expected a KITTI sequence)");
  KittiSequence seq;
  seq.dir_ = dir;
  const fs::path velodyne = dir / "velodyne";
  if (!fs::is_directory(velodyne))
    throw file_error(dir, "no velodyne/ folder: not a KITTI odometry sequence directory");
  // KITTI's .bin scans, or PCD scans (which may carry ring and time fields: `scfloam
  // simulate --scan-format pcd` writes motion-distorted sequences so), never both.
  std::size_t pcd_count = 0;
  for (const auto& entry : fs::directory_iterator(velodyne)) {
    const fs::path& path = entry.path();
    if (path.extension() == ".bin" || path.extension() == ".pcd") seq.scan_paths_.push_back(path);
    if (path.extension() == ".pcd") ++pcd_count;
  }
  if (seq.scan_paths_.empty()) throw file_error(velodyne, "no .bin or .pcd scans in the folder");
  if (pcd_count != 0 && pcd_count != seq.scan_paths_.size())
    throw file_error(velodyne, "holds both .bin and .pcd scans (" + std::to_string(pcd_count) +
                                   " .pcd of " + std::to_string(seq.scan_paths_.size()) +
                                   "): keep one kind");
  std::sort(seq.scan_paths_.begin(), seq.scan_paths_.end());
  check_no_gaps(seq.scan_paths_);

  const fs::path calib = dir / "calib.txt";
  if (!fs::exists(calib)) throw file_error(calib, "missing (needed for the velodyne->camera `Tr`)");
  seq.calib_ = read_kitti_calib(calib);

  const fs::path times = dir / "times.txt";
  if (fs::exists(times)) {
    seq.times_ = read_times(times);
    if (seq.times_.size() != seq.scan_paths_.size())
      throw file_error(times, std::to_string(seq.times_.size()) + " timestamps for " +
                                  std::to_string(seq.scan_paths_.size()) + " scans");
  } else {
    // KITTI records at 10 Hz; without times.txt we assume that rate.
    for (std::size_t i = 0; i < seq.scan_paths_.size(); ++i) seq.times_.push_back(0.1 * i);
  }

  const fs::path poses = dir / "poses.txt";
  if (fs::exists(poses)) {
    PoseList gt = read_kitti_poses(poses);
    if (gt.size() != seq.scan_paths_.size())
      throw file_error(poses, std::to_string(gt.size()) + " poses for " +
                                  std::to_string(seq.scan_paths_.size()) + " scans");
    seq.gt_camera_ = std::move(gt);
  }
  return seq;
}

Scan KittiSequence::load(std::size_t index) const {
  const fs::path& path = scan_paths_.at(index);
  Scan scan;
  if (path.extension() == ".pcd") scan = read_pcd(path).scan;  // with its ring and time fields
  else scan.points = read_kitti_bin(path);
  scan.timestamp_s = times_.at(index);
  return scan;
}

PoseList KittiSequence::ground_truth_lidar() const {
  if (!gt_camera_) return {};
  return camera_to_lidar_poses(*gt_camera_, calib_.has_Tr ? calib_.T_cam0_velo
                                                         : Eigen::Isometry3d::Identity());
}

}  // namespace scfloam
