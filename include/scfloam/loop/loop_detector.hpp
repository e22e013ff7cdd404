// Loop detection stage: one call per keyframe stores its Scan Context and pose, searches the
// older keyframes by ring key, aligns each candidate by column shift, and applies the score
// threshold and the distance gate. Not thread-safe: one stage owns it.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <vector>

#include "scfloam/loop/config.hpp"
#include "scfloam/loop/distance_gate.hpp"
#include "scfloam/loop/loop_candidate.hpp"
#include "scfloam/loop/ring_key_index.hpp"
#include "scfloam/loop/scan_context.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

struct LoopQuery {
  std::vector<LoopCandidate> evaluated;  // every aligned candidate, closest ring key first
  std::optional<LoopCandidate> best;     // the accepted one (lowest score among passed), if any
};

class LoopDetector {
 public:
  explicit LoopDetector(const LoopDetectionConfig& config);

  // Adds keyframe size() (frame `frame_index`, pose T_world_lidar) and queries the database.
  // `points_lidar`: edges + planes (the paper) or the raw scan (baseline), see
  // LoopDetectionConfig::descriptor_from_features.
  LoopQuery add_keyframe(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                         const std::vector<Eigen::Vector3f>& points_lidar);
  LoopQuery add_keyframe(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                         const std::vector<Eigen::Vector3f>& edges_lidar,
                         const std::vector<Eigen::Vector3f>& planes_lidar);
  LoopQuery add_keyframe(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                         const std::vector<LidarPoint>& raw_points_lidar);
  // With a precomputed descriptor; `lateral_variants` are the query's laterally shifted
  // descriptors (lateral_descriptors()), empty = no augmentation.
  LoopQuery add_keyframe(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                         ScanContext descriptor, const std::vector<ScanContext>& lateral_variants = {});

  // After pose-graph optimization: new poses of keyframes 0 .. poses.size()-1 (the gate uses them).
  void update_poses(const PoseList& T_world_keyframes);

  std::size_t size() const { return descriptors_.size(); }
  const ScanContext& descriptor(std::size_t keyframe) const { return descriptors_.at(keyframe); }
  const Eigen::Isometry3d& pose(std::size_t keyframe) const { return T_world_keyframes_.at(keyframe); }
  std::int64_t frame_index(std::size_t keyframe) const { return frame_indices_.at(keyframe); }
  const LoopDetectionConfig& config() const { return config_; }

 private:
  template <class... Clouds>
  LoopQuery add_clouds(std::int64_t frame_index, const Eigen::Isometry3d& T_world_lidar,
                       const Clouds&... clouds);
  LoopCandidate evaluate(const std::vector<const ScanContext*>& variants, int current_kf, int loop_kf,
                         float ring_key_distance, double gate_m) const;

  LoopDetectionConfig config_;
  DistanceGate gate_;
  RingKeyIndex index_;
  std::vector<ScanContext> descriptors_;
  PoseList T_world_keyframes_;
  std::vector<std::int64_t> frame_indices_;
};

// Descriptors of the points from virtual sensors at +-config.lateral_augmentation_m along the
// lidar's y axis (none when it is 0).
std::vector<ScanContext> lateral_descriptors(const std::vector<Eigen::Vector3f>& points_lidar,
                                             const LoopDetectionConfig& config);

// Rows worth a line in loops.csv for one query: every candidate that passed the score
// threshold, or else the single best-scoring one (so each keyframe with candidates leaves a
// trace of why nothing was accepted).
std::vector<LoopCandidate> rows_to_log(const LoopQuery& query);

}  // namespace scfloam
