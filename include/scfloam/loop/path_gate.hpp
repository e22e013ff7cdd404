// The distance gate measured in the pose graph: a loop candidate is plausible when its
// distance under the current (optimized) poses is within base + drift_fraction * L, L being
// the shortest path length that links the two keyframes in the graph (along the keyframe
// chain, or shortened through accepted loops). Odometry drift accumulates along that path,
// so it bounds how far apart the estimates of one place can be. The paper's k/n term grows
// with the whole drive instead (docs/loop_closure.md: on the KITTI-00-like replay it rejects
// a 212-keyframe revisit whose estimates are 48-57 m apart after ~800 m of graph path).
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "scfloam/loop/loop_detector.hpp"

namespace scfloam {

class GraphPathLengths {
 public:
  // Appends a keyframe `step_m` of travel after the previous one (ignored for the first).
  void add_keyframe(double step_m);
  // An accepted loop between keyframes a and b: a path through it costs nothing.
  void add_loop(std::size_t a, std::size_t b);
  void clear_loops() { loops_.clear(); }
  std::size_t size() const { return along_m_.size(); }

  // Shortest path length (m) from `source` to each of `targets` (all < size()).
  std::vector<double> from(std::size_t source, const std::vector<std::size_t>& targets) const;

 private:
  std::vector<double> along_m_;  // path length along the chain from keyframe 0
  std::vector<std::pair<std::size_t, std::size_t>> loops_;
};

// Re-applies the gate to the candidates that passed the Scan Context score: distance_m and
// gate_m come from the callables (called in candidate order), verdicts are set again (gate, then rank: the best score
// among those within their gate wins) and query.best is replaced.
template <class DistanceOf, class GateOf>
void regate(LoopQuery& query, DistanceOf distance_of, GateOf gate_of) {
  LoopCandidate* best = nullptr;
  for (LoopCandidate& c : query.evaluated) {
    if (c.verdict == LoopVerdict::kRejectedScore) continue;
    c.distance_m = distance_of(c);
    c.gate_m = gate_of(c);
    c.verdict = c.distance_m <= c.gate_m ? LoopVerdict::kAccepted : LoopVerdict::kRejectedGate;
    if (c.verdict == LoopVerdict::kAccepted && (best == nullptr || c.sc_score < best->sc_score))
      best = &c;
  }
  for (LoopCandidate& c : query.evaluated)
    if (c.verdict == LoopVerdict::kAccepted && &c != best) c.verdict = LoopVerdict::kRejectedRank;
  query.best.reset();
  if (best != nullptr) query.best = *best;
}

}  // namespace scfloam
