#include "scfloam/loop/loop_detector.hpp"

#include <algorithm>
#include <string>
#include <utility>

#include "scfloam/error.hpp"

namespace scfloam {
namespace {

void check_config(const LoopDetectionConfig& c) {
  if (c.exclude_recent_keyframes < 0 || c.num_candidates < 1 || !(c.fine_search_ratio >= 0.0) ||
      !(c.score_threshold >= 0.0))
    throw Error("loop detection: need exclude_recent_keyframes >= 0, num_candidates >= 1, "
                "fine_search_ratio >= 0 and score_threshold >= 0");
}

}  // namespace

LoopDetector::LoopDetector(const LoopDetectionConfig& config)
    : config_((check_config(config), config)),
      gate_(DistanceGate::from_config(config)),
      index_(config.descriptor.num_rings, config.tree_rebuild_every, config.tree_rebuild_async) {}

LoopQuery LoopDetector::add_keyframe(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                                     const std::vector<Eigen::Vector3f>& points_lidar) {
  return add_keyframe(frame_index, T_world_lidar, make_scan_context(points_lidar, config_.descriptor));
}

LoopQuery LoopDetector::add_keyframe(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                                     const std::vector<Eigen::Vector3f>& edges_lidar,
                                     const std::vector<Eigen::Vector3f>& planes_lidar) {
  return add_keyframe(frame_index, T_world_lidar,
                      make_scan_context(edges_lidar, planes_lidar, config_.descriptor));
}

LoopQuery LoopDetector::add_keyframe(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                                     const std::vector<LidarPoint>& raw_points_lidar) {
  return add_keyframe(frame_index, T_world_lidar,
                      make_scan_context(raw_points_lidar, config_.descriptor));
}

LoopQuery LoopDetector::add_keyframe(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                                     ScanContext descriptor) {
  if (descriptor.bins.rows() != config_.descriptor.num_rings ||
      descriptor.bins.cols() != config_.descriptor.num_sectors)
    throw Error("loop detection: descriptor size does not match the configuration");
  const int current_kf = static_cast<int>(size());
  index_.add(descriptor.ring_key);
  descriptors_.push_back(std::move(descriptor));
  T_world_keyframes_.push_back(T_world_lidar);
  frame_indices_.push_back(frame_index);

  LoopQuery query;
  const ScanContext& current = descriptors_.back();
  const int eligible = current_kf - config_.exclude_recent_keyframes;
  if (eligible <= 0 || current.empty()) return query;

  const double gate_m = gate_.threshold_m(size());
  for (const RingKeyNeighbour& n :
       index_.nearest(current.ring_key, config_.num_candidates, static_cast<std::size_t>(eligible)))
    query.evaluated.push_back(evaluate(current, current_kf, n.keyframe, n.distance, gate_m));

  // The accepted candidate is the best score among those that passed both checks.
  LoopCandidate* best = nullptr;
  for (LoopCandidate& c : query.evaluated) {
    if (c.verdict != LoopVerdict::kAccepted) continue;
    if (best == nullptr || c.sc_score < best->sc_score) best = &c;
  }
  for (LoopCandidate& c : query.evaluated)
    if (c.verdict == LoopVerdict::kAccepted && &c != best) c.verdict = LoopVerdict::kRejectedRank;
  if (best != nullptr) query.best = *best;
  return query;
}

LoopCandidate LoopDetector::evaluate(const ScanContext& current, int current_kf, int loop_kf,
                                     float ring_key_distance, double gate_m) const {
  const ColumnAlignment alignment =
      align_scan_contexts(current, descriptors_[loop_kf], config_.fine_search_ratio);
  LoopCandidate c;
  c.current_kf = current_kf;
  c.loop_kf = loop_kf;
  c.current_frame = frame_indices_[current_kf];
  c.loop_frame = frame_indices_[loop_kf];
  c.sc_score = alignment.distance;
  c.yaw_rad = alignment.yaw_loop_current_rad;
  c.ring_key_distance = ring_key_distance;
  c.distance_m = DistanceGate::distance_m(T_world_keyframes_[loop_kf], T_world_keyframes_[current_kf]);
  c.gate_m = gate_m;
  if (c.sc_score > config_.score_threshold)
    c.verdict = LoopVerdict::kRejectedScore;
  else if (c.distance_m > gate_m)
    c.verdict = LoopVerdict::kRejectedGate;
  else
    c.verdict = LoopVerdict::kAccepted;
  return c;
}

void LoopDetector::update_poses(const PoseList& T_world_keyframes) {
  if (T_world_keyframes.size() > size())
    throw Error("loop detection: " + std::to_string(T_world_keyframes.size()) +
                " poses for " + std::to_string(size()) + " keyframes");
  std::copy(T_world_keyframes.begin(), T_world_keyframes.end(), T_world_keyframes_.begin());
}

std::vector<LoopCandidate> rows_to_log(const LoopQuery& query) {
  std::vector<LoopCandidate> rows;
  for (const LoopCandidate& c : query.evaluated)
    if (c.verdict != LoopVerdict::kRejectedScore) rows.push_back(c);
  if (rows.empty() && !query.evaluated.empty())
    rows.push_back(*std::min_element(
        query.evaluated.begin(), query.evaluated.end(),
        [](const LoopCandidate& a, const LoopCandidate& b) { return a.sc_score < b.sc_score; }));
  return rows;
}

}  // namespace scfloam
