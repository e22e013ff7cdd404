// Keyframes shared by the three stages. Clouds are immutable once made; poses change when the
// pose graph is optimized. A keyframe newer than the last optimization is placed by chaining
// the odometry's motion onto its optimized predecessor, so every stage can ask for the best
// current pose of every keyframe, whatever frame the odometry was in when it made it.
//
// Memory bound (docs/robustness-long-run.md): at most `resident_limit` keyframes keep their
// clouds in memory, the least recently used beyond that are written once to a spill file and
// read back on demand (bit-exact). The newest keyframes and those used for the odometry's map
// and loop submaps (the area around the robot) are the recently used ones.
#pragma once

#include <Eigen/Geometry>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <list>
#include <memory>
#include <mutex>
#include <vector>

#include "scfloam/pipeline/keyframe.hpp"
#include "scfloam/pipeline/pipeline.hpp"

namespace scfloam {

class KeyframeStore {
 public:
  // resident_limit 0: every keyframe stays in memory. spill_dir empty: the system's temp folder.
  explicit KeyframeStore(std::size_t resident_limit = 0, std::filesystem::path spill_dir = {});
  ~KeyframeStore();  // removes the spill file
  KeyframeStore(const KeyframeStore&) = delete;
  KeyframeStore& operator=(const KeyframeStore&) = delete;

  // Keyframes arrive in index order; the first one defines the map frame (identity).
  void add(KeyframePtr keyframe);
  // Poses of keyframes 0 .. poses.size()-1 after an optimization.
  void set_optimized(const PoseList& poses);

  std::size_t size() const;
  // The keyframe with its clouds (read back from the spill file if it was spilled).
  KeyframePtr get(std::size_t index) const;
  // Best current pose of every keyframe (optimized, or chained from the last optimized one).
  PoseList current_poses() const;
  Eigen::Isometry3d current_pose(std::size_t index) const;
  // Increases with every set_optimized(): stages compare it to see whether poses changed.
  std::uint64_t version() const { return version_.load(); }

  // While a Hold exists nothing is spilled: a stage may keep raw pointers into clouds it got
  // from get() (loop submap views) for as long as it holds one.
  class Hold {
   public:
    explicit Hold(const KeyframeStore& store);
    ~Hold();
    Hold(const Hold&) = delete;
    Hold& operator=(const Hold&) = delete;

   private:
    const KeyframeStore& store_;
  };

  KeyframeStorageStats stats() const;

 private:
  struct Entry {
    std::size_t frame = 0;
    Eigen::Isometry3d T_prev_current;
    KeyframePtr resident;                 // null while spilled
    std::int64_t file_offset = -1;        // where its clouds are in the spill file, -1: never spilled
    std::list<std::size_t>::iterator lru;  // valid while resident
    std::size_t edges = 0, planes = 0, raw = 0;
  };
  void touch(Entry& entry, std::size_t index) const;  // most recently used
  void spill_excess() const;                           // mutex held
  void write_clouds(Entry& entry) const;               // mutex held
  KeyframePtr read_clouds(std::size_t index, const Entry& entry) const;

  const std::size_t resident_limit_;
  const std::filesystem::path spill_path_;
  mutable std::mutex mutex_;
  mutable std::vector<Entry> entries_;
  mutable std::list<std::size_t> lru_;  // resident keyframes, least recently used first
  mutable std::fstream spill_;
  mutable std::int64_t spill_end_ = 0;
  mutable int holds_ = 0;
  mutable std::size_t reloads_ = 0;
  PoseList poses_;  // best current pose per keyframe
  std::atomic<std::uint64_t> version_{0};
};

}  // namespace scfloam
