// Point-to-line and point-to-plane residuals with analytic Jacobians, and the Ceres cost that
// evaluates all of a round's matches in one residual block (one block per match costs Ceres
// ~10x more in bookkeeping than the arithmetic itself at ~10^4 matches per frame).
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <vector>

namespace scfloam {

// An edge point and the map line it matched: residual = component of (T p - line_point)
// perpendicular to line_dir (a 3-vector whose norm is the point-to-line distance).
struct EdgeMatch {
  Eigen::Vector3d point_lidar;
  Eigen::Vector3d line_point;
  Eigen::Vector3d line_dir;  // unit
};

// A plane point and the map plane it matched: residual = normal . (T p) + offset.
struct PlaneMatch {
  Eigen::Vector3d point_lidar;
  Eigen::Vector3d normal;  // unit
  double offset = 0;
};

using Jacobian16 = Eigen::Matrix<double, 1, 6>;
using Jacobian36 = Eigen::Matrix<double, 3, 6>;

// Residuals at pose (R, t) and, when J is not null, their derivative with respect to the
// tangent delta = [omega; v] of PoseManifold.
Eigen::Vector3d edge_residual(const EdgeMatch& m, const Eigen::Matrix3d& R,
                              const Eigen::Vector3d& t, Jacobian36* J);
double plane_residual(const PlaneMatch& m, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                      Jacobian16* J);

// Orthonormal rows spanning the plane perpendicular to the unit vector `dir`.
Eigen::Matrix<double, 2, 3> perpendicular_basis(const Eigen::Vector3d& dir);

// Huber loss folded into the residual: r <- sqrt(rho(|r|^2)) r / |r|, so that the squared
// norm equals Huber's rho(s) = s for s <= delta^2, 2 delta sqrt(s) - delta^2 above; J is
// transformed with the exact derivative. Keeps the loss per match inside one residual block.
template <int Rows>
void robustify_huber(double delta, Eigen::Matrix<double, Rows, 1>& r,
                     Eigen::Matrix<double, Rows, 6>* J) {
  const double m = r.norm();
  if (m <= delta) return;
  const double rho = 2 * delta * m - delta * delta;
  const double g = std::sqrt(rho) / m;      // scale perpendicular to r
  const double a = delta / std::sqrt(rho);  // d|r~|/d|r| along r
  if (J) {
    const Eigen::Matrix<double, Rows, 1> u = r / m;
    *J = g * *J + (a - g) * u * (u.transpose() * *J);
  }
  r *= g;
}

// All matches of one correspondence round as one residual block on the 7-double pose block:
// two rows per edge (the point-to-line vector in a basis perpendicular to the line), one per
// plane, each robustified.
class FeatureCost : public ceres::CostFunction {
 public:
  FeatureCost(const std::vector<EdgeMatch>& edges, const std::vector<PlaneMatch>& planes,
              double huber_delta_m);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const std::vector<EdgeMatch>& edges_;
  const std::vector<PlaneMatch>& planes_;
  double delta_;
};

}  // namespace scfloam
