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

// The query seen from virtual sensors +-lateral_augmentation_m along the lidar's y axis.
template <class... Clouds>
std::vector<ScanContext> shifted_descriptors(const LoopDetectionConfig& config, const Clouds&... clouds) {
  std::vector<ScanContext> variants;
  if (config.lateral_augmentation_m <= 0.0) return variants;
  for (const double offset_m : {config.lateral_augmentation_m, -config.lateral_augmentation_m}) {
    ScanContextBuilder shifted(config.descriptor, static_cast<float>(offset_m));
    (shifted.add(clouds), ...);
    variants.push_back(shifted.finish());
  }
  return variants;
}

}  // namespace

LoopDetector::LoopDetector(const LoopDetectionConfig& config)
    : config_((check_config(config), config)),
      gate_(DistanceGate::from_config(config)),
      index_(config.descriptor.num_rings, config.tree_rebuild_every, config.tree_rebuild_async) {}

template <class... Clouds>
LoopQuery LoopDetector::add_clouds(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                                   const Clouds&... clouds) {
  ScanContextBuilder builder(config_.descriptor);
  (builder.add(clouds), ...);
  return add_keyframe(frame_index, T_world_lidar, builder.finish(), shifted_descriptors(config_, clouds...));
}

LoopQuery LoopDetector::add_keyframe(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                                     const std::vector<Eigen::Vector3f>& points_lidar) {
  return add_clouds(frame_index, T_world_lidar, points_lidar);
}

LoopQuery LoopDetector::add_keyframe(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                                     const std::vector<Eigen::Vector3f>& edges_lidar,
                                     const std::vector<Eigen::Vector3f>& planes_lidar) {
  return add_clouds(frame_index, T_world_lidar, edges_lidar, planes_lidar);
}

LoopQuery LoopDetector::add_keyframe(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                                     const std::vector<LidarPoint>& raw_points_lidar) {
  return add_clouds(frame_index, T_world_lidar, raw_points_lidar);
}

LoopQuery LoopDetector::add_keyframe(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                                     ScanContext descriptor,
                                     const std::vector<ScanContext>& lateral_variants) {
  const auto fits = [&](const ScanContext& d) {
    return d.bins.rows() == config_.descriptor.num_rings && d.bins.cols() == config_.descriptor.num_sectors;
  };
  if (!fits(descriptor) || !std::all_of(lateral_variants.begin(), lateral_variants.end(), fits))
    throw Error("loop detection: descriptor size does not match the configuration");
  const int current_kf = static_cast<int>(size());
  index_.add(descriptor.ring_key);
  descriptors_.push_back(std::move(descriptor));
  T_world_keyframes_.push_back(T_world_lidar);
  frame_indices_.push_back(frame_index);

  LoopQuery query;
  const int eligible = current_kf - config_.exclude_recent_keyframes;
  if (eligible <= 0 || descriptors_.back().empty()) return query;

  // Candidates: the ring-key neighbours of each query variant; each candidate is aligned with
  // the variants that retrieved it, keeping the best.
  std::vector<const ScanContext*> variants{&descriptors_.back()};
  for (const ScanContext& v : lateral_variants)
    if (!v.empty()) variants.push_back(&v);
  struct Retrieved {
    int loop_kf;
    float ring_key_distance;
    std::vector<const ScanContext*> by;
  };
  std::vector<Retrieved> retrieved;
  for (const ScanContext* v : variants)
    for (const RingKeyNeighbour& n :
         index_.nearest(v->ring_key, config_.num_candidates, static_cast<std::size_t>(eligible))) {
      auto it = std::find_if(retrieved.begin(), retrieved.end(),
                             [&](const Retrieved& r) { return r.loop_kf == n.keyframe; });
      if (it == retrieved.end()) {
        retrieved.push_back({n.keyframe, n.distance, {v}});
      } else {
        it->ring_key_distance = std::min(it->ring_key_distance, n.distance);
        it->by.push_back(v);
      }
    }
  std::sort(retrieved.begin(), retrieved.end(), [](const Retrieved& a, const Retrieved& b) {
    return a.ring_key_distance != b.ring_key_distance ? a.ring_key_distance < b.ring_key_distance
                                                      : a.loop_kf < b.loop_kf;
  });

  const double gate_m = gate_.threshold_m(size());
  for (const Retrieved& r : retrieved)
    query.evaluated.push_back(evaluate(r.by, current_kf, r.loop_kf, r.ring_key_distance, gate_m));

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

LoopCandidate LoopDetector::evaluate(const std::vector<const ScanContext*>& variants, int current_kf,
                                     int loop_kf, float ring_key_distance, double gate_m) const {
  ColumnAlignment alignment;
  for (const ScanContext* v : variants) {
    const ColumnAlignment a = align_scan_contexts(*v, descriptors_[loop_kf], config_.fine_search_ratio);
    if (v == variants.front() || a.distance < alignment.distance) alignment = a;
  }
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

std::vector<ScanContext> lateral_descriptors(const std::vector<Eigen::Vector3f>& points_lidar,
                                             const LoopDetectionConfig& config) {
  return shifted_descriptors(config, points_lidar);
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
