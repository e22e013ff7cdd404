#include "scfloam/pipeline/outputs.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <functional>

#include "scfloam/atomic_file.hpp"
#include "scfloam/backend/pose_graph.hpp"
#include "scfloam/error.hpp"
#include "scfloam/eval/report.hpp"
#include "scfloam/features/deskew.hpp"
#include "scfloam/features/sweep_times.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/trajectory.hpp"
#include "scfloam/loop/loops_csv.hpp"
#include "scfloam/registration/voxel_hash.hpp"
#include "scfloam/se3.hpp"
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

// Running sums of the points that fell into one voxel, as offsets from the voxel's corner:
// floats keep them exact to the input there, where sums of map coordinates (kilometres) would
// need doubles, and the map of a long drive has millions of voxels (KITTI-00-like: 10.5 M).
struct VoxelSum {
  std::int32_t cx = 0, cy = 0, cz = 0;  // the voxel
  float x = 0, y = 0, z = 0, intensity = 0;
  std::uint32_t count = 0;
};

// Centroid and mean intensity per voxel. Memory matters for the whole map: the sums live in a
// deque (no copy of everything when it grows, as a vector's doubling makes), the index runs to
// 75 % load, and take_points() releases both as it builds the result. Measured on the
// KITTI-00-like replay (10.5 M voxels), the process's peak: 1450 MB before, see
// docs/benchmarks.md "Session 36".
class VoxelAverager {
 public:
  explicit VoxelAverager(double leaf_m)
      : leaf_(static_cast<float>(leaf_m)), inv_leaf_(static_cast<float>(1.0 / leaf_m)), index_(FlatKeyIndex::MaxLoad::kThreeQuarters) {
    index_.reset(1 << 16);
  }
  void add(const LidarPoint& p) {
    const Eigen::Vector3i c = voxel_coords(Eigen::Vector3f(p.x, p.y, p.z), inv_leaf_);
    const std::uint32_t i = index_.insert(voxel_key(c.x(), c.y(), c.z()), static_cast<std::uint32_t>(sums_.size()));
    if (i == sums_.size()) sums_.push_back(VoxelSum{c.x(), c.y(), c.z()});
    VoxelSum& s = sums_[i];
    s.x += p.x - static_cast<float>(c.x()) * leaf_;
    s.y += p.y - static_cast<float>(c.y()) * leaf_;
    s.z += p.z - static_cast<float>(c.z()) * leaf_;
    s.intensity += p.intensity;
    ++s.count;
  }
  // The voxels' centroids, in the order they were first filled; empties the averager.
  std::vector<LidarPoint> take_points() {
    index_ = FlatKeyIndex(FlatKeyIndex::MaxLoad::kThreeQuarters);
    std::vector<LidarPoint> out;
    out.reserve(sums_.size());
    while (!sums_.empty()) {
      const VoxelSum& s = sums_.front();
      LidarPoint p;
      p.x = static_cast<float>(s.cx) * leaf_ + s.x / static_cast<float>(s.count);
      p.y = static_cast<float>(s.cy) * leaf_ + s.y / static_cast<float>(s.count);
      p.z = static_cast<float>(s.cz) * leaf_ + s.z / static_cast<float>(s.count);
      p.intensity = s.intensity / static_cast<float>(s.count);
      out.push_back(p);
      sums_.pop_front();  // frees the deque's blocks as they empty
    }
    return out;
  }

 private:
  float leaf_, inv_leaf_;
  FlatKeyIndex index_;
  std::deque<VoxelSum> sums_;
};

// The sensor's velocity (body frame: angular, linear) at `frame` from the run's final
// trajectory, over the intervals either side of it; nullopt with a single pose or no time step.
std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> frame_velocity(const RunResult& result,
                                                                          std::size_t frame) {
  const PoseList& T = result.T_world_lidar;
  if (T.size() < 2 || result.stamps_s.size() != T.size() || frame >= T.size()) return std::nullopt;
  const std::size_t a = frame > 0 ? frame - 1 : frame, b = frame + 1 < T.size() ? frame + 1 : frame;
  const double dt = result.stamps_s[b] - result.stamps_s[a];
  if (!(dt > 0)) return std::nullopt;
  const Eigen::Vector3d omega = so3_log(T[a].linear().transpose() * T[b].linear()) / dt;
  const Eigen::Vector3d velocity = T[frame].linear().transpose() * (T[b].translation() - T[a].translation()) / dt;
  return std::make_pair(omega, velocity);
}

// A keyframe's raw scan, deskewed when the odometry deskewed (poses are at the stamps, so to
// the stamp), range-cropped and voxel-averaged in its own lidar frame. Raw sweeps left as
// they are would smear the map by the distance driven in a sweep (~1 m at 10 m/s).
std::vector<LidarPoint> keyframe_cloud(const ScanSource& source, const RunResult& result, std::size_t frame,
                                       const OutputOptions& options) {
  Scan scan = source.load(frame);
  if (result.deskewed_scans && !scan.has_time && result.azimuth_times && result.azimuth_times->usable)
    scan.has_time = assign_times_from_azimuth(scan.points, result.azimuth_times->sweep_period_s,
                                              result.azimuth_times->stamp_fraction, &*result.azimuth_times)
                        .usable;
  if (result.deskewed_scans && scan.has_time)
    if (const auto velocity = frame_velocity(result, frame))
      deskew_constant_velocity(scan.points, velocity->first, velocity->second);
  const double min_r2 = options.map_min_range_m * options.map_min_range_m;
  const double max_r2 = options.map_max_range_m * options.map_max_range_m;
  VoxelAverager voxels(options.map_voxel_m);
  for (const auto& p : scan.points) {
    const double r2 = double(p.x) * p.x + double(p.y) * p.y;
    if (r2 >= min_r2 && r2 <= max_r2) voxels.add(p);
  }
  return voxels.take_points();
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
      batch[k - begin] = keyframe_cloud(source, result, result.keyframe_frames[k], options);
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
  summary["deskew"]["redeskewed_frames"] = result.redeskewed_frames;
  if (const auto& sweep = result.azimuth_times) {
    // Scans without point times: whether their order gave times from the azimuth.
    nlohmann::json times = {{"from", "azimuth"}, {"usable", sweep->usable}};
    if (sweep->usable) {
      times["turn"] = sweep->clockwise ? "clockwise" : "counterclockwise";
      times["order"] = sweep->ring_major ? "beam by beam" : "column by column";
      times["seam_deg"] = sweep->seam_rad * 180 / M_PI;
      times["sweep_period_s"] = sweep->sweep_period_s;
      times["stamp_fraction"] = sweep->stamp_fraction;
    } else {
      times["why_not"] = sweep->why;
    }
    summary["deskew"]["times"] = times;
  }
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
  return map.take_points();
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
                       nlohmann::json& summary, const OutputOptions& options) {
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
  summary["peak_rss_mb"] = peak_rss_mb();
  write_file_atomic(out_dir / "summary.json", summary.dump(2) + "\n");
}

}  // namespace scfloam
