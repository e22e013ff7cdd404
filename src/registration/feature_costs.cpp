#include "scfloam/registration/feature_costs.hpp"

#include <Eigen/Geometry>

namespace scfloam {

Eigen::Vector3d edge_residual(const EdgeMatch& m, const Eigen::Matrix3d& R,
                              const Eigen::Vector3d& t, Jacobian36* J) {
  const Eigen::Vector3d Rp = R * m.point_lidar;
  const Eigen::Vector3d d = Rp + t - m.line_point;
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - m.line_dir * m.line_dir.transpose();
  if (J) {
    // d(Rp)/d omega = -[Rp]x for R' = exp(omega) R; d t / d v = I.
    J->leftCols<3>() = -P * (Eigen::Matrix3d() << 0, -Rp.z(), Rp.y(), Rp.z(), 0, -Rp.x(),
                             -Rp.y(), Rp.x(), 0).finished();
    J->rightCols<3>() = P;
  }
  return P * d;
}

double plane_residual(const PlaneMatch& m, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                      Jacobian16* J) {
  const Eigen::Vector3d Rp = R * m.point_lidar;
  if (J) {
    J->leftCols<3>() = Rp.cross(m.normal).transpose();  // -n^T [Rp]x
    J->rightCols<3>() = m.normal.transpose();
  }
  return m.normal.dot(Rp + t) + m.offset;
}

Eigen::Matrix<double, 2, 3> perpendicular_basis(const Eigen::Vector3d& dir) {
  const Eigen::Vector3d helper =
      std::abs(dir.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d e1 = helper.cross(dir).normalized();
  Eigen::Matrix<double, 2, 3> E;
  E.row(0) = e1.transpose();
  E.row(1) = dir.cross(e1).transpose();
  return E;
}

FeatureCost::FeatureCost(const std::vector<EdgeMatch>& edges,
                         const std::vector<PlaneMatch>& planes, double huber_delta_m)
    : edges_(edges), planes_(planes), delta_(huber_delta_m) {
  set_num_residuals(static_cast<int>(2 * edges.size() + planes.size()));
  mutable_parameter_block_sizes()->push_back(7);
}

bool FeatureCost::Evaluate(double const* const* parameters, double* residuals,
                           double** jacobians) const {
  const Eigen::Quaterniond q = Eigen::Map<const Eigen::Quaterniond>(parameters[0]).normalized();
  const Eigen::Matrix3d R = q.toRotationMatrix();
  const Eigen::Map<const Eigen::Vector3d> t(parameters[0] + 4);
  double* J = (jacobians && jacobians[0]) ? jacobians[0] : nullptr;  // row-major rows x 7
  std::size_t row = 0;
  for (const auto& m : edges_) {
    // The residual lies in the plane perpendicular to the line: its coordinates in an
    // orthonormal basis of that plane have the same norm and give the same J^T J in two rows
    // instead of three (Ceres' work per iteration grows with the rows).
    Jacobian36 J3;
    const Eigen::Vector3d r3 = edge_residual(m, R, t, J ? &J3 : nullptr);
    const Eigen::Matrix<double, 2, 3> E = perpendicular_basis(m.line_dir);
    Eigen::Vector2d r = E * r3;
    Eigen::Matrix<double, 2, 6> Je;
    if (J) Je.noalias() = E * J3;
    robustify_huber<2>(delta_, r, J ? &Je : nullptr);
    for (int i = 0; i < 2; ++i, ++row) {
      residuals[row] = r[i];
      if (J) {
        Eigen::Map<Eigen::Matrix<double, 1, 7>> Jrow(J + 7 * row);
        Jrow << Je.row(i), 0.0;
      }
    }
  }
  for (const auto& m : planes_) {
    Jacobian16 Jp;
    Eigen::Matrix<double, 1, 1> r(plane_residual(m, R, t, J ? &Jp : nullptr));
    robustify_huber<1>(delta_, r, J ? &Jp : nullptr);
    residuals[row] = r[0];
    if (J) {
      Eigen::Map<Eigen::Matrix<double, 1, 7>> Jrow(J + 7 * row);
      Jrow << Jp, 0.0;
    }
    ++row;
  }
  return true;
}

}  // namespace scfloam
