// The single entry point that knows the whole order of the stages: scans in, trajectory out.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scfloam/config.hpp"
#include "scfloam/features/feature_extractor.hpp"
#include "scfloam/features/sweep_times.hpp"
#include "scfloam/io/scan_source.hpp"
#include "scfloam/loop/loop_candidate.hpp"
#include "scfloam/odometry/odometry.hpp"
#include "scfloam/pipeline/keyframe.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

// The paper's methods as modes of one program (its Table I).
enum class SlamMode {
  kOdometry,   // F-LOAM: odometry only
  kSimpleSc,   // Simple-SC-F-LOAM: raw-scan Scan Context, fixed gate, ICP loop registration
  kOptimized,  // Optimized-SC-F-LOAM: feature Scan Context, adaptive gate, feature registration
};
std::optional<SlamMode> parse_mode(const std::string& name);
std::string mode_name(SlamMode mode);

// Counters the stages update while a run goes on, for a monitor on another thread (a long
// run's memory sampler): which queue holds how many keyframes when memory grows.
struct LiveCounters {
  std::atomic<std::size_t> keyframes{0};        // made by the odometry so far
  std::atomic<std::size_t> detection_queue{0};  // keyframes waiting for loop detection
  std::atomic<std::size_t> closure_queue{0};    // keyframes waiting for loop closure
  std::atomic<std::size_t> solves{0};           // pose-graph solves so far
};

// One pose-graph solve during the run: how many nodes it freed, of how many, and its time.
struct SolveSample {
  std::size_t free_nodes = 0, nodes = 0;
  double ms = 0;
  bool escalated = false;  // a window solve that freed the whole graph to judge a misfit loop
};

struct RunOptions {
  SlamMode mode = SlamMode::kOdometry;
  std::size_t max_frames = 0;  // 0: every scan of the source
  bool progress = true;        // progress bar on stderr
  bool deterministic = false;  // loop work in frame order on one thread (also a config key)
  // Set from elsewhere (a signal handler) to stop early: checked between frames; the loop work
  // already queued is finished, so the result is a complete run over the frames processed.
  const std::atomic<bool>* stop = nullptr;
  // Called on the odometry's thread after every frame (frame, features_ms, registration_ms):
  // lets a long run record its timings while it goes on.
  std::function<void(std::size_t, double, double)> on_frame;
  // Updated by the stages as they go (may be null); must outlive run_slam.
  LiveCounters* live = nullptr;
  // Called after every pose-graph solve, on the thread that solves (the loop-closure thread;
  // run_slam's own for the run's final solve and in deterministic mode).
  std::function<void(const SolveSample&)> on_solve;
};

// Where the keyframes' clouds are at the end of a run (pipeline.resident_keyframes).
struct KeyframeStorageStats {
  std::size_t keyframes = 0;
  std::size_t resident = 0;        // clouds in memory
  std::size_t resident_limit = 0;  // 0: no limit
  std::size_t spilled = 0;         // clouds written to the spill file
  std::size_t spill_bytes = 0;
  std::size_t reloads = 0;         // clouds read back from it
  std::size_t edge_points = 0, plane_points = 0, raw_points = 0;  // over all keyframes
};

class PoseGraph;

struct RunResult {
  SlamMode mode = SlamMode::kOdometry;
  std::vector<double> stamps_s;
  PoseList T_world_lidar;            // every frame; optimized where the mode optimizes
  PoseList odometry_T_world_lidar;   // every frame, as the odometry estimated it
  std::vector<std::size_t> keyframe_frames;
  std::size_t degenerate_frames = 0;
  // The elevation correction the odometry applied, at the first and the last frame (they
  // differ only when the config estimates it online).
  double elevation_correction_first_deg = 0, elevation_correction_last_deg = 0;
  RingLayoutInfo ring_layout;  // where the rings came from (the last change of source)
  SettingCheck deskew_check;    // whether the scans proved motion-distorted (at the last frame)
  // The odometry deskewed scans that carry point times (at the last frame): the map and the
  // saved keyframe clouds deskew their raw scans too.
  bool deskewed_scans = false;
  // Scans without point times that the odometry deskewed got them from the azimuth: the last
  // such scan's sweep as its order showed it and the times given (the map does the same).
  std::optional<SweepLayout> azimuth_times;
  std::size_t redeskewed_frames = 0;  // frames deskewed again at their own velocity
  SettingCheck elevation_check;  // whether the scans proved to need the elevation correction
  // How many frames ran each number of correspondence rounds (index = rounds).
  std::vector<std::size_t> registration_rounds;
  // Per-stage samples in milliseconds ("features", "registration", ...).
  std::map<std::string, std::vector<double>> timing_ms;
  double wall_s = 0;
  bool interrupted = false;  // RunOptions::stop ended the run before the last scan
  // Loop modes only: every loop candidate with its verdict, the final graph.
  std::vector<LoopCandidate> loop_rows;
  std::size_t loop_solves_skipped = 0;  // accepted loops the graph already agreed with
  std::size_t loop_solves_deferred = 0;  // accepted loops solved later, with a backlog's others
  std::size_t window_solves = 0;     // graph solves that freed only a window of recent nodes
  std::size_t escalated_solves = 0;  // window solves escalated to the whole graph by a misfit loop
  std::size_t confirmed_loops = 0;   // loops confirmed by their neighbours at the last solve
  std::shared_ptr<const PoseGraph> graph;
  PoseList keyframe_poses;  // final pose of every keyframe
  KeyframeStorageStats keyframe_storage;
};

RunResult run_slam(const ScanSource& source, const SlamConfig& config, const RunOptions& options);

}  // namespace scfloam
