// Reading the two trajectories `scfloam eval` compares and pairing their poses: KITTI files
// pair by index (same count required), timestamped ones (TUM, or KITTI plus a times.txt) pair
// by nearest timestamp within a tolerance.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "scfloam/io/trajectory.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

enum class TrajectoryFormat { kAuto, kKitti, kTum };

// "auto", "kitti" or "tum"; throws scfloam::Error otherwise.
TrajectoryFormat parse_trajectory_format(const std::string& name);
const char* trajectory_format_name(TrajectoryFormat format);

// From the first data line: 12 numbers -> KITTI, 8 -> TUM; throws naming the file otherwise.
TrajectoryFormat detect_trajectory_format(const std::filesystem::path& path);

struct LoadedTrajectory {
  std::filesystem::path path;
  TrajectoryFormat format = TrajectoryFormat::kKitti;
  PoseList poses;
  std::vector<double> stamps_s;  // empty for a KITTI file without a times file
  bool has_stamps() const { return !stamps_s.empty(); }
};

// A KITTI times.txt: one timestamp (s) a line, non-decreasing.

// Reads `path` (format kAuto: detected by content). `times_path`, when given, supplies
// timestamps for a KITTI file (its count must equal the pose count); a TUM file has its own.
LoadedTrajectory load_trajectory(const std::filesystem::path& path, TrajectoryFormat format,
                                 const std::optional<std::filesystem::path>& times_path = {});

struct AssociatedTrajectories {
  PoseList gt, est;
  std::vector<std::size_t> gt_index, est_index;  // rows of the input files, per pair
  std::size_t gt_total = 0, est_total = 0;       // poses in the files
  std::string method;                            // e.g. "by index", "by timestamp (<= 0.02 s)"
};

// Both without timestamps: by index, counts must match. Both with: each estimate pose to the
// nearest ground-truth stamp within max_dt_s, one to one. Mixed: error saying which times file
// is missing. Errors name both files and their counts.
AssociatedTrajectories associate_trajectories(const LoadedTrajectory& gt,
                                              const LoadedTrajectory& est, double max_dt_s);

}  // namespace scfloam
