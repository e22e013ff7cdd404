// What a run leaves in its output folder: trajectories and summary.json (docs/formats.md).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "scfloam/io/scan_source.hpp"
#include "scfloam/pipeline/pipeline.hpp"

namespace scfloam {

// summary.json's content: frames, keyframes, wall_s, peak_rss_mb, timing_ms{stage: {median,
// mean, p95, count}}, and accuracy against ground truth when the source has it.
nlohmann::json make_summary(const ScanSource& source, const RunResult& result);

// poses_kitti.txt (every frame; camera-0 convention when the source has Tr, else lidar),
// poses_tum.txt (timestamped lidar poses), odometry_kitti.txt, keyframes_kitti.txt, loops.csv,
// graph.g2o, map.pcd, summary.json. Every file is written atomically.
void write_run_outputs(const std::filesystem::path& out_dir, const ScanSource& source,
                       const RunResult& result, const nlohmann::json& summary);

// The corrected keyframe feature clouds in the map frame, voxel-downsampled at leaf_m.
std::vector<LidarPoint> assemble_map(const RunResult& result, double leaf_m);

// Refuses to reuse a folder that already holds a result unless `overwrite`.
void prepare_output_dir(const std::filesystem::path& out_dir, bool overwrite);

}  // namespace scfloam
