#include "scfloam/pipeline/pipeline.hpp"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <thread>

#include "scfloam/bounded_queue.hpp"
#include "scfloam/error.hpp"
#include "scfloam/odometry/odometry.hpp"
#include "scfloam/progress.hpp"
#include "scfloam/stats.hpp"

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

}  // namespace

RunResult run_slam(const ScanSource& source, const SlamConfig& config, const RunOptions& options) {
  if (options.mode != SlamMode::kOdometry)
    throw Error("mode '" + mode_name(options.mode) +
                "' is not available yet: loop closure lands with the loop issues; use --mode odometry");
  const std::size_t count =
      options.max_frames ? std::min(options.max_frames, source.size()) : source.size();
  if (count == 0) throw Error("the input has no scans: " + source.describe());

  RunResult result;
  result.mode = options.mode;
  Stopwatch wall;
  Odometry odometry(config.odometry);
  ScanPrefetcher prefetcher(source, count);
  ProgressBar progress("odometry", count, options.progress);
  auto& features_ms = result.timing_ms["features"];
  auto& registration_ms = result.timing_ms["registration"];
  while (auto item = prefetcher.next()) {
    const auto& [index, scan] = *item;
    const OdometryResult odom = odometry.process(scan);
    result.stamps_s.push_back(scan.timestamp_s);
    result.odometry_T_world_lidar.push_back(odom.T_world_lidar);
    features_ms.push_back(odom.features_ms);
    registration_ms.push_back(odom.registration_ms);
    if (odom.degenerate) ++result.degenerate_frames;
    progress.update(index + 1, std::to_string(static_cast<int>(odom.features_ms +
                                                               odom.registration_ms + 0.5)) +
                                   " ms/frame");
  }
  progress.finish();
  result.T_world_lidar = result.odometry_T_world_lidar;
  result.wall_s = wall.elapsed_ms() / 1000.0;
  return result;
}

}  // namespace scfloam
