// One edge of the keyframe pose graph (pose_graph.hpp), apart so that loop_support.hpp can
// read edges without the graph.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>

namespace scfloam {

struct PoseGraphEdge {
  std::size_t from = 0, to = 0;
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();
  // Square root of the information matrix; the residual is [Log(R_err); t_err] of the error
  // transform E = T_from_to^-1 * (T_world_from^-1 * T_world_to).
  Eigen::Matrix<double, 6, 6> sqrt_information = Eigen::Matrix<double, 6, 6>::Identity();
  bool is_loop = false;
  bool active = true;  // false while the solver finds the loop inconsistent
};

}  // namespace scfloam
