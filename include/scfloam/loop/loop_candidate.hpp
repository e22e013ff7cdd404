// One evaluated loop candidate: a pair of keyframes, how well their Scan Contexts agree,
// what the distance gate said, and the verdict (one row of loops.csv).
#pragma once

#include <cstdint>
#include <limits>
#include <string>

namespace scfloam {

enum class LoopVerdict {
  kAccepted,       // passed score and gate (and, once registered, the match check)
  kRejectedScore,  // Scan Context distance above the threshold
  kRejectedGate,   // farther than the distance gate under the current poses
  kRejectedRank,   // passed score and gate, but a better candidate was chosen for this keyframe
  kRejectedMatch,  // loop registration did not produce a good match (set by the caller)
};

// "accepted", "rejected_score", "rejected_gate", "rejected_rank", "rejected_match".
std::string to_string(LoopVerdict verdict);
// Inverse of to_string; throws scfloam::Error on an unknown name.
LoopVerdict parse_loop_verdict(const std::string& name);

struct LoopCandidate {
  std::int64_t current_frame = -1, loop_frame = -1;  // frame indices in the input sequence
  int current_kf = -1, loop_kf = -1;                  // keyframe indices
  double sc_score = 1.0;              // mean column cosine distance after alignment, [0, 1]
  double yaw_rad = 0.0;               // yaw of T_loop_current from the column shift
  double ring_key_distance = 0.0;     // L2 distance of the ring keys (search order)
  double distance_m = 0.0;            // |t(T_world_loop^-1 T_world_current)|, current poses
  double gate_m = 0.0;                // the gate threshold at this query
  LoopVerdict verdict = LoopVerdict::kRejectedScore;
  // Filled by loop registration (issue 5); NaN = not registered.
  double match_inlier_fraction = std::numeric_limits<double>::quiet_NaN();
  double match_residual_m = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace scfloam
