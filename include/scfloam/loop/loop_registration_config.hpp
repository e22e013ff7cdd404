// Loop registration parameters (docs/parameters.md).
#pragma once

namespace scfloam {

struct LoopRegistrationConfig {
  int submap_neighbors = 25;  // keyframes each side of the loop keyframe in the submap
  // Reuse the last submap while the loop keyframe stays within this many keyframes of its
  // anchor (consecutive loop frames revisit neighbouring keyframes); 0 rebuilds every time.
  int submap_reuse_keyframes = 10;
  // Feature registration, coarse to fine: a loop starts farther off than a frame does, so the
  // first rounds search correspondences within coarse_radius_m, the last ones within the
  // odometry's own radius.
  double coarse_radius_m = 2.5;
  int coarse_rounds = 6;
  // Map neighbours of a feature point in the loop match (solve and check), in place of the
  // odometry's registration.knn: F-LOAM's 5, which the check's 0.45 was measured with. The
  // odometry's 8-12 make its chained estimate tilt less, but in a loop match they cost
  // matches on a thin submap (fewer points have their k-th neighbour within reach) and, from
  // a drifted guess, right loops (docs/loop_closure.md, "Session 17").
  int knn = 5;
  int rounds = 6;
  // Try the fine stage alone from the pose guess first: once a revisit's first loop has closed
  // the graph, the poses are right to centimetres and the coarse stage only costs time.
  // Falls back to coarse to fine (both guesses) when that match fails the check.
  bool fine_first = true;
  // A match is accepted when at least this fraction of the current features found a line or
  // plane in the submap and their mean distance is below max_mean_residual_m.
  double min_inlier_fraction = 0.45;
  double max_mean_residual_m = 0.08;
  // The fraction counts plane matches under this flatness test (F-LOAM's 0.2 m, which the
  // 0.45 was measured with), not under the solve's stricter registration.plane_max_dist_m:
  // the solve refuses rough patches to keep their bias out of the pose, but a rough patch
  // that lies on the submap's surface still says the match is right.
  double check_plane_max_dist_m = 0.2;
  // An accepted feature match's pose-graph edge takes its information from the match, the
  // Hessian over the residual variance, divided by this: the residuals of neighbouring points
  // are not independent (shared map points, the scan's own distortion), so the Hessian alone
  // is overconfident. 0 = the fixed pose_graph.loop_*_sigma instead (as ICP loops always do).
  double information_inflation = 0;
  // ICP baseline, SC-A-LOAM's parameters: Open3D point-to-point ICP on clouds downsampled at
  // icp_leaf_m; accepted when the mean squared correspondence distance (PCL's "fitness
  // score") is below icp_max_fitness_m2.
  double icp_leaf_m = 0.4;
  double icp_max_correspondence_m = 150.0;
  int icp_max_iterations = 100;
  double icp_max_fitness_m2 = 0.3;
};

}  // namespace scfloam
