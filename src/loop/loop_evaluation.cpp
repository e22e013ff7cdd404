#include "scfloam/loop/loop_evaluation.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "scfloam/error.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

RevisitDirection classify(const Eigen::Isometry3d& T_world_old, const Eigen::Isometry3d& T_world_new,
                          const LoopEvaluationConfig& config) {
  const double angle_deg =
      rotation_angle_rad(T_world_old.linear().transpose() * T_world_new.linear()) * 180.0 / M_PI;
  if (angle_deg <= config.same_direction_max_deg) return RevisitDirection::kSame;
  if (angle_deg >= config.opposite_direction_min_deg) return RevisitDirection::kOpposite;
  return RevisitDirection::kCrossing;
}

}  // namespace

std::vector<RevisitEpisode> find_revisit_episodes(const PoseList& T_world_keyframes_gt,
                                                  const LoopEvaluationConfig& config) {
  const int n = static_cast<int>(T_world_keyframes_gt.size());
  const double radius_sq = config.revisit_radius_m * config.revisit_radius_m;
  std::vector<RevisitEpisode> episodes;
  bool in_episode = false;
  for (int i = 0; i < n; ++i) {
    // The closest older keyframe far enough back in time decides whether and how i revisits.
    int closest = -1;
    double closest_sq = std::numeric_limits<double>::infinity();
    const Eigen::Vector3d t_i = T_world_keyframes_gt[i].translation();
    for (int j = 0; j < i - config.min_keyframe_gap; ++j) {
      const double d_sq = (T_world_keyframes_gt[j].translation() - t_i).squaredNorm();
      if (d_sq < closest_sq) {
        closest_sq = d_sq;
        closest = j;
      }
    }
    if (closest < 0 || closest_sq > radius_sq) {
      in_episode = false;
      continue;
    }
    const RevisitDirection direction =
        classify(T_world_keyframes_gt[closest], T_world_keyframes_gt[i], config);
    if (in_episode && episodes.back().direction == direction && episodes.back().last_kf == i - 1) {
      episodes.back().last_kf = i;
    } else {
      episodes.push_back({i, i, direction, false});
      in_episode = true;
    }
  }
  return episodes;
}

LoopEvaluation evaluate_loops(const PoseList& T_world_keyframes_gt,
                              const std::vector<LoopCandidate>& candidates,
                              const LoopEvaluationConfig& config) {
  LoopEvaluation result;
  result.episodes = find_revisit_episodes(T_world_keyframes_gt, config);
  const int n = static_cast<int>(T_world_keyframes_gt.size());
  for (const LoopCandidate& c : candidates) {
    if (c.verdict != LoopVerdict::kAccepted) continue;
    if (c.current_kf < 0 || c.current_kf >= n || c.loop_kf < 0 || c.loop_kf >= n)
      throw Error("loop evaluation: candidate keyframes " + std::to_string(c.current_kf) + ", " +
                  std::to_string(c.loop_kf) + " outside the " + std::to_string(n) +
                  " ground-truth keyframes");
    ++result.accepted;
    const double d = (T_world_keyframes_gt[c.current_kf].translation() -
                      T_world_keyframes_gt[c.loop_kf].translation()).norm();
    if (d > config.correct_radius_m) {
      result.false_positives.push_back(c);
      continue;
    }
    ++result.true_positives;
    for (RevisitEpisode& e : result.episodes)
      if (c.current_kf >= e.first_kf && c.current_kf <= e.last_kf) e.found = true;
  }
  for (const RevisitEpisode& e : result.episodes) {
    EpisodeRecall& r = e.direction == RevisitDirection::kSame       ? result.same
                       : e.direction == RevisitDirection::kOpposite ? result.opposite
                                                                    : result.crossing;
    ++r.episodes;
    if (e.found) ++r.found;
  }
  return result;
}

}  // namespace scfloam
