#include "scfloam/registration/pose_manifold.hpp"

#include "scfloam/se3.hpp"

namespace scfloam {

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Eigen::Quaterniond> q(x);
  const Eigen::Map<const Eigen::Vector3d> t(x + 4);
  const Eigen::Map<const Eigen::Vector3d> omega(delta), v(delta + 3);
  const double angle = omega.norm();
  const Eigen::Quaterniond dq =
      angle < 1e-12 ? Eigen::Quaterniond(1, 0.5 * omega.x(), 0.5 * omega.y(), 0.5 * omega.z())
                    : Eigen::Quaterniond(Eigen::AngleAxisd(angle, omega / angle));
  Eigen::Map<Eigen::Quaterniond> q_out(x_plus_delta);
  Eigen::Map<Eigen::Vector3d> t_out(x_plus_delta + 4);
  q_out = (dq * q).normalized();  // stay on SO(3): never let the quaternion drift in norm
  t_out = t + v;
  return true;
}

bool PoseManifold::PlusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topRows<6>().setIdentity();
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Map<const Eigen::Quaterniond> qy(y), qx(x);
  Eigen::Map<Eigen::Matrix<double, 6, 1>> d(y_minus_x);
  d.head<3>() = so3_log((qy * qx.conjugate()).normalized().toRotationMatrix());
  d.tail<3>() = Eigen::Map<const Eigen::Vector3d>(y + 4) - Eigen::Map<const Eigen::Vector3d>(x + 4);
  return true;
}

bool PoseManifold::MinusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.leftCols<6>().setIdentity();
  return true;
}

bool SubspacePoseManifold::Plus(const double* x, const double* delta,
                                double* x_plus_delta) const {
  const Eigen::Matrix<double, 6, 1> full_delta =
      basis_ * Eigen::Map<const Eigen::VectorXd>(delta, basis_.cols());
  return full_.Plus(x, full_delta.data(), x_plus_delta);
}

bool SubspacePoseManifold::PlusJacobian(const double*, double* jacobian) const {
  // [I_6; 0] * B, stored row-major 7 x m.
  Eigen::Map<Eigen::Matrix<double, 7, Eigen::Dynamic, Eigen::RowMajor>> J(jacobian, 7,
                                                                          basis_.cols());
  J.setZero();
  J.topRows<6>() = basis_;
  return true;
}

bool SubspacePoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Matrix<double, 6, 1> full_delta;
  full_.Minus(y, x, full_delta.data());
  Eigen::Map<Eigen::VectorXd>(y_minus_x, basis_.cols()) = basis_.transpose() * full_delta;
  return true;
}

bool SubspacePoseManifold::MinusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>> J(jacobian,
                                                                          basis_.cols(), 7);
  J.setZero();
  J.leftCols<6>() = basis_.transpose();
  return true;
}

void pose_to_block(const Eigen::Isometry3d& T, double* block) {
  Eigen::Map<Eigen::Quaterniond> q(block);
  Eigen::Map<Eigen::Vector3d> t(block + 4);
  q = Eigen::Quaterniond(T.linear()).normalized();
  t = T.translation();
}

Eigen::Isometry3d block_to_pose(const double* block) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Map<const Eigen::Quaterniond>(block).normalized().toRotationMatrix();
  T.translation() = Eigen::Map<const Eigen::Vector3d>(block + 4);
  return T;
}

}  // namespace scfloam
