// Keyframes shared by the three stages. Clouds are immutable once made; poses change when the
// pose graph is optimized. A keyframe newer than the last optimization is placed by chaining
// the odometry's motion onto its optimized predecessor, so every stage can ask for the best
// current pose of every keyframe, whatever frame the odometry was in when it made it.
#pragma once

#include <Eigen/Geometry>
#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

#include "scfloam/pipeline/keyframe.hpp"

namespace scfloam {


class KeyframeStore {
 public:
  // Keyframes arrive in index order; the first one defines the map frame (identity).
  void add(KeyframePtr keyframe);
  // Poses of keyframes 0 .. poses.size()-1 after an optimization.
  void set_optimized(const PoseList& poses);

  std::size_t size() const;
  KeyframePtr get(std::size_t index) const;
  // Best current pose of every keyframe (optimized, or chained from the last optimized one).
  PoseList current_poses() const;
  Eigen::Isometry3d current_pose(std::size_t index) const;
  // Increases with every set_optimized(): stages compare it to see whether poses changed.
  std::uint64_t version() const { return version_.load(); }

 private:
  mutable std::mutex mutex_;
  std::vector<KeyframePtr> keyframes_;
  PoseList poses_;  // best current pose per keyframe
  std::atomic<std::uint64_t> version_{0};
};

}  // namespace scfloam
