// What a run leaves in its output folder: trajectories, maps, summary.json (docs/formats.md,
// docs/inputs.md).
#pragma once

#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "scfloam/io/scan_source.hpp"
#include "scfloam/pipeline/pipeline.hpp"

namespace scfloam {

// Convention of the KITTI-format trajectories (poses_kitti.txt, odometry_kitti.txt,
// keyframes_kitti.txt). kAuto: camera-0 when the source has Tr, else lidar.
enum class PoseFrame { kAuto, kLidar, kCamera };
std::optional<PoseFrame> parse_pose_frame(const std::string& name);  // "lidar", "camera", "auto"

struct OutputOptions {
  double map_voxel_m = 0.2;   // leaf of map.pcd / map.ply (and of saved keyframe clouds)
  bool write_ply = false;     // map.ply (binary little endian, x y z intensity) besides map.pcd
  bool save_keyframes = false;  // keyframes/NNNNNN.pcd + keyframes/poses_kitti.txt + frames.txt
  PoseFrame frame = PoseFrame::kAuto;
  // Raw points kept in the map: horizontal range in [min, max] (the odometry's crop).
  double map_min_range_m = 0;
  double map_max_range_m = std::numeric_limits<double>::infinity();
};

// Error when the options cannot be met by this source (--frame camera without Tr, a map voxel
// that is not positive): checked before the run, so that nothing is computed in vain.
void check_output_options(const ScanSource& source, const OutputOptions& options);

// summary.json's content: frames, keyframes, wall_s, peak_rss_mb, timing_ms{stage: {median,
// mean, p95, count}}, and accuracy against ground truth when the source has it.
nlohmann::json make_summary(const ScanSource& source, const RunResult& result);

// poses_kitti.txt (every frame, in options.frame), poses_tum.txt (timestamped lidar poses),
// odometry_kitti.txt, keyframes_kitti.txt, loops.csv, graph.g2o, map.pcd (+ map.ply),
// keyframes/ on request, summary.json. Every file is written atomically. summary.json is
// written last, with `peak_rss_mb` updated to the process's peak so far: assembling the map
// re-reads the keyframes' scans and can take more memory than the run did.
void write_run_outputs(const std::filesystem::path& out_dir, const ScanSource& source,
                       const RunResult& result, nlohmann::json& summary,
                       const OutputOptions& options = {});

// The map with intensity: every keyframe's raw scan re-read from the source, deskewed as the
// odometry deskewed (RunResult::deskewed_scans) at the final trajectory's velocity, range-cropped,
// moved by its corrected pose and voxel-averaged (centroid and mean intensity per voxel).
std::vector<LidarPoint> assemble_map(const ScanSource& source, const RunResult& result,
                                     const OutputOptions& options);

// Creates the folder if missing; refuses one that already holds a result (summary.json)
// unless `overwrite`.
void prepare_output_dir(const std::filesystem::path& out_dir, bool overwrite);

}  // namespace scfloam
