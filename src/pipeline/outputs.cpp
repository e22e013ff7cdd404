#include "scfloam/pipeline/outputs.hpp"

#include <cmath>

#include "scfloam/atomic_file.hpp"
#include "scfloam/backend/pose_graph.hpp"
#include "scfloam/error.hpp"
#include "scfloam/eval/report.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/loop/loops_csv.hpp"
#include "scfloam/registration/voxel_filter.hpp"
#include "scfloam/stats.hpp"

namespace scfloam {
namespace fs = std::filesystem;
namespace {

// Poses relative to the first one, so that the first pose is the identity as KITTI expects.
PoseList relative_to_first(const PoseList& poses) {
  PoseList out;
  if (poses.empty()) return out;
  const Eigen::Isometry3d first_inv = poses.front().inverse();
  for (const auto& T : poses) out.push_back(first_inv * T);
  return out;
}

// KITTI camera-0 convention when the source has Tr, else the lidar poses themselves.
PoseList kitti_convention(const ScanSource& source, const PoseList& lidar) {
  const auto Tr = source.T_cam0_lidar();
  return Tr ? lidar_to_camera_poses(relative_to_first(lidar), *Tr) : relative_to_first(lidar);
}

nlohmann::json accuracy_json(const PoseList& gt, const PoseList& est) {
  const EvalReport report = evaluate_trajectory(gt, est);
  return nlohmann::json::parse(eval_json(report));
}

}  // namespace

nlohmann::json make_summary(const ScanSource& source, const RunResult& result) {
  nlohmann::json summary;
  summary["input"] = source.describe();
  summary["mode"] = mode_name(result.mode);
  summary["frames"] = result.T_world_lidar.size();
  summary["keyframes"] = result.keyframe_frames.size();
  summary["degenerate_frames"] = result.degenerate_frames;
  summary["wall_s"] = result.wall_s;
  summary["fps"] = result.wall_s > 0 ? result.T_world_lidar.size() / result.wall_s : 0.0;
  summary["peak_rss_mb"] = peak_rss_mb();
  nlohmann::json timing = nlohmann::json::object();
  for (const auto& [stage, samples] : result.timing_ms) {
    const TimingStats s = summarize(samples);
    timing[stage] = {{"median", s.median}, {"mean", s.mean}, {"p95", s.p95}, {"count", s.count}};
  }
  summary["timing_ms"] = timing;
  if (result.mode != SlamMode::kOdometry) {
    std::size_t accepted = 0;
    for (const auto& row : result.loop_rows) accepted += row.verdict == LoopVerdict::kAccepted;
    summary["loops"] = {{"candidates", result.loop_rows.size()},
                        {"accepted", accepted},
                        {"rejected", result.loop_rows.size() - accepted}};
  }
  // Accuracy against the source's ground truth, when it has one for every processed frame.
  const PoseList gt_lidar = source.ground_truth_lidar();
  if (gt_lidar.size() >= result.T_world_lidar.size() && !result.T_world_lidar.empty()) {
    const PoseList gt(gt_lidar.begin(), gt_lidar.begin() + result.T_world_lidar.size());
    const PoseList gt_kitti = kitti_convention(source, gt);
    summary["accuracy"] = accuracy_json(gt_kitti, kitti_convention(source, result.T_world_lidar));
    if (result.mode != SlamMode::kOdometry)
      summary["odometry_accuracy"] =
          accuracy_json(gt_kitti, kitti_convention(source, result.odometry_T_world_lidar));
  }
  return summary;
}

void prepare_output_dir(const fs::path& out_dir, bool overwrite) {
  std::error_code ec;
  if (fs::exists(out_dir) && !fs::is_directory(out_dir))
    throw file_error(out_dir, "exists and is not a directory");
  if (!overwrite && fs::exists(out_dir / "summary.json"))
    throw file_error(out_dir, "already holds a result (summary.json); pass --force to overwrite");
  fs::create_directories(out_dir, ec);
  if (ec) throw file_error(out_dir, "cannot create the output folder: " + ec.message());
}

std::vector<LidarPoint> assemble_map(const RunResult& result, double leaf_m) {
  FeatureCloud world;
  for (std::size_t i = 0; i < result.keyframes.size() && i < result.keyframe_poses.size(); ++i) {
    const Eigen::Isometry3f T = result.keyframe_poses[i].cast<float>();
    for (const auto* cloud : {&result.keyframes[i]->edges, &result.keyframes[i]->planes})
      for (const auto& p : *cloud) world.push_back(T * p);
  }
  const FeatureCloud reduced = voxel_downsample(world, leaf_m);
  std::vector<LidarPoint> points(reduced.size());
  for (std::size_t i = 0; i < reduced.size(); ++i) {
    points[i].x = reduced[i].x();
    points[i].y = reduced[i].y();
    points[i].z = reduced[i].z();
  }
  return points;
}

void write_run_outputs(const fs::path& out_dir, const ScanSource& source, const RunResult& result,
                       const nlohmann::json& summary) {
  const PoseList lidar = relative_to_first(result.T_world_lidar);
  write_kitti_poses(out_dir / "poses_kitti.txt", kitti_convention(source, result.T_world_lidar));
  write_kitti_poses(out_dir / "odometry_kitti.txt",
                    kitti_convention(source, result.odometry_T_world_lidar));
  write_tum(out_dir / "poses_tum.txt", StampedTrajectory{result.stamps_s, lidar});
  if (!result.keyframe_poses.empty()) {
    // Keyframe poses in the same convention and origin as poses_kitti.txt.
    PoseList kf = result.keyframe_poses;
    if (!result.T_world_lidar.empty()) {
      const Eigen::Isometry3d first_inv = result.T_world_lidar.front().inverse();
      for (auto& T : kf) T = first_inv * T;
    }
    const auto Tr = source.T_cam0_lidar();
    write_kitti_poses(out_dir / "keyframes_kitti.txt", Tr ? lidar_to_camera_poses(kf, *Tr) : kf);
  }
  if (result.mode != SlamMode::kOdometry) write_loops_csv(out_dir / "loops.csv", result.loop_rows);
  if (result.graph) result.graph->write_g2o(out_dir / "graph.g2o");
  if (!result.keyframes.empty()) write_pcd_binary(out_dir / "map.pcd", assemble_map(result, 0.2));
  write_file_atomic(out_dir / "summary.json", summary.dump(2) + "\n");
}

}  // namespace scfloam
