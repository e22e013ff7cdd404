#include "pipeline/loop_closure.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cstdlib>
#include <limits>

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "scfloam/stats.hpp"

namespace scfloam {
namespace {

// Hands the pages of free heap chunks back to the system, in every malloc arena. A long run's
// transient peaks (a solve's Ceres problem and factor, map rebuilds, clouds read back from the
// spill file and dropped) leave free chunks that glibc keeps resident in the arenas of the
// threads that freed them: over 20 000 patrol frames RSS less the heap in use grew 58 -> 150 MB
// while the heap in use stayed flat; with this trim it stays at ~80 MB
// (docs/robustness-long-run.md, session 7).
void release_free_heap() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

}  // namespace

LoopClosure::LoopClosure(const SlamConfig& config, LoopRegistrationMethod method,
                         KeyframeStore& store)
    : config_(config),
      method_(method),
      store_(store),
      earliest_partner_(std::numeric_limits<std::size_t>::max()),
      earliest_current_(std::numeric_limits<std::size_t>::max()) {}

std::vector<KeyframeView> LoopClosure::submap_around(std::size_t loop_kf, std::size_t limit,
                                                     std::size_t& loop_index) const {
  const int n = config_.loop_registration.submap_neighbors;
  const std::size_t first = loop_kf > static_cast<std::size_t>(n) ? loop_kf - n : 0;
  const std::size_t last = std::min(limit, loop_kf + n + 1);
  std::vector<KeyframeView> submap;
  for (std::size_t i = first; i < last; ++i) {
    const KeyframePtr kf = store_.get(i);
    submap.push_back({graph_.pose(i), &kf->edges, &kf->planes, &kf->raw});
    if (i == loop_kf) loop_index = submap.size() - 1;
  }
  return submap;
}

LoopMatch LoopClosure::register_features(const KeyframeView& current, std::size_t loop_kf,
                                         std::size_t limit, double sc_yaw_rad) {
  const int reuse = config_.loop_registration.submap_reuse_keyframes;
  const bool reusable =
      submap_ && reuse > 0 &&
      std::abs(static_cast<long>(loop_kf) - static_cast<long>(submap_->anchor_keyframe())) <= reuse;
  if (!reusable) {
    std::size_t loop_index = 0;
    const std::vector<KeyframeView> views = submap_around(loop_kf, limit, loop_index);
    submap_ = std::make_unique<LoopSubmap>(views, loop_index, views.empty() ? 0 : loop_kf - loop_index,
                                           config_.loop_registration,
                                           config_.odometry.registration, config_.odometry.map);
  }
  return register_loop_features(current, *submap_, graph_.pose(submap_->anchor_keyframe()),
                                graph_.pose(loop_kf), sc_yaw_rad, config_.loop_registration,
                                config_.odometry.registration);
}

void LoopClosure::apply_path_gate(LoopQuery& query, std::size_t current_kf) {
  std::vector<std::size_t> loop_kfs;
  for (const LoopCandidate& c : query.evaluated)
    if (c.verdict != LoopVerdict::kRejectedScore) loop_kfs.push_back(static_cast<std::size_t>(c.loop_kf));
  if (loop_kfs.empty()) return;
  paths_.clear_loops();
  for (const PoseGraphEdge& e : graph_.edges())
    if (e.is_loop && e.active) paths_.add_loop(e.from, e.to);
  const std::vector<double> path_m = paths_.from(current_kf, loop_kfs);
  const LoopDetectionConfig& d = config_.loop_detection;
  std::size_t next = 0;
  const Eigen::Isometry3d T_world_current = graph_.pose(current_kf);
  regate(
      query,
      [&](const LoopCandidate& c) {
        return DistanceGate::distance_m(graph_.pose(static_cast<std::size_t>(c.loop_kf)), T_world_current);
      },
      [&](const LoopCandidate&) { return d.gate_base_m + d.gate_drift_fraction * path_m[next++]; });
}

bool LoopClosure::add(const KeyframePtr& keyframe, const LoopQuery& detected, bool backlog) {
  const std::size_t k = keyframe->index;
  graph_.add_node(store_.current_pose(k));
  if (k > 0) graph_.add_odometry_edge(k - 1, k, keyframe->T_prev_current, config_.pose_graph);
  paths_.add_keyframe(keyframe->T_prev_current.translation().norm());
  LoopQuery query = detected;
  if (config_.loop_detection.adaptive_gate && config_.loop_detection.gate_drift_fraction > 0.0)
    apply_path_gate(query, k);
  const std::optional<std::size_t> row = log_.add(query);
  if (!query.best || !row) return false;

  // Register the current keyframe to the loop keyframe's submap, at the current estimates.
  Stopwatch watch;
  const std::size_t loop_kf = static_cast<std::size_t>(query.best->loop_kf);
  const KeyframeView current{graph_.pose(k), &keyframe->edges, &keyframe->planes, &keyframe->raw};
  // The submap stops short of the recent keyframes, which are never loop partners.
  LoopMatch match;
  if (method_ == LoopRegistrationMethod::kFeatures) {
    match = register_features(current, loop_kf, k, query.best->yaw_rad);
  } else {
    std::size_t loop_index = 0;
    const std::vector<KeyframeView> submap = submap_around(loop_kf, k, loop_index);
    match = register_loop_icp(current, submap, loop_index, query.best->yaw_rad,
                              config_.loop_registration);
  }
  registration_ms_.push_back(watch.elapsed_ms());
  log_.set_match(*row, match.accepted ? LoopVerdict::kAccepted : LoopVerdict::kRejectedMatch,
                 match.inlier_fraction, match.residual_m);
  if (!match.accepted) return false;

  // Edge from the current keyframe to the loop keyframe.
  if (match.information.isZero()) {
    graph_.add_loop_edge(k, loop_kf, match.T_loop_current.inverse(), config_.pose_graph);
  } else {  // the match's own information (loop_edge_information): L^T L = information
    const Eigen::Matrix<double, 6, 6> L = match.information.llt().matrixU();
    graph_.add_edge({k, loop_kf, match.T_loop_current.inverse(), L, true});
  }
  loop_rows_.push_back(*row);
  // A loop the graph already agrees with joins it for the next solve, the poses standing; one
  // that arrives while keyframes wait for this stage waits for the backlog's solve.
  const bool agrees =
      graph_.edge_chi2(graph_.edges().size() - 1) < config_.pose_graph.skip_solve_loop_chi2;
  // Only a loop that needs a solve widens the next window: one that agrees needs no node
  // freed, and holding its ends free would let it stretch the window past its cap.
  if (!agrees) {
    earliest_partner_ = std::min(earliest_partner_, loop_kf);
    earliest_current_ = std::min(earliest_current_, k);
  }
  const auto max_deferred = static_cast<std::size_t>(std::max(config_.pipeline.max_deferred_loops, 0));
  const bool defer = !agrees && backlog && pending_deferred_ < max_deferred;
  solves_skipped_ += agrees;
  if (defer) {
    ++pending_deferred_;
    ++solves_deferred_;
  }
  if (agrees || defer) {
    unsolved_loops_ = true;
    accepted_ = graph_.loop_edge_count();
    return true;
  }
  solve();
  return true;
}

void LoopClosure::solve_deferred() {
  if (pending_deferred_ > 0) solve();
}

void LoopClosure::finish() {
  if (unsolved_loops_ || whole_solve_due_) solve(/*whole_graph=*/true);
}

std::size_t LoopClosure::first_free_node(bool whole_graph) const {
  const PoseGraphConfig& c = config_.pose_graph;
  const int margin = c.solve_window_margin_keyframes;
  if (whole_graph || margin < 0) return 0;
  std::size_t first_free = 0;
  if (earliest_partner_ != std::numeric_limits<std::size_t>::max())
    first_free = earliest_partner_ > static_cast<std::size_t>(margin)
                     ? earliest_partner_ - static_cast<std::size_t>(margin)
                     : 0;
  // The cap: the newest solve_window_max_keyframes nodes at most, the older ones anchor; but
  // every loop added since the last solve keeps its newer end free, or it would not be solved.
  const std::size_t cap = static_cast<std::size_t>(std::max(c.solve_window_max_keyframes, 0));
  if (cap > 0 && graph_.size() > cap)
    first_free = std::max(first_free, std::min(graph_.size() - cap, earliest_current_));
  return first_free;
}

void LoopClosure::solve(bool whole_graph) {
  Stopwatch watch;
  const PoseGraphReport report = graph_.optimize(config_.pose_graph, first_free_node(whole_graph));
  optimization_ms_.push_back(watch.elapsed_ms());
  const std::size_t first_free = report.first_free_node;  // 0 if the solve escalated
  if (on_solve_) {
    const std::size_t fixed = std::min(std::max<std::size_t>(first_free, 1), graph_.size());
    on_solve_({graph_.size() - fixed, graph_.size(), optimization_ms_.back(), report.escalated});
  }
  whole_solve_due_ = first_free > 0;
  window_solves_ += first_free > 0;
  escalated_solves_ += report.escalated;
  confirmed_loops_ = report.confirmed_loops;
  earliest_partner_ = std::numeric_limits<std::size_t>::max();
  earliest_current_ = std::numeric_limits<std::size_t>::max();
  unsolved_loops_ = false;
  pending_deferred_ = 0;
  publish(report);
  // After a solve: its transient peak has just been freed, and it is the stage's rarest event
  // (one per ~200 frames on the patrol), so the trim's ~7 ms (median) cost nothing.
  Stopwatch trim_watch;
  release_free_heap();
  heap_trim_ms_.push_back(trim_watch.elapsed_ms());
}

void LoopClosure::publish(const PoseGraphReport& report) {
  // Loops the graph found inconsistent are recorded as rejected in the log, and those it
  // switched back on as accepted again.
  auto set_verdict = [&](std::size_t edge, LoopVerdict verdict) {
    std::size_t loop_number = 0;
    for (std::size_t e = 0; e < edge; ++e) loop_number += graph_.edges()[e].is_loop;
    const auto& logged = log_.rows()[loop_rows_.at(loop_number)];
    log_.set_match(loop_rows_[loop_number], verdict, logged.match_inlier_fraction,
                   logged.match_residual_m);
  };
  for (std::size_t edge : report.rejected_edges) set_verdict(edge, LoopVerdict::kRejectedMatch);
  for (std::size_t edge : report.restored_edges) set_verdict(edge, LoopVerdict::kAccepted);
  accepted_ = graph_.loop_edge_count();
  store_.set_optimized(graph_.poses());
}

}  // namespace scfloam
