// Sequence-level precision/recall of loop detection against ground truth (issue 4):
// a keyframe revisits when an older keyframe, more than `min_keyframe_gap` keyframes earlier,
// lies within `revisit_radius_m` under ground truth; contiguous runs of revisiting keyframes
// heading the same way relative to the revisited place form an episode. Recall counts episodes
// with at least one correct accepted candidate; precision counts accepted candidates whose two
// keyframes are within `correct_radius_m` under ground truth.
#pragma once

#include <vector>

#include "scfloam/loop/loop_candidate.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

struct LoopEvaluationConfig {
  double revisit_radius_m = 5.0;
  int min_keyframe_gap = 100;         // revisit = more than this many keyframes apart
  double correct_radius_m = 5.0;      // an accepted candidate is true when this close
  double same_direction_max_deg = 45.0;       // relative heading below: same direction
  double opposite_direction_min_deg = 135.0;  // above: opposite; between: crossing
};

enum class RevisitDirection { kSame, kOpposite, kCrossing };

struct RevisitEpisode {
  int first_kf = 0, last_kf = 0;  // inclusive keyframe range of the current (revisiting) pass
  RevisitDirection direction = RevisitDirection::kSame;
  bool found = false;
};

struct EpisodeRecall {
  int episodes = 0, found = 0;
  double recall() const { return episodes == 0 ? 1.0 : static_cast<double>(found) / episodes; }
};

struct LoopEvaluation {
  int accepted = 0, true_positives = 0;
  std::vector<LoopCandidate> false_positives;
  std::vector<RevisitEpisode> episodes;
  EpisodeRecall same, opposite, crossing;
  // Precision of accepted candidates; 1 when none was accepted.
  double precision() const { return accepted == 0 ? 1.0 : static_cast<double>(true_positives) / accepted; }
};

// Ground-truth revisit episodes of a keyframe trajectory (episodes' `found` all false).
std::vector<RevisitEpisode> find_revisit_episodes(const PoseList& T_world_keyframes_gt,
                                                  const LoopEvaluationConfig& config);

// Scores the candidates whose verdict is kAccepted (others are ignored).
LoopEvaluation evaluate_loops(const PoseList& T_world_keyframes_gt,
                              const std::vector<LoopCandidate>& candidates,
                              const LoopEvaluationConfig& config);

}  // namespace scfloam
