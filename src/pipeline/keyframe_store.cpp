#include "pipeline/keyframe_store.hpp"

#include "scfloam/error.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {

void KeyframeStore::add(KeyframePtr keyframe) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (keyframe->index != keyframes_.size())
    throw Error("internal: keyframe " + std::to_string(keyframe->index) + " out of order");
  poses_.push_back(poses_.empty() ? Eigen::Isometry3d::Identity()
                                  : orthonormalized(poses_.back() * keyframe->T_prev_current));
  keyframes_.push_back(std::move(keyframe));
}

void KeyframeStore::set_optimized(const PoseList& poses) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::size_t m = std::min(poses.size(), poses_.size());
    for (std::size_t i = 0; i < m; ++i) poses_[i] = poses[i];
    for (std::size_t i = std::max<std::size_t>(m, 1); i < poses_.size(); ++i)
      poses_[i] = orthonormalized(poses_[i - 1] * keyframes_[i]->T_prev_current);
  }
  ++version_;
}

std::size_t KeyframeStore::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return keyframes_.size();
}

KeyframePtr KeyframeStore::get(std::size_t index) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return keyframes_.at(index);
}

PoseList KeyframeStore::current_poses() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return poses_;
}

Eigen::Isometry3d KeyframeStore::current_pose(std::size_t index) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return poses_.at(index);
}

}  // namespace scfloam
