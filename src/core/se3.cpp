#include "scfloam/se3.hpp"

#include <Eigen/SVD>
#include <cmath>

namespace scfloam {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Eigen::Matrix3d so3_exp(const Eigen::Vector3d& omega) {
  const double angle = omega.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity() + skew(omega);
  return Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
}

Eigen::Vector3d so3_log(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(Eigen::Quaterniond(R).normalized());
  double angle = aa.angle();
  Eigen::Vector3d axis = aa.axis();
  if (angle > M_PI) {  // Eigen may return (2pi - a) about -axis's opposite
    angle = 2 * M_PI - angle;
    axis = -axis;
  }
  return axis * angle;
}

double rotation_angle_rad(const Eigen::Matrix3d& R) {
  // atan2 form: accurate for small and large angles alike (acos loses precision near 0).
  const Eigen::Vector3d v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * v.norm(), 0.5 * (R.trace() - 1.0));
}

Eigen::Isometry3d orthonormalized(const Eigen::Isometry3d& T) {
  Eigen::Isometry3d out = T;
  Eigen::Quaterniond q(T.linear());
  out.linear() = q.normalized().toRotationMatrix();
  return out;
}

Eigen::Isometry3d left_perturb(const Eigen::Matrix<double, 6, 1>& xi, const Eigen::Isometry3d& T) {
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  delta.linear() = so3_exp(xi.head<3>());
  delta.translation() = xi.tail<3>();
  return delta * T;
}

Eigen::Isometry3d interpolate(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                              double alpha) {
  const Eigen::Quaterniond qa(a.linear()), qb(b.linear());
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = qa.slerp(alpha, qb).normalized().toRotationMatrix();
  out.translation() = (1 - alpha) * a.translation() + alpha * b.translation();
  return out;
}

}  // namespace scfloam
