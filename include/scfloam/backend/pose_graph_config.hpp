// Pose graph parameters (docs/parameters.md); kept apart from pose_graph.hpp so that the
// whole configuration can be included without Ceres or Eigen.
#pragma once

namespace scfloam {

struct PoseGraphConfig {
  // Odometry edge standard deviations per edge (the public code: variances 1e-6 rad^2, 1e-4 m^2).
  double odometry_rotation_sigma_rad = 1e-3;
  double odometry_translation_sigma_m = 1e-2;
  // Loop edge standard deviations before the robust kernel (the public code: variance 0.5).
  double loop_rotation_sigma_rad = 0.05;
  double loop_translation_sigma_m = 0.1;
  // Cauchy scale in whitened units: residuals well below it count quadratically.
  double loop_cauchy_scale = 5.0;
  // A loop whose squared whitened residual after solving exceeds this is switched off
  // (chi-square, 6 dof: 22.46 is the 99.9 % quantile).
  double loop_outlier_chi2 = 22.46;
  int max_outlier_rounds = 3;
  // A loop that closes a consistent short cycle with at least loop_support_min other loops
  // (their ends within loop_support_span_keyframes of its own on the odometry chain; the cycle
  // loop, odometry, other loop, odometry within loop_support_translation_m and
  // loop_support_rotation_deg of the identity) is confirmed: the chi-square test above does not
  // switch it off and the Cauchy kernel does not weaken it. A heading failure of the odometry
  // (14 degrees in one turn, measured) leaves every loop across it misfitting the chain's
  // sigmas, and the test would switch all of them off; the loops agree with each other, and
  // that is the evidence that the chain, not they, went wrong (docs/loop_closure.md, "Loops
  // that confirm each other"). loop_support_span_keyframes 0: no loop is confirmed.
  int loop_support_min = 2;
  int loop_support_span_keyframes = 10;
  double loop_support_translation_m = 0.3;
  double loop_support_rotation_deg = 0.5;
  // ... but a confirmed loop whose squared whitened residual after least squares is above this
  // (10x the test's bound: 1.5 m at the loop's 0.1 m sigma) is judged like any other: a group
  // of mutually consistent false loops (one repeated structure matched the same wrong way) must
  // not bend the graph without limit. Measured true loops after an 18 / 30 degree failure:
  // at most 27 / 111.
  double loop_support_max_chi2 = 224.6;
  // A new loop whose squared whitened residual under the current estimate is below this is
  // added without a solve: the graph already agrees with it (0.05: about 2 cm at the default
  // 0.1 m sigma). On a revisited route most loops after the first one are like that, and a
  // full solve of thousands of keyframes per loop made the closure stage the bottleneck of a
  // long run (docs/robustness-long-run.md). The run ends with one solve if loops were added
  // since the last. 0 = solve after every loop.
  double skip_solve_loop_chi2 = 0.05;
  // A solve during the run frees only the nodes from the earliest loop partner since the last
  // solve, minus this many keyframes, to the newest; older nodes stay where they are (they
  // anchor the window through the edges that reach into it). On a route that keeps revisiting
  // the same block the loops then cost one lap's keyframes, not the whole history's. The run
  // ends with a whole-graph solve, so offline results see every loop. < 0: every solve frees
  // the whole graph.
  int solve_window_margin_keyframes = 100;
  // ... and at most this many of the newest nodes, however old the earliest partner: on a
  // patrol a loop to the first lap freed nearly the whole graph (20 000 frames: 4000-5900 of
  // 6000 nodes, solves of seconds, the closure queue full), while that lap's nodes, placed by
  // earlier solves, can as well anchor the loop as fixed nodes; 1000 is about three patrol laps
  // (docs/robustness-long-run.md, session 7). The run's final whole-graph solve still frees
  // every node. 0: no cap (window from the partner only).
  int solve_window_max_keyframes = 1000;
  int max_iterations = 50;
};

}  // namespace scfloam
