// The third stage: keyframes become pose-graph nodes; a proposed loop is registered (features
// or ICP, by mode), checked, added as a robust edge, and the graph re-optimized. Corrected
// poses go to the keyframe store, where the other stages pick them up.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <vector>

#include "pipeline/keyframe_store.hpp"
#include "scfloam/backend/pose_graph.hpp"
#include "scfloam/config.hpp"
#include "scfloam/loop/loop_detector.hpp"
#include "scfloam/loop/loop_registration.hpp"
#include "scfloam/loop/loops_csv.hpp"
#include "scfloam/loop/path_gate.hpp"

namespace scfloam {

enum class LoopRegistrationMethod { kFeatures, kIcp };

class LoopClosure {
 public:
  LoopClosure(const SlamConfig& config, LoopRegistrationMethod method, KeyframeStore& store);

  // Adds keyframe `keyframe` (already in the store) and handles the loop its query proposed.
  // Returns true when the loop was accepted. An accepted loop the graph does not already
  // agree with is solved at once, unless `backlog` (keyframes are waiting for this stage) and
  // fewer than pipeline.max_deferred_loops solves are pending: then solve_deferred() or the
  // next add() without a backlog solves them together.
  bool add(const KeyframePtr& keyframe, const LoopQuery& query, bool backlog = false);
  // One solve for the deferred loops, if any (the store then holds corrected poses).
  void solve_deferred();
  // End of the run: one solve if loops were added without one since the last (their edges
  // then inform the final poses).
  void finish();
  // Called after every solve (a long run's monitor: window size and time); may be empty.
  void set_on_solve(std::function<void(const SolveSample&)> on_solve) {
    on_solve_ = std::move(on_solve);
  }

  const LoopLog& log() const { return log_; }
  const PoseGraph& graph() const { return graph_; }
  std::size_t accepted_loops() const { return accepted_.load(); }  // any thread
  const std::vector<double>& registration_ms() const { return registration_ms_; }
  const std::vector<double>& optimization_ms() const { return optimization_ms_; }
  // Time to hand free heap back to the system after each solve (malloc_trim, glibc only).
  const std::vector<double>& heap_trim_ms() const { return heap_trim_ms_; }
  // Accepted loops added without a solve (pose_graph.skip_solve_loop_chi2).
  std::size_t solves_skipped() const { return solves_skipped_; }
  // Accepted loops whose solve waited for a backlog to clear (pipeline.max_deferred_loops).
  std::size_t solves_deferred() const { return solves_deferred_; }
  // Solves that freed only a window of the graph (pose_graph.solve_window_margin_keyframes).
  std::size_t window_solves() const { return window_solves_; }
  // Window solves in which a loop misfit, so that the whole graph was solved to judge it.
  std::size_t escalated_solves() const { return escalated_solves_; }
  // Loops confirmed by their neighbours at the last solve (pose_graph.loop_support_*).
  std::size_t confirmed_loops() const { return confirmed_loops_; }

 private:
  std::vector<KeyframeView> submap_around(std::size_t loop_kf, std::size_t limit,
                                          std::size_t& loop_index) const;
  // Logs the loops a solve switched off and hands the poses to the store.
  void publish(const PoseGraphReport& report);
  // Timed solve, then publish: a window from the earliest pending loop partner (less the
  // margin) to the newest node, or with `whole_graph` every node.
  void solve(bool whole_graph = false);
  // First node a solve frees: the earliest pending loop partner less the margin, but no
  // earlier than the window cap allows (pose_graph.solve_window_*); 0 for the whole graph.
  std::size_t first_free_node(bool whole_graph) const;
  // The gate in the graph (loop_detection.gate_drift_fraction > 0): distances under the
  // optimized poses, uncertainty growing with the graph path between the two keyframes.
  void apply_path_gate(LoopQuery& query, std::size_t current_kf);
  LoopMatch register_features(const KeyframeView& current, std::size_t loop_kf, std::size_t limit,
                              double sc_yaw_rad);

  const SlamConfig& config_;
  LoopRegistrationMethod method_;
  KeyframeStore& store_;
  PoseGraph graph_;
  GraphPathLengths paths_;  // keyframe chain + accepted loops, for the path gate
  LoopLog log_;
  std::unique_ptr<LoopSubmap> submap_;  // feature method: reused across consecutive loops
  std::vector<std::size_t> loop_rows_;  // loops.csv row of each loop edge, in edge order
  std::atomic<std::size_t> accepted_{0};
  std::vector<double> registration_ms_, optimization_ms_, heap_trim_ms_;
  std::function<void(const SolveSample&)> on_solve_;
  std::size_t solves_skipped_ = 0, solves_deferred_ = 0, window_solves_ = 0,
              escalated_solves_ = 0, confirmed_loops_ = 0;
  std::size_t pending_deferred_ = 0;  // deferred loops not yet solved
  std::size_t earliest_partner_;      // of the loops added since the last solve
  std::size_t earliest_current_;      // newer end of the earliest loop since the last solve
  bool whole_solve_due_ = false;      // a window solve left older nodes out
  bool unsolved_loops_ = false;
};

}  // namespace scfloam
