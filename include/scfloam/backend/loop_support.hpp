// Which loop edges are confirmed by their neighbours (docs/loop_closure.md, "Session 29:
// loops that confirm each other").
//
// Two loops a_i -> b_i and a_j -> b_j whose ends lie a few keyframes apart on the odometry chain
// close a short cycle: loop i, the odometry from a_i to a_j, loop j back, the odometry from
// b_j to b_i. When both loops are right, that cycle is the identity to within the odometry's
// drift over those few keyframes, whatever the odometry did between the two visits (unless it
// failed inside one of the short spans: then the cycle misses and nothing is confirmed). A loop
// that agrees with enough such neighbours is right even when the long chain between its ends
// cannot be fitted to it under the odometry's sigmas: the graph's chi-square test would blame
// the loop, the cycles blame the chain.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <map>
#include <vector>

#include "scfloam/backend/pose_graph_config.hpp"
#include "scfloam/backend/pose_graph_edge.hpp"

namespace scfloam {

// Per edge, the number of other loop edges (active or not) it closes a consistent short cycle
// with; 0 for odometry edges. Odometry edges are those between consecutive nodes (k -> k + 1,
// not loops); a cycle whose odometry spans lack one is not formed. Loops pair by their `from`
// ends and by their `to` ends (the pipeline adds every loop from the newer keyframe).
//
// Counts depend on the measurements only, never on the estimates, so they are kept up to date
// incrementally as the graph grows (a pose graph solve after every loop must not pay for all
// pairs of thousands of loops); the whole count is redone only when an odometry edge arrives
// behind nodes already counted or the configuration changes.
class LoopSupport {
 public:
  const std::vector<std::size_t>& update(const std::vector<PoseGraphEdge>& edges, std::size_t nodes,
                                         const PoseGraphConfig& config);

 private:
  void reset(const PoseGraphConfig& config);
  bool consistent(const PoseGraphEdge& li, const PoseGraphEdge& lj) const;

  std::size_t seen_edges_ = 0;
  int span_ = 0;
  double max_translation_m_ = 0, max_angle_rad_ = 0;
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::vector<std::size_t> step_;                   // node k's odometry edge from k - 1, or kNone
  std::vector<Eigen::Isometry3d> chain_;            // the odometry's own pose of each node
  std::vector<std::size_t> stretch_;                // which unbroken stretch of the chain
  std::multimap<std::size_t, std::size_t> loops_;   // loop edges counted, by `from`
  std::vector<std::size_t> support_;
};

// The same counts, from scratch.
std::vector<std::size_t> loop_support(const std::vector<PoseGraphEdge>& edges, std::size_t nodes,
                                      const PoseGraphConfig& config);

}  // namespace scfloam
