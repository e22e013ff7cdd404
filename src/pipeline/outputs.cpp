#include "scfloam/pipeline/outputs.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "scfloam/atomic_file.hpp"
#include "scfloam/backend/pose_graph.hpp"
#include "scfloam/error.hpp"
#include "scfloam/eval/report.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/loop/loops_csv.hpp"
#include "scfloam/registration/voxel_hash.hpp"
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

// The Tr to apply for the chosen frame, nullopt for lidar poses.
std::optional<Eigen::Isometry3d> output_Tr(const ScanSource& source, PoseFrame frame) {
  if (frame == PoseFrame::kLidar) return std::nullopt;
  return source.T_cam0_lidar();  // kCamera without Tr is refused by check_output_options
}

// Running sums of the points that fell into one voxel (doubles: map coordinates are large).
struct VoxelSum {
  double x = 0, y = 0, z = 0, intensity = 0;
  std::uint32_t count = 0;
};

class VoxelAverager {
 public:
  explicit VoxelAverager(double leaf_m) : inv_leaf_(static_cast<float>(1.0 / leaf_m)) { index_.reset(1 << 16); }
  void add(const LidarPoint& p) {
    const Eigen::Vector3i c = voxel_coords(Eigen::Vector3f(p.x, p.y, p.z), inv_leaf_);
    const std::uint32_t i = index_.insert(voxel_key(c.x(), c.y(), c.z()), static_cast<std::uint32_t>(sums_.size()));
    if (i == sums_.size()) sums_.emplace_back();
    VoxelSum& s = sums_[i];
    s.x += p.x, s.y += p.y, s.z += p.z, s.intensity += p.intensity, ++s.count;
  }
  std::vector<LidarPoint> points() const {
    std::vector<LidarPoint> out(sums_.size());
    for (std::size_t i = 0; i < sums_.size(); ++i) {
      const VoxelSum& s = sums_[i];
      out[i].x = static_cast<float>(s.x / s.count);
      out[i].y = static_cast<float>(s.y / s.count);
      out[i].z = static_cast<float>(s.z / s.count);
      out[i].intensity = static_cast<float>(s.intensity / s.count);
    }
    return out;
  }

 private:
  float inv_leaf_;
  FlatKeyIndex index_;
  std::vector<VoxelSum> sums_;
};

// A keyframe's raw scan, range-cropped and voxel-averaged in its own lidar frame.
std::vector<LidarPoint> keyframe_cloud(const ScanSource& source, std::size_t frame, const OutputOptions& options) {
  const Scan scan = source.load(frame);
  const double min_r2 = options.map_min_range_m * options.map_min_range_m;
  const double max_r2 = options.map_max_range_m * options.map_max_range_m;
  VoxelAverager voxels(options.map_voxel_m);
  for (const auto& p : scan.points) {
    const double r2 = double(p.x) * p.x + double(p.y) * p.y;
    if (r2 >= min_r2 && r2 <= max_r2) voxels.add(p);
  }
  return voxels.points();
}

// Keyframe poses relative to the first frame (lidar convention), as the map and keyframes/ use.
PoseList keyframe_poses_from_first(const RunResult& result) {
  PoseList kf;
  for (std::size_t i = 0; i < result.keyframe_frames.size(); ++i)
    kf.push_back(i < result.keyframe_poses.size() ? result.keyframe_poses[i]
                                                  : result.T_world_lidar.at(result.keyframe_frames[i]));
  if (!result.T_world_lidar.empty()) {
    const Eigen::Isometry3d first_inv = result.T_world_lidar.front().inverse();
    for (auto& T : kf) T = first_inv * T;
  }
  return kf;
}

// Keyframe clouds in batches: loaded in parallel (sources are thread-safe per index), merged
// in order so that the map does not depend on scheduling.
void for_each_keyframe_cloud(const ScanSource& source, const RunResult& result, const OutputOptions& options,
                             const std::function<void(std::size_t, const std::vector<LidarPoint>&)>& use) {
  constexpr std::size_t kBatch = 8;
  const std::size_t n = result.keyframe_frames.size();
  std::vector<std::vector<LidarPoint>> batch(kBatch);
  for (std::size_t begin = 0; begin < n; begin += kBatch) {
    const std::size_t end = std::min(n, begin + kBatch);
    tbb::parallel_for(begin, end, [&](std::size_t k) {
      batch[k - begin] = keyframe_cloud(source, result.keyframe_frames[k], options);
    });
    for (std::size_t k = begin; k < end; ++k) use(k, batch[k - begin]);
  }
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
  summary["elevation_correction_deg"] = {{"first_frame", result.elevation_correction_first_deg},
                                         {"last_frame", result.elevation_correction_last_deg}};
  const auto check_json = [](const SettingCheck& check) {
    nlohmann::json out = {{"check", check.verdict}};
    if (check.decided) out["decided_at_frame"] = check.decided_at_frame;
    if (check.decided || check.frames_compared > 0) out["frames_compared"] = check.frames_compared;
    if (check.frames_compared > 0) out["residual_ratio"] = check.residual_ratio;
    return out;
  };
  summary["deskew"] = check_json(result.deskew_check);
  summary["elevation_check"] = check_json(result.elevation_check);
  nlohmann::json rings = {{"source", result.ring_layout.source}, {"beams", result.ring_layout.beams}};
  if (result.ring_layout.source == "learned") {
    rings["highest_deg"] = result.ring_layout.highest_deg;
    rings["lowest_deg"] = result.ring_layout.lowest_deg;
    rings["reason"] = result.ring_layout.reason;
  } else if (result.ring_layout.scan_beams > 0) {
    rings["scan_beams"] = result.ring_layout.scan_beams;
    rings["cropped_beams"] = result.ring_layout.cropped_beams;
    rings["cropped_fraction"] = result.ring_layout.cropped_fraction;
  }
  summary["rings"] = rings;
  // Frames per number of correspondence rounds: {"2": frames, ...}; extra rounds past the
  // steady-state count show where the motion model was off.
  nlohmann::json rounds = nlohmann::json::object();
  for (std::size_t k = 0; k < result.registration_rounds.size(); ++k)
    if (result.registration_rounds[k]) rounds[std::to_string(k)] = result.registration_rounds[k];
  summary["registration_rounds"] = rounds;
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
                        {"rejected", result.loop_rows.size() - accepted},
                        // accepted without a graph solve: consistent with the estimate
                        {"solves_skipped", result.loop_solves_skipped},
                        {"solves_deferred", result.loop_solves_deferred},
                        {"window_solves", result.window_solves},
                        {"escalated_solves", result.escalated_solves},
                        // loops that close consistent short cycles with their neighbours
                        {"confirmed", result.confirmed_loops}};
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

std::optional<PoseFrame> parse_pose_frame(const std::string& name) {
  if (name == "lidar") return PoseFrame::kLidar;
  if (name == "camera") return PoseFrame::kCamera;
  if (name == "auto") return PoseFrame::kAuto;
  return std::nullopt;
}

void check_output_options(const ScanSource& source, const OutputOptions& options) {
  if (options.frame == PoseFrame::kCamera && !source.T_cam0_lidar())
    throw Error("--frame camera: the input has no lidar -> camera extrinsic (KITTI calib.txt `Tr:`); "
                "use --frame lidar (" + source.describe() + ")");
  if (!(options.map_voxel_m > 0)) throw Error("--map-voxel must be a positive size in metres");
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

std::vector<LidarPoint> assemble_map(const ScanSource& source, const RunResult& result,
                                     const OutputOptions& options) {
  const PoseList poses = keyframe_poses_from_first(result);
  VoxelAverager map(options.map_voxel_m);
  for_each_keyframe_cloud(source, result, options, [&](std::size_t k, const std::vector<LidarPoint>& cloud) {
    const Eigen::Isometry3f T = poses[k].cast<float>();
    for (LidarPoint p : cloud) {
      const Eigen::Vector3f w = T * Eigen::Vector3f(p.x, p.y, p.z);
      p.x = w.x(), p.y = w.y(), p.z = w.z();
      map.add(p);
    }
  });
  return map.points();
}

namespace {

// keyframes/NNNNNN.pcd (lidar frame), poses_kitti.txt (lidar poses relative to the first
// frame: map = union of pose * cloud), frames.txt (input frame index and stamp of each).
void write_keyframes(const fs::path& dir, const ScanSource& source, const RunResult& result,
                     const OutputOptions& options) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw file_error(dir, "cannot create the folder: " + ec.message());
  for_each_keyframe_cloud(source, result, options, [&](std::size_t k, const std::vector<LidarPoint>& cloud) {
    char name[32];
    std::snprintf(name, sizeof name, "%06zu.pcd", k);
    write_pcd_binary(dir / name, cloud);
  });
  write_kitti_poses(dir / "poses_kitti.txt", keyframe_poses_from_first(result));
  std::string frames = "# keyframe frame stamp_s\n";
  char line[96];
  for (std::size_t k = 0; k < result.keyframe_frames.size(); ++k) {
    const std::size_t f = result.keyframe_frames[k];
    std::snprintf(line, sizeof line, "%zu %zu %.9f\n", k, f, f < result.stamps_s.size() ? result.stamps_s[f] : 0.0);
    frames += line;
  }
  write_file_atomic(dir / "frames.txt", frames);
}

}  // namespace

void write_run_outputs(const fs::path& out_dir, const ScanSource& source, const RunResult& result,
                       const nlohmann::json& summary, const OutputOptions& options) {
  check_output_options(source, options);
  const auto Tr = output_Tr(source, options.frame);
  auto convention = [&](const PoseList& lidar) {
    const PoseList rel = relative_to_first(lidar);
    return Tr ? lidar_to_camera_poses(rel, *Tr) : rel;
  };
  write_kitti_poses(out_dir / "poses_kitti.txt", convention(result.T_world_lidar));
  write_kitti_poses(out_dir / "odometry_kitti.txt", convention(result.odometry_T_world_lidar));
  write_tum(out_dir / "poses_tum.txt", StampedTrajectory{result.stamps_s, relative_to_first(result.T_world_lidar)});
  if (!result.keyframe_frames.empty()) {
    // Keyframe poses in the same convention and origin as poses_kitti.txt.
    const PoseList kf = keyframe_poses_from_first(result);
    write_kitti_poses(out_dir / "keyframes_kitti.txt", Tr ? lidar_to_camera_poses(kf, *Tr) : kf);
  }
  if (result.mode != SlamMode::kOdometry) write_loops_csv(out_dir / "loops.csv", result.loop_rows);
  if (result.graph) result.graph->write_g2o(out_dir / "graph.g2o");
  if (!result.keyframe_frames.empty()) {
    const std::vector<LidarPoint> map = assemble_map(source, result, options);
    write_pcd_binary(out_dir / "map.pcd", map);
    if (options.write_ply) write_ply(out_dir / "map.ply", map, PlyEncoding::kBinaryLittleEndian);
    if (options.save_keyframes) write_keyframes(out_dir / "keyframes", source, result, options);
  }
  write_file_atomic(out_dir / "summary.json", summary.dump(2) + "\n");
}

}  // namespace scfloam
