// Keyframe pose graph on Ceres: nodes are keyframe poses T_world_kf, edges are measured
// relative poses T_i_j (odometry between consecutive keyframes, loops from registration).
//
// Robustness against wrong loops, in two layers (docs/loop_closure.md, "Pose graph"), which
// loops confirmed by their neighbours are exempt from (loop_support.hpp):
// - loop edges carry a Cauchy kernel in the final solve, so a mildly inconsistent loop pulls
//   less;
// - after a least-squares solve, a loop whose whitened residual is still beyond a chi-square
//   bound is inconsistent with the odometry and the other loops: it is switched off and the
//   graph is solved again; a loop switched off earlier that fits the new solution is switched
//   back on (a false loop can make its true neighbour misfit first). A bounded kernel alone
//   cannot do this job: a genuine first loop after a long drive carries metres of discrepancy,
//   which a tight kernel would treat as an outlier and leave the loop open.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <filesystem>
#include <vector>

#include "scfloam/backend/loop_support.hpp"
#include "scfloam/backend/pose_graph_config.hpp"
#include "scfloam/backend/pose_graph_edge.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

struct PoseGraphReport {
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
  double solve_ms = 0;
  bool converged = false;
  std::vector<std::size_t> rejected_edges;  // indices into edges() switched off by this solve
  // Loops switched off earlier that fit again, or that their neighbours now confirm.
  std::vector<std::size_t> restored_edges;
  // The window actually solved: a windowed solve in which a loop misfits is escalated to the
  // whole graph (first_free_node 0), which alone judges loops.
  std::size_t first_free_node = 0;
  bool escalated = false;
  // Loops confirmed by their neighbours: not robustified, switched off only for a gross misfit.
  std::size_t confirmed_loops = 0;
};

// Square-root information for independent rotation/translation sigmas.
Eigen::Matrix<double, 6, 6> sqrt_information_from_sigmas(double rotation_sigma_rad,
                                                         double translation_sigma_m);

class PoseGraph {
 public:
  // Adds a node with its initial estimate; returns its index.
  std::size_t add_node(const Eigen::Isometry3d& T_world_node);
  void add_edge(const PoseGraphEdge& edge);
  // Convenience: edges with the config's sigmas.
  void add_odometry_edge(std::size_t from, std::size_t to, const Eigen::Isometry3d& T_from_to,
                         const PoseGraphConfig& config);
  void add_loop_edge(std::size_t from, std::size_t to, const Eigen::Isometry3d& T_from_to,
                     const PoseGraphConfig& config);

  // Optimizes all nodes with node 0 held fixed (the map's origin). With first_free_node > 0,
  // a bounded window: nodes before it stay where they are, and edges among them are left out;
  // if a loop misfits in the window, the solve is escalated to the whole graph.
  PoseGraphReport optimize(const PoseGraphConfig& config, std::size_t first_free_node = 0);

  std::size_t size() const { return nodes_.size(); }
  Eigen::Isometry3d pose(std::size_t node) const;
  PoseList poses() const;
  const std::vector<PoseGraphEdge>& edges() const { return edges_; }
  // Squared whitened residual of an edge under the current estimate.
  double edge_chi2(std::size_t edge) const;
  std::size_t loop_edge_count() const;
  // Per edge: 1 for a loop confirmed by its neighbours (loop_support.hpp, config.loop_support_*).
  // Not thread-safe even though const: it brings a cache of the counts up to date.
  std::vector<char> confirmed_loops(const PoseGraphConfig& config) const;

  // g2o text format (VERTEX_SE3:QUAT / EDGE_SE3:QUAT, information in g2o's [t, r] order),
  // readable by g2o and GTSAM's readG2o. Written atomically.
  void write_g2o(const std::filesystem::path& path) const;

 private:
  // One parameter block per node: [tx ty tz qx qy qz qw] (Eigen's quaternion storage order).
  std::vector<std::array<double, 7>> nodes_;
  std::vector<PoseGraphEdge> edges_;

  // robust_except: null for least squares; else loops take the Cauchy kernel except those marked.
  PoseGraphReport solve_once(const PoseGraphConfig& config, const std::vector<char>* robust_except,
                             std::size_t first_free_node);
  // The active loop in the window with the largest chi2 above min_chi2, or edges_.size();
  // loops marked in `confirmed` are passed over unless their chi2 exceeds confirmed_max_chi2.
  std::size_t worst_loop(double min_chi2, std::size_t first_free_node,
                         const std::vector<char>* confirmed, double confirmed_max_chi2) const;
  // Kept up to date as edges are added (the counts depend on the measurements only).
  mutable LoopSupport support_;
  // Per edge: a confirmed loop switched off for a gross misfit (loop_support_max_chi2); it
  // comes back only by fitting, not by its confirmation (which would switch it on and off in
  // every solve).
  std::vector<char> held_off_;
  bool in_window(const PoseGraphEdge& e, std::size_t first_free_node) const {
    return e.from >= first_free_node || e.to >= first_free_node;
  }
};

}  // namespace scfloam
