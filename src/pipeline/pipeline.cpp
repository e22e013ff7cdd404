// The three stages of the paper, joined by bounded queues:
//   odometry (this thread) -> loop detection (thread) -> loop registration + pose graph (thread)
// Corrected keyframe poses flow back through the KeyframeStore: the odometry re-anchors its
// local map on them, the detector's distance gate uses them.
#include "scfloam/pipeline/pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <unordered_set>
#include <utility>

#include "pipeline/keyframe_store.hpp"
#include "pipeline/loop_closure.hpp"
#include "scfloam/backend/pose_graph.hpp"
#include "scfloam/bounded_queue.hpp"
#include "scfloam/error.hpp"
#include "scfloam/loop/keyframe_selector.hpp"
#include "scfloam/loop/loop_detector.hpp"
#include "scfloam/loop/loop_registration.hpp"
#include "scfloam/odometry/odometry.hpp"
#include "scfloam/progress.hpp"
#include "scfloam/registration/voxel_filter.hpp"
#include "scfloam/se3.hpp"
#include "scfloam/stats.hpp"
#include "scfloam/thread_priority.hpp"

namespace scfloam {
namespace {

// Reads scans on its own thread so that disk and decoding overlap the odometry.
class ScanPrefetcher {
 public:
  ScanPrefetcher(const ScanSource& source, std::size_t count) : queue_(8) {
    thread_ = std::thread([this, &source, count] {
      try {
        for (std::size_t i = 0; i < count; ++i)
          if (!queue_.push({i, source.load(i)})) return;
      } catch (...) {
        error_ = std::current_exception();
      }
      queue_.close();
    });
  }
  ~ScanPrefetcher() {
    queue_.close();
    thread_.join();
  }
  // The next scan in order, or nullopt at the end; rethrows a reader's error.
  std::optional<std::pair<std::size_t, Scan>> next() {
    auto item = queue_.pop();
    if (!item && error_) std::rethrow_exception(error_);
    return item;
  }

 private:
  BoundedQueue<std::pair<std::size_t, Scan>> queue_;
  std::exception_ptr error_;
  std::thread thread_;
};

// What each mode changes in the configuration (the paper's Table I methods).
SlamConfig configure_for_mode(SlamConfig config, SlamMode mode) {
  if (mode == SlamMode::kSimpleSc) {
    config.loop_detection.descriptor_from_features = false;
    config.loop_detection.adaptive_gate = false;
  } else if (mode == SlamMode::kOptimized) {
    config.loop_detection.descriptor_from_features = true;
    config.loop_detection.adaptive_gate = true;
  }
  return config;
}

FeatureCloud downsampled_raw(const Scan& scan, double leaf_m, VoxelFilter& filter) {
  FeatureCloud points, out;
  points.reserve(scan.points.size());
  for (const auto& p : scan.points) points.emplace_back(p.x, p.y, p.z);
  filter.filter(points, leaf_m, out);
  return out;
}

struct DetectedKeyframe {
  KeyframePtr keyframe;
  LoopQuery query;
};

// Loop detection for one keyframe, with the gate on the best current poses.
class DetectionStage {
 public:
  DetectionStage(const LoopDetectionConfig& config, const KeyframeStore& store)
      : detector_(config), store_(store) {}

  LoopQuery detect(const KeyframePtr& kf) {
    Stopwatch watch;
    if (store_.version() != seen_version_) {
      seen_version_ = store_.version();
      PoseList poses = store_.current_poses();
      poses.resize(std::min(poses.size(), detector_.size()));
      detector_.update_poses(poses);
    }
    const Eigen::Isometry3d T_world_kf = store_.current_pose(kf->index);
    LoopQuery query =
        detector_.config().descriptor_from_features
            ? detector_.add_keyframe(static_cast<std::int64_t>(kf->frame), T_world_kf, kf->edges,
                                     kf->planes)
            : detector_.add_keyframe(static_cast<std::int64_t>(kf->frame), T_world_kf, kf->raw);
    ms_.push_back(watch.elapsed_ms());
    return query;
  }
  const std::vector<double>& ms() const { return ms_; }

 private:
  LoopDetector detector_;
  const KeyframeStore& store_;
  std::uint64_t seen_version_ = 0;
  std::vector<double> ms_;
};

// Loop detection and loop closure on their own threads, fed keyframe by keyframe. `live`
// (may be null) gets the queue depths after every push and pop.
class LoopThreads {
 public:
  LoopThreads(DetectionStage& detection, LoopClosure& closure, const KeyframeStore& store,
              int capacity, int nice, int max_lag, LiveCounters* live)
      : to_detection_(capacity), to_closure_(capacity), max_lag_(max_lag), live_(live) {
    detection_thread_ = std::thread([this, &detection, nice] {
      lower_current_thread_priority(nice);
      guarded([&] {
        while (auto kf = to_detection_.pop()) {
          report_depths();
          to_closure_.push({*kf, detection.detect(*kf)});
          report_depths();
        }
      });
      to_closure_.close();
    });
    closure_thread_ = std::thread([this, &closure, &store, nice] {
      lower_current_thread_priority(nice);
      guarded([&] {
        while (auto item = to_closure_.pop()) {
          report_depths();
          const KeyframeStore::Hold hold(store);  // its submap views point into clouds
          const bool backlog = to_closure_.size() > 0;
          closure.add(item->keyframe, item->query, backlog);
          if (!backlog) closure.solve_deferred();  // caught up: one solve for the waiting loops
          {
            std::lock_guard<std::mutex> lock(lag_mutex_);
            ++closed_;
          }
          lag_changed_.notify_all();
        }
      });
    });
  }
  ~LoopThreads() { finish(); }

  void push(KeyframePtr kf) {
    {
      std::lock_guard<std::mutex> lock(lag_mutex_);
      pushed_frames_.push_back(kf->frame);
    }
    to_detection_.push(std::move(kf));
    report_depths();
  }
  // Before the odometry processes scan `frame`: waits until every keyframe made before scan
  // frame - max_lag has been through loop closure (no wait when max_lag < 0).
  void wait_for_lag(std::size_t frame) {
    if (max_lag_ < 0) return;
    std::unique_lock<std::mutex> lock(lag_mutex_);
    lag_changed_.wait(lock, [&] {
      return stopped_ || closed_ == pushed_frames_.size() ||
             static_cast<std::int64_t>(pushed_frames_[closed_]) + max_lag_ >=
                 static_cast<std::int64_t>(frame);
    });
  }
  // Waits for every keyframe to be handled; rethrows a stage's error.
  void finish() {
    to_detection_.close();
    if (detection_thread_.joinable()) detection_thread_.join();
    if (closure_thread_.joinable()) closure_thread_.join();
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }

 private:
  void report_depths() {
    if (!live_) return;
    live_->detection_queue.store(to_detection_.size(), std::memory_order_relaxed);
    live_->closure_queue.store(to_closure_.size(), std::memory_order_relaxed);
  }

  template <typename F>
  void guarded(F&& work) {
    try {
      work();
    } catch (...) {
      {
        std::lock_guard<std::mutex> lock(error_mutex_);
        if (!error_) error_ = std::current_exception();
      }
      to_detection_.close();
      to_closure_.close();
      {
        std::lock_guard<std::mutex> lock(lag_mutex_);
        stopped_ = true;  // a waiting push goes on, into a closed queue
      }
      lag_changed_.notify_all();
    }
  }

  BoundedQueue<KeyframePtr> to_detection_;
  BoundedQueue<DetectedKeyframe> to_closure_;
  std::int64_t max_lag_;  // frames (pipeline.max_loop_lag_frames)
  LiveCounters* live_;
  std::mutex lag_mutex_;  // guards the three below
  std::condition_variable lag_changed_;
  std::vector<std::size_t> pushed_frames_;  // scan index of every keyframe handed over
  std::size_t closed_ = 0;                  // keyframes the closure stage has finished
  bool stopped_ = false;                    // a stage failed
  std::thread detection_thread_, closure_thread_;
  std::mutex error_mutex_;
  std::exception_ptr error_;
};

// The odometry's side: keyframe selection, re-anchoring on corrected poses, per-frame anchors.
class OdometryStage {
 public:
  OdometryStage(const SlamConfig& config, KeyframeStore& store, bool loops)
      : config_(config),
        store_(store),
        loops_(loops),
        odometry_(config.odometry),
        selector_(config.loop_detection.keyframe_distance_m,
                  config.loop_detection.keyframe_angle_deg * M_PI / 180.0) {}

  // Processes one scan; returns the keyframes made. While one of the odometry's setting checks
  // runs, its frames are held (no keyframe, no trajectory yet): if the check switches to the
  // other setting, that setting's results replace them (OdometryResult::revised), so that
  // neither the keyframes nor the trajectory carry the setting it dropped. A trial lasts
  // 2-30 s at the start of a run.
  std::vector<KeyframePtr> process(std::size_t frame, const Scan& scan, RunResult& result) {
    // A correction re-anchors the odometry's frame: not while frames in the old one are held.
    if (loops_ && store_.version() != seen_version_ && held_.empty()) {
      Stopwatch watch;
      reanchor();
      result.timing_ms["map_rebuild"].push_back(watch.elapsed_ms());
    }
    OdometryResult odom = odometry_.process(scan);
    if (odom.redeskewed) ++result.redeskewed_frames;
    result.stamps_s.push_back(scan.timestamp_s);
    result.timing_ms["features"].push_back(odom.features_ms);
    result.timing_ms["registration"].push_back(odom.registration_ms);
    result.deskew_check = odometry_.deskew_check();
    result.elevation_check = odometry_.elevation_check();
    result.deskewed_scans = odometry_.deskews();
    result.azimuth_times = odometry_.azimuth_times();
    if (result.stamps_s.size() == 1 || result.ring_layout.source != odometry_.ring_layout().source)
      result.ring_layout = odometry_.ring_layout();

    if (!odom.revised.empty()) {
      if (odom.revised.size() > held_.size())
        throw std::logic_error("the odometry revised frames the pipeline did not hold");
      const std::size_t first = held_.size() - odom.revised.size();
      for (std::size_t i = 0; i < odom.revised.size(); ++i) held_[first + i].odom = std::move(odom.revised[i]);
      odom.revised.clear();
    }
    held_.push_back({frame, std::move(odom), std::nullopt});
    if (odometry_.may_revise()) {
      // A held frame's scan is gone by the time it may become a keyframe; the raw cloud does
      // not depend on the odometry's settings.
      if (raw_clouds()) held_.back().raw = downsampled_raw(scan, config_.pipeline.raw_leaf_m, raw_filter_);
      return {};
    }
    return flush(result, &scan);
  }

  // Accepts the held frames; `scan` is the last one's, if it has no raw cloud yet. (At the end
  // of the input, a trial still running keeps the configured setting's results, as an
  // undecided check does.)
  std::vector<KeyframePtr> flush(RunResult& result, const Scan* scan = nullptr) {
    std::vector<KeyframePtr> made;
    for (HeldFrame& held : held_)
      if (KeyframePtr kf = accept(held, result, scan)) made.push_back(std::move(kf));
    held_.clear();
    return made;
  }

  // Every frame placed on its keyframe's final pose.
  PoseList final_poses(const PoseList& keyframe_poses) const {
    PoseList out;
    out.reserve(anchors_.size());
    for (const auto& [kf, T_kf_frame] : anchors_) out.push_back(keyframe_poses.at(kf) * T_kf_frame);
    return out;
  }

 private:
  struct HeldFrame {
    std::size_t frame;
    OdometryResult odom;
    std::optional<FeatureCloud> raw;  // raw_clouds(): taken while the scan was at hand
  };

  // Keyframes carry a downsampled raw cloud for raw-scan descriptors (simple-sc).
  bool raw_clouds() const { return loops_ && !config_.loop_detection.descriptor_from_features; }

  // The frame's pose into the trajectory; returns the keyframe it made, if any.
  KeyframePtr accept(HeldFrame& held, RunResult& result, const Scan* scan) {
    OdometryResult& odom = held.odom;
    // The odometry's own chain of relative motions: its trajectory before any correction.
    const Eigen::Isometry3d T_last_current = has_last_ ? T_world_last_.inverse() * odom.T_world_lidar
                                                       : Eigen::Isometry3d::Identity();
    T_chain_ = orthonormalized(T_chain_ * T_last_current);
    T_world_last_ = odom.T_world_lidar;
    has_last_ = true;
    result.odometry_T_world_lidar.push_back(T_chain_);
    if (odom.degenerate) ++result.degenerate_frames;
    const auto rounds = static_cast<std::size_t>(std::max(0, odom.registration_rounds));
    if (result.registration_rounds.size() <= rounds) result.registration_rounds.resize(rounds + 1, 0);
    ++result.registration_rounds[rounds];
    if (result.odometry_T_world_lidar.size() == 1) result.elevation_correction_first_deg = odom.elevation_correction_deg;
    result.elevation_correction_last_deg = odom.elevation_correction_deg;

    KeyframePtr made;
    if (selector_.update(T_chain_)) {
      auto kf = std::make_shared<Keyframe>();
      kf->index = kf_poses_.size();
      kf->frame = held.frame;
      kf->T_prev_current = kf_poses_.empty() ? Eigen::Isometry3d::Identity()
                                             : kf_poses_.back().inverse() * odom.T_world_lidar;
      kf->edges = std::move(odom.edges);
      kf->planes = std::move(odom.planes);
      if (raw_clouds()) {
        if (held.raw) kf->raw = std::move(*held.raw);
        else if (scan) kf->raw = downsampled_raw(*scan, config_.pipeline.raw_leaf_m, raw_filter_);
        else throw std::logic_error("a held keyframe without its raw cloud");
      }
      kf_poses_.push_back(odom.T_world_lidar);
      result.keyframe_frames.push_back(held.frame);
      store_.add(kf);  // the map is assembled from keyframes in every mode
      made = kf;
    }
    anchors_.push_back({kf_poses_.size() - 1, kf_poses_.back().inverse() * odom.T_world_lidar});
    return made;
  }

  // The graph moved the keyframes: move the odometry's frame with them and rebuild its local
  // map from the corrected keyframes around the current position.
  void reanchor() {
    seen_version_ = store_.version();
    const PoseList corrected = store_.current_poses();
    if (corrected.size() != kf_poses_.size() || kf_poses_.empty()) return;  // cannot happen
    if (!map_needs_rebuild(corrected)) return;  // the odometry stays in its frame, unharmed
    const Eigen::Isometry3d correction = corrected.back() * kf_poses_.back().inverse();
    const Eigen::Isometry3d T_world_now = orthonormalized(correction * T_world_last_);
    kf_poses_ = corrected;
    T_world_last_ = T_world_now;
    std::vector<std::pair<Eigen::Isometry3d, const FeatureCloud*>> edges, planes;
    std::vector<KeyframePtr> keep;
    const double radius = config_.odometry.map.radius_m;
    const double cell_m = config_.pipeline.map_rebuild_cell_m;
    std::unordered_set<std::uint64_t> taken;  // cells that already have a newer keyframe
    for (std::size_t i = corrected.size(); i-- > 0;) {
      const Eigen::Vector3d p = corrected[i].translation();
      if ((p - T_world_now.translation()).norm() > radius) continue;
      // On a revisit the newest keyframe of a place stands for the older ones: the rebuild
      // (and the memory it reads back) is bounded by the area, not by the laps driven.
      if (cell_m > 0 && !taken.insert(cell_key(p, cell_m)).second) continue;
      keep.push_back(store_.get(i));
      edges.emplace_back(corrected[i], &keep.back()->edges);
      planes.emplace_back(corrected[i], &keep.back()->planes);
    }
    // Inserted oldest first, as the odometry itself built the map.
    std::reverse(edges.begin(), edges.end());
    std::reverse(planes.begin(), planes.end());
    odometry_.reset_map(edges, planes, T_world_now);
    last_rebuild_position_ = T_world_now.translation();
  }

  static std::uint64_t cell_key(const Eigen::Vector3d& p, double cell_m) {
    const auto c = [&](double v) {
      return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v / cell_m)) & 0x1FFFFF);
    };
    return (c(p.x()) << 42) | (c(p.y()) << 21) | c(p.z());
  }

  // Rebuilding costs hundreds of milliseconds (every keyframe within the map radius). The
  // loops after the first of an episode move the keyframes around here by millimetres:
  // then the map is as good as rebuilt, and the pose graph alone carries the correction.
  bool map_needs_rebuild(const PoseList& corrected) const {
    if (!config_.pipeline.rebuild_map_after_loop) return false;
    const double min_shift_m = config_.pipeline.map_rebuild_min_shift_m;
    const double radius_m = config_.odometry.map.radius_m;
    const Eigen::Vector3d here = kf_poses_.back().translation();
    if (min_shift_m <= 0 || (here - last_rebuild_position_).norm() > 0.2 * radius_m) return true;
    constexpr double kLeverArm_m = 30.0;  // typical range of a map point from its keyframe
    const Eigen::Isometry3d old_inv = kf_poses_.back().inverse();
    const Eigen::Isometry3d new_inv = corrected.back().inverse();
    for (std::size_t i = 0; i < kf_poses_.size(); ++i) {
      if ((kf_poses_[i].translation() - here).norm() > radius_m) continue;
      const Eigen::Isometry3d change = (old_inv * kf_poses_[i]).inverse() * (new_inv * corrected[i]);
      const double shift_m =
          change.translation().norm() + kLeverArm_m * rotation_angle_rad(change.linear());
      if (shift_m > min_shift_m) return true;
    }
    return false;
  }

  const SlamConfig& config_;
  KeyframeStore& store_;
  bool loops_;
  Odometry odometry_;
  KeyframeSelector selector_;
  VoxelFilter raw_filter_;
  std::uint64_t seen_version_ = 0;
  PoseList kf_poses_;  // keyframe poses in the odometry's current frame
  std::vector<std::pair<std::size_t, Eigen::Isometry3d>> anchors_;  // per frame: kf, T_kf_frame
  Eigen::Isometry3d T_world_last_ = Eigen::Isometry3d::Identity();
  // Far from anything at the start, so that the first correction rebuilds.
  Eigen::Vector3d last_rebuild_position_ = Eigen::Vector3d::Constant(1e9);
  Eigen::Isometry3d T_chain_ = Eigen::Isometry3d::Identity();
  bool has_last_ = false;
  std::vector<HeldFrame> held_;  // frames of a running setting check, oldest first
};

}  // namespace

RunResult run_slam(const ScanSource& source, const SlamConfig& base_config,
                   const RunOptions& options) {
  const std::size_t count =
      options.max_frames ? std::min(options.max_frames, source.size()) : source.size();
  if (count == 0) throw Error("the input has no scans: " + source.describe());
  const SlamConfig config = configure_for_mode(base_config, options.mode);
  const bool loops = options.mode != SlamMode::kOdometry;
  const bool deterministic = config.pipeline.deterministic || options.deterministic;

  RunResult result;
  result.mode = options.mode;
  Stopwatch wall;
  KeyframeStore store(static_cast<std::size_t>(config.pipeline.resident_keyframes),
                      config.pipeline.spill_dir);
  OdometryStage odometry(config, store, loops);
  DetectionStage detection(config.loop_detection, store);
  LoopClosure closure(config,
                      options.mode == SlamMode::kSimpleSc ? LoopRegistrationMethod::kIcp
                                                          : LoopRegistrationMethod::kFeatures,
                      store);
  closure.set_on_solve([&options](const SolveSample& sample) {
    if (options.live) options.live->solves.fetch_add(1, std::memory_order_relaxed);
    if (options.on_solve) options.on_solve(sample);
  });
  // Deterministic: the loop work below runs on this thread, ICP included.
  std::optional<IcpOnThisThreadRepeatable> repeatable_icp;
  if (loops && deterministic) repeatable_icp.emplace();
  std::optional<LoopThreads> threads;
  if (loops && !deterministic)
    threads.emplace(detection, closure, store, config.pipeline.queue_capacity,
                    config.pipeline.loop_thread_nice,
                    config.pipeline.max_loop_lag_frames, options.live);

  ScanPrefetcher prefetcher(source, count);
  ProgressBar progress(mode_name(options.mode), count, options.progress);
  // Where the odometry thread waits: for the next scan, for the loop stages to catch up, and
  // for room in the loop queue.
  std::vector<double>& wait_input_ms = result.timing_ms["wait_input"];
  std::vector<double>& wait_queue_ms = result.timing_ms["wait_loop_queue"];
  std::vector<double>& wait_lag_ms = result.timing_ms["wait_loop_lag"];
  // A keyframe goes to the loop stages (their threads, or at once when deterministic).
  const auto hand_over = [&](KeyframePtr kf) {
    if (options.live) options.live->keyframes.fetch_add(1, std::memory_order_relaxed);
    if (!loops) return;
    if (threads) {
      Stopwatch queue_watch;
      threads->push(std::move(kf));
      wait_queue_ms.push_back(queue_watch.elapsed_ms());
    } else {
      const LoopQuery query = detection.detect(kf);
      const KeyframeStore::Hold hold(store);
      closure.add(kf, query);
    }
  };
  Stopwatch waiting;
  while (auto item = prefetcher.next()) {
    wait_input_ms.push_back(waiting.elapsed_ms());
    const auto& [index, scan] = *item;
    if (threads) {
      Stopwatch lag_watch;
      threads->wait_for_lag(index);
      wait_lag_ms.push_back(lag_watch.elapsed_ms());
    }
    std::vector<KeyframePtr> made;
    try {
      made = odometry.process(index, scan, result);
    } catch (const Error& e) {
      // Name the input and the scan: the odometry does not know where its scan came from.
      throw Error(source.describe() + ", scan " + std::to_string(index) + ": " + e.what());
    }
    for (KeyframePtr& kf : made) hand_over(std::move(kf));
    const auto& f = result.timing_ms["features"];
    const auto& r = result.timing_ms["registration"];
    if (options.on_frame) options.on_frame(index, f.back(), r.back());
    char note[64];
    std::snprintf(note, sizeof note, "%.1f ms/frame, %zu loops", f.back() + r.back(),
                  closure.accepted_loops());
    progress.update(index + 1, note);
    waiting.restart();
    if (options.stop && options.stop->load() && index + 1 < count) {
      result.interrupted = true;
      break;
    }
  }
  for (KeyframePtr& kf : odometry.flush(result)) hand_over(std::move(kf));
  if (threads) threads->finish();
  if (loops) closure.finish();
  progress.finish();
  if (wait_queue_ms.empty()) result.timing_ms.erase("wait_loop_queue");
  if (wait_lag_ms.empty()) result.timing_ms.erase("wait_loop_lag");

  result.keyframe_poses = store.current_poses();
  result.T_world_lidar = odometry.final_poses(result.keyframe_poses);
  result.keyframe_storage = store.stats();
  if (loops) {
    result.timing_ms["loop_detection"] = detection.ms();
    result.timing_ms["loop_registration"] = closure.registration_ms();
    result.timing_ms["optimization"] = closure.optimization_ms();
    result.timing_ms["heap_trim"] = closure.heap_trim_ms();
    result.loop_solves_skipped = closure.solves_skipped();
    result.loop_solves_deferred = closure.solves_deferred();
    result.window_solves = closure.window_solves();
    result.escalated_solves = closure.escalated_solves();
    result.confirmed_loops = closure.confirmed_loops();
    result.loop_rows = closure.log().rows();
    result.graph = std::make_shared<PoseGraph>(closure.graph());
  }
  result.wall_s = wall.elapsed_ms() / 1000.0;
  return result;
}

}  // namespace scfloam
