// Long run (issue 8): replays one simulated patrol lap (scfloam simulate --scenario patrol)
// lap after lap with continuing stamps, through the whole pipeline, for N frames: a robot
// patrolling for an hour. Samples the resident memory while it runs and writes
//   OUT/memory.csv   elapsed_s, frames_read, rss_mb, heap_in_use_mb, heap_free_mb, keyframes,
//                    detection_queue, closure_queue, solves    (every --sample-s seconds)
//   OUT/frames.csv   frame, features_ms, registration_ms       (every frame)
//   OUT/solves.csv   elapsed_s, frames_read, nodes, free_nodes, ms  (every pose-graph solve)
//   OUT/summary.json the run's summary.json plus what is stored per keyframe
//   OUT/loops.csv    current_frame, loop_frame, verdict        (registered loop candidates)
// heap_in_use_mb is what malloc has handed out and not got back (mallinfo2 uordblks + hblkhd),
// heap_free_mb what it got back but keeps (fordblks): RSS growing with the first is live data,
// with the second allocator retention. The CSVs are rewritten every 60 s while the run goes
// on, so a stopped run leaves its data.
// Usage: long_run LAP_DIR OUT_DIR [--frames 20000] [--mode optimized] [--sample-s 2]
//                 [--resident-keyframes N] [--rebuild-cell-m M]  (pipeline.* keys)
#include <malloc.h>

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>

#include "scfloam/atomic_file.hpp"
#include "scfloam/backend/pose_graph.hpp"
#include "scfloam/error.hpp"
#include "scfloam/io/scan_source.hpp"
#include "scfloam/pipeline/outputs.hpp"
#include "scfloam/pipeline/pipeline.hpp"
#include "scfloam/stats.hpp"

using namespace scfloam;
namespace fs = std::filesystem;

namespace {

// Frame i is lap frame i mod N, stamped as if the laps followed each other; the lap's poses
// are periodic (frame N has frame 0's pose), so the ground truth repeats too.
class RepeatingSource : public ScanSource {
 public:
  RepeatingSource(std::unique_ptr<ScanSource> lap, std::size_t frames)
      : lap_(std::move(lap)), frames_(frames), lap_gt_(lap_->ground_truth_lidar()) {}
  std::size_t size() const override { return frames_; }
  Scan load(std::size_t index) const override {
    Scan scan = lap_->load(index % lap_->size());
    scan.timestamp_s = 0.1 * static_cast<double>(index);
    std::size_t seen = read_.load();
    while (index + 1 > seen && !read_.compare_exchange_weak(seen, index + 1)) {
    }
    return scan;
  }
  std::string describe() const override {
    return lap_->describe() + " repeated to " + std::to_string(frames_) + " frames";
  }
  std::optional<Eigen::Isometry3d> T_cam0_lidar() const override { return lap_->T_cam0_lidar(); }
  PoseList ground_truth_lidar() const override {
    if (lap_gt_.size() != lap_->size()) return {};
    PoseList gt(frames_);
    for (std::size_t i = 0; i < frames_; ++i) gt[i] = lap_gt_[i % lap_gt_.size()];
    return gt;
  }
  std::size_t frames_read() const { return read_.load(); }

 private:
  std::unique_ptr<ScanSource> lap_;
  std::size_t frames_;
  PoseList lap_gt_;
  mutable std::atomic<std::size_t> read_{0};
};

double current_rss_mb() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0;
}

// Bytes malloc has handed out (arenas and mmapped chunks) and bytes it holds free, all
// arenas together (glibc >= 2.33).
struct HeapUse {
  double in_use_mb = 0, free_mb = 0;
};
HeapUse current_heap() {
  const struct mallinfo2 mi = mallinfo2();
  return {static_cast<double>(mi.uordblks + mi.hblkhd) / (1024.0 * 1024.0),
          static_cast<double>(mi.fordblks) / (1024.0 * 1024.0)};
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: long_run LAP_DIR OUT_DIR [--frames 20000] [--mode optimized] [--sample-s 2]"
                 " [--resident-keyframes N] [--rebuild-cell-m M]\n");
    return 2;
  }
  const fs::path lap_dir = argv[1], out_dir = argv[2];
  std::size_t frames = 20000;
  std::string mode_text = "optimized";
  double sample_s = 2;
  SlamConfig config;
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--frames") frames = std::stoul(value);
    else if (key == "--mode") mode_text = value;
    else if (key == "--sample-s") sample_s = std::stod(value);
    else if (key == "--resident-keyframes") config.pipeline.resident_keyframes = std::stoi(value);
    else if (key == "--rebuild-cell-m") config.pipeline.map_rebuild_cell_m = std::stod(value);
    else throw Error("unknown option " + key);
  }
  const auto mode = parse_mode(mode_text);
  if (!mode) throw Error("unknown mode " + mode_text);
  fs::create_directories(out_dir);
  RepeatingSource source(open_scan_source(lap_dir), frames);

  // Memory sampler: resident set size against frames read, while the pipeline runs; the
  // odometry's per-frame times arrive through on_frame.
  std::ostringstream memory_csv;
  memory_csv << "elapsed_s,frames_read,rss_mb,heap_in_use_mb,heap_free_mb,keyframes,"
                "detection_queue,closure_queue,solves\n";
  std::ostringstream solves_csv;
  solves_csv << "elapsed_s,frames_read,nodes,free_nodes,ms\n";
  LiveCounters live;
  std::vector<std::array<double, 2>> frame_ms;
  frame_ms.reserve(frames);
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  const auto write_csvs = [&] {  // m held
    write_file_atomic(out_dir / "memory.csv", memory_csv.str());
    write_file_atomic(out_dir / "solves.csv", solves_csv.str());
    write_file_atomic(out_dir / "frames.csv", [&](std::ostream& out) {
      out << "frame,features_ms,registration_ms\n";
      char row[64];
      for (std::size_t i = 0; i < frame_ms.size(); ++i) {
        std::snprintf(row, sizeof row, "%zu,%.3f,%.3f\n", i, frame_ms[i][0], frame_ms[i][1]);
        out << row;
      }
    });
  };
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed_s = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  std::thread sampler([&] {
    std::unique_lock<std::mutex> lock(m);
    double last_write_s = 0;
    do {
      const double t = elapsed_s();
      const HeapUse heap = current_heap();
      char row[160];
      std::snprintf(row, sizeof row, "%.1f,%zu,%.1f,%.1f,%.1f,%zu,%zu,%zu,%zu\n", t,
                    source.frames_read(), current_rss_mb(), heap.in_use_mb, heap.free_mb,
                    live.keyframes.load(), live.detection_queue.load(), live.closure_queue.load(),
                    live.solves.load());
      memory_csv << row;
      if (t - last_write_s > 60) {
        write_csvs();
        last_write_s = t;
      }
    } while (!cv.wait_for(lock, std::chrono::duration<double>(sample_s), [&] { return done; }));
  });

  RunOptions options;
  options.mode = *mode;
  options.progress = true;
  options.live = &live;
  options.on_solve = [&](const SolveSample& solve) {
    char row[96];
    std::snprintf(row, sizeof row, "%.1f,%zu,%zu,%zu,%.1f\n", elapsed_s(), source.frames_read(),
                  solve.nodes, solve.free_nodes, solve.ms);
    std::lock_guard<std::mutex> lock(m);
    solves_csv << row;
  };
  options.on_frame = [&](std::size_t, double features_ms, double registration_ms) {
    std::lock_guard<std::mutex> lock(m);
    frame_ms.push_back({features_ms, registration_ms});
  };
  const auto stop_sampler = [&] {
    {
      std::lock_guard<std::mutex> lock(m);
      done = true;
      write_csvs();
    }
    cv.notify_one();
    sampler.join();
  };
  RunResult result;
  try {
    result = run_slam(source, config, options);
  } catch (...) {
    stop_sampler();  // what was measured so far stays on disk
    throw;
  }
  stop_sampler();

  // Loops over time: every candidate that passed score and gate, with its final verdict.
  write_file_atomic(out_dir / "loops.csv", [&](std::ostream& out) {
    out << "current_frame,loop_frame,verdict\n";
    for (const auto& row : result.loop_rows)
      if (row.verdict == LoopVerdict::kAccepted || row.verdict == LoopVerdict::kRejectedMatch)
        out << row.current_frame << ',' << row.loop_frame << ',' << to_string(row.verdict) << '\n';
  });
  // What every keyframe keeps for the rest of the run, and where.
  const KeyframeStorageStats& s = result.keyframe_storage;
  const double kfs = std::max<std::size_t>(1, s.keyframes);
  nlohmann::json summary = make_summary(source, result);
  summary["keyframe_storage"] = {
      {"keyframes", s.keyframes},
      {"resident", s.resident},
      {"resident_limit", s.resident_limit},
      {"spilled", s.spilled},
      {"spill_mb", s.spill_bytes / 1e6},
      {"reloads", s.reloads},
      {"edge_points_per_keyframe", s.edge_points / kfs},
      {"plane_points_per_keyframe", s.plane_points / kfs},
      {"raw_points_per_keyframe", s.raw_points / kfs},
      {"feature_bytes_per_keyframe",
       (s.edge_points + s.plane_points + s.raw_points) * sizeof(Eigen::Vector3f) / kfs},
      {"graph_nodes", result.graph ? result.graph->size() : 0}};
  write_file_atomic(out_dir / "summary.json", summary.dump(2) + "\n");
  std::printf("%zu frames, %zu keyframes (%zu resident), peak RSS %.0f MB, %.1f s\n",
              result.T_world_lidar.size(), s.keyframes, s.resident, peak_rss_mb(), result.wall_s);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "error: %s\n", e.what());
  return 1;
}
