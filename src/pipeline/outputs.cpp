#include "scfloam/pipeline/outputs.hpp"

#include <cmath>

#include "scfloam/atomic_file.hpp"
#include "scfloam/error.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/stats.hpp"

namespace scfloam {
namespace fs = std::filesystem;

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

void write_run_outputs(const fs::path& out_dir, const ScanSource& source, const RunResult& result,
                       const nlohmann::json& summary) {
  // Poses relative to the first frame, so that the first pose is the identity as KITTI expects.
  auto relative_to_first = [](const PoseList& poses) {
    PoseList out;
    if (poses.empty()) return out;
    const Eigen::Isometry3d first_inv = poses.front().inverse();
    for (const auto& T : poses) out.push_back(first_inv * T);
    return out;
  };
  const PoseList lidar = relative_to_first(result.T_world_lidar);
  const PoseList odometry = relative_to_first(result.odometry_T_world_lidar);
  const auto Tr = source.T_cam0_lidar();
  write_kitti_poses(out_dir / "poses_kitti.txt", Tr ? lidar_to_camera_poses(lidar, *Tr) : lidar);
  write_kitti_poses(out_dir / "odometry_kitti.txt",
                    Tr ? lidar_to_camera_poses(odometry, *Tr) : odometry);
  write_tum(out_dir / "poses_tum.txt", StampedTrajectory{result.stamps_s, lidar});
  write_file_atomic(out_dir / "summary.json", summary.dump(2) + "\n");
}

}  // namespace scfloam
