// Trajectory files: KITTI (12 numbers a line, 3x4 row-major) and TUM
// ("t tx ty tz qx qy qz qw" a line, '#' comments).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "scfloam/types.hpp"

namespace scfloam {

// Throws scfloam::Error naming the file and line on a malformed or non-finite line, or a
// rotation that is not a rotation (|R^T R - I| > 1e-3).
PoseList read_kitti_poses(const std::filesystem::path& path);
void write_kitti_poses(const std::filesystem::path& path, const PoseList& poses);

struct StampedTrajectory {
  std::vector<double> stamps_s;
  PoseList poses;
};
StampedTrajectory read_tum(const std::filesystem::path& path);
void write_tum(const std::filesystem::path& path, const StampedTrajectory& trajectory);

// A times file (KITTI times.txt): one timestamp in seconds a line, never going backwards.
std::vector<double> read_times(const std::filesystem::path& path);

// The numbers of one text line (space, tab or comma separated), or Error("path: line N: ...").
std::vector<double> parse_numbers(const std::string& line, const std::filesystem::path& path,
                                  std::size_t line_no);

}  // namespace scfloam
