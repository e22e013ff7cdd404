// KITTI odometry sequence directories: velodyne/NNNNNN.bin, calib.txt, times.txt, poses.txt.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "scfloam/types.hpp"

namespace scfloam {

// The velodyne -> camera-0 extrinsic of KITTI's 2011-10-03 drives (sequences 00-02), the
// default for simulated sequences: T_cam0_velo, so that p_cam = Tr * p_velo.
Eigen::Isometry3d kitti_default_Tr();

struct KittiCalib {
  Eigen::Isometry3d T_cam0_velo = Eigen::Isometry3d::Identity();  // the `Tr:` line
  bool has_Tr = false;
};

// Parses calib.txt; a file without a `Tr:` (or `Tr_velo_to_cam:`) line gives has_Tr = false.
KittiCalib read_kitti_calib(const std::filesystem::path& path);
void write_kitti_calib(const std::filesystem::path& path, const Eigen::Isometry3d& T_cam0_velo);

// A KITTI .bin scan (float32 x, y, z, reflectance). Throws naming the file when its size is
// not a multiple of 16 bytes or a point is NaN/inf (KITTI files never hold those: corruption).
std::vector<LidarPoint> read_kitti_bin(const std::filesystem::path& path);
void write_kitti_bin(const std::filesystem::path& path, const std::vector<LidarPoint>& points);

// Lidar-frame poses (T_lidar0_lidarI) <-> KITTI camera-0 poses: T_cam = Tr * T_velo * Tr^-1.
PoseList lidar_to_camera_poses(const PoseList& T_velo, const Eigen::Isometry3d& Tr);
PoseList camera_to_lidar_poses(const PoseList& T_cam, const Eigen::Isometry3d& Tr);

class KittiSequence {
 public:
  // Opens and checks the directory; throws scfloam::Error naming what is missing or wrong.
  static KittiSequence open(const std::filesystem::path& dir);

  std::size_t size() const { return scan_paths_.size(); }
  Scan load(std::size_t index) const;  // timestamp from times.txt
  const std::filesystem::path& dir() const { return dir_; }
  const std::filesystem::path& scan_path(std::size_t index) const { return scan_paths_.at(index); }
  const std::vector<double>& times() const { return times_; }
  const KittiCalib& calib() const { return calib_; }
  // Ground truth from poses.txt in camera-0 convention, when present.
  const std::optional<PoseList>& ground_truth_camera() const { return gt_camera_; }
  // The same ground truth as lidar poses (T_lidar0_lidarI); empty when absent.
  PoseList ground_truth_lidar() const;

 private:
  std::filesystem::path dir_;
  std::vector<std::filesystem::path> scan_paths_;
  std::vector<double> times_;
  KittiCalib calib_;
  std::optional<PoseList> gt_camera_;
};

}  // namespace scfloam
