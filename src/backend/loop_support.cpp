#include "scfloam/backend/loop_support.hpp"

#include <cmath>

namespace scfloam {

void LoopSupport::reset(const PoseGraphConfig& config) {
  *this = LoopSupport();
  span_ = config.loop_support_span_keyframes;
  max_translation_m_ = config.loop_support_translation_m;
  max_angle_rad_ = config.loop_support_rotation_deg * M_PI / 180.0;
}

bool LoopSupport::consistent(const PoseGraphEdge& li, const PoseGraphEdge& lj) const {
  // Two measurements from one keyframe are not independent evidence.
  if (li.from == lj.from) return false;
  const auto apart = [](std::size_t x, std::size_t y) { return x > y ? x - y : y - x; };
  const auto span = static_cast<std::size_t>(span_);
  if (apart(li.from, lj.from) > span || apart(li.to, lj.to) > span) return false;
  if (stretch_[li.from] != stretch_[lj.from] || stretch_[li.to] != stretch_[lj.to]) return false;
  const auto odometry = [&](std::size_t from, std::size_t to) {
    return chain_[from].inverse() * chain_[to];
  };
  // T_ai_bi = odometry(a_i, a_j) * T_aj_bj * odometry(b_j, b_i) when both loops are right.
  const Eigen::Isometry3d cycle =
      li.T_from_to.inverse() * odometry(li.from, lj.from) * lj.T_from_to * odometry(lj.to, li.to);
  return cycle.translation().norm() <= max_translation_m_ &&
         Eigen::AngleAxisd(cycle.linear()).angle() <= max_angle_rad_;
}

const std::vector<std::size_t>& LoopSupport::update(const std::vector<PoseGraphEdge>& edges,
                                                    std::size_t nodes,
                                                    const PoseGraphConfig& config) {
  const bool same_config = span_ == config.loop_support_span_keyframes &&
                           max_translation_m_ == config.loop_support_translation_m &&
                           max_angle_rad_ == config.loop_support_rotation_deg * M_PI / 180.0;
  bool redo = !same_config || edges.size() < seen_edges_ || nodes < chain_.size();
  // Edges are only appended; an odometry edge into a node whose chain pose is already built
  // changes poses (or stretches) that earlier counts used.
  for (std::size_t i = seen_edges_; i < edges.size() && !redo; ++i)
    redo = !edges[i].is_loop && edges[i].to == edges[i].from + 1 && edges[i].to < chain_.size();
  if (redo) reset(config);
  support_.resize(edges.size(), 0);
  if (span_ <= 0) {
    seen_edges_ = edges.size();
    return support_;
  }
  // Odometry steps of the new edges, then the chain out to every node.
  step_.resize(nodes, kNone);
  for (std::size_t i = seen_edges_; i < edges.size(); ++i)
    if (!edges[i].is_loop && edges[i].to == edges[i].from + 1 && step_[edges[i].to] == kNone)
      step_[edges[i].to] = i;
  for (std::size_t k = chain_.size(); k < nodes; ++k) {
    if (k == 0) {
      chain_.push_back(Eigen::Isometry3d::Identity());
      stretch_.push_back(0);
      continue;
    }
    const bool linked = step_[k] != kNone;
    chain_.push_back(linked ? chain_[k - 1] * edges[step_[k]].T_from_to : Eigen::Isometry3d::Identity());
    stretch_.push_back(stretch_[k - 1] + (linked ? 0 : 1));
  }
  // Each new loop against the loops counted so far whose `from` is within the span.
  const auto span = static_cast<std::size_t>(span_);
  for (std::size_t i = seen_edges_; i < edges.size(); ++i) {
    if (!edges[i].is_loop) continue;
    const PoseGraphEdge& li = edges[i];
    const std::size_t low = li.from > span ? li.from - span : 0;
    for (auto it = loops_.lower_bound(low); it != loops_.end() && it->first <= li.from + span; ++it)
      if (consistent(li, edges[it->second])) {
        ++support_[i];
        ++support_[it->second];
      }
    loops_.emplace(li.from, i);
  }
  seen_edges_ = edges.size();
  return support_;
}

std::vector<std::size_t> loop_support(const std::vector<PoseGraphEdge>& edges, std::size_t nodes,
                                      const PoseGraphConfig& config) {
  LoopSupport support;
  return support.update(edges, nodes, config);
}

}  // namespace scfloam
