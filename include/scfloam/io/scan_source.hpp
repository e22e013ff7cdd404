// Where scans come from. The pipeline reads every input through this interface; readers for
// KITTI directories, point-cloud folders and bags implement it.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "scfloam/types.hpp"

namespace scfloam {

class ScanSource {
 public:
  virtual ~ScanSource() = default;
  virtual std::size_t size() const = 0;
  // Thread-safe for distinct indices: the pipeline prefetches on another thread.
  virtual Scan load(std::size_t index) const = 0;
  // One line for humans: "KITTI sequence /path (4541 scans, ground truth, Tr)".
  virtual std::string describe() const = 0;
  // Velodyne -> camera-0 extrinsic when the input has one (KITTI's `Tr`): trajectories are
  // then also written in KITTI's camera-0 convention.
  virtual std::optional<Eigen::Isometry3d> T_cam0_lidar() const { return std::nullopt; }
  // Ground truth as lidar poses relative to the first frame (T_lidar0_lidarI); empty if none.
  virtual PoseList ground_truth_lidar() const { return {}; }
};

// How to read an input whose kind leaves choices open.
struct ScanSourceOptions {
  std::string topic;                        // bags: the PointCloud2 topic (auto when empty)
  std::filesystem::path timestamps_file;    // folders: one stamp per scan (else from names/headers)
};

enum class InputKind { kKitti, kBag, kScanFolder, kScanFile };

// What `path` is, by names and magic bytes only (nothing is parsed). Error naming the path and
// listing what was looked for when it is none of the kinds.
InputKind detect_input_kind(const std::filesystem::path& path);

// A KITTI odometry sequence directory (velodyne/, calib.txt, times.txt, optional poses.txt).
std::unique_ptr<ScanSource> open_kitti_source(const std::filesystem::path& dir);

// Detects the kind of input at `path` and opens it: a bag (is_bag_input), a KITTI directory
// (velodyne/), a folder of .pcd/.ply/.bin scans (one kind), or a single scan file.
// Error naming the path when it cannot; `options.timestamps_file` is refused for bags and KITTI.
std::unique_ptr<ScanSource> open_scan_source(const std::filesystem::path& path,
                                             const ScanSourceOptions& options = {});

}  // namespace scfloam
