#include "scfloam/odometry/elevation_calibration.hpp"

#include <algorithm>
#include <cmath>

namespace scfloam {

ElevationStep elevation_step(const std::vector<PlaneMatch>& matches,
                             const Eigen::Isometry3d& T_world_lidar, double huber_m) {
  Eigen::Matrix<double, 7, 7> H = Eigen::Matrix<double, 7, 7>::Zero();
  Eigen::Matrix<double, 7, 1> g = Eigen::Matrix<double, 7, 1>::Zero();
  const Eigen::Matrix3d R = T_world_lidar.linear();
  const Eigen::Vector3d t = T_world_lidar.translation();
  for (const PlaneMatch& m : matches) {
    const Eigen::Vector3d& p = m.point_lidar;
    const double h = std::hypot(p.x(), p.y());
    if (h < 1e-3) continue;  // on the axis: the correction leaves it alone
    Jacobian16 J_pose;
    const double r = plane_residual(m, R, t, &J_pose);
    // The correction raises a point's elevation about the sensor's z axis; its derivative at
    // zero angle moves the point along the local "up" of its beam.
    const Eigen::Vector3d dp_dangle(-p.x() * p.z() / h, -p.y() * p.z() / h, h);
    Eigen::Matrix<double, 1, 7> J;
    J << J_pose, m.normal.dot(R * dp_dangle);
    const double w = std::abs(r) <= huber_m ? 1.0 : huber_m / std::abs(r);
    H.noalias() += w * J.transpose() * J;
    g.noalias() += w * J.transpose() * r;
  }
  ElevationStep out;
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> pose(H.topLeftCorner<6, 6>());
  if (pose.info() != Eigen::Success || !(H(6, 6) > 0)) return out;
  const Eigen::Matrix<double, 6, 1> coupling = H.block<6, 1>(0, 6);
  const double information = H(6, 6) - coupling.dot(pose.solve(coupling));
  // Below 1e-6 of its raw information the angle is a pose change in disguise.
  if (!(information > 1e-6 * H(6, 6))) return out;
  out.information = information;
  out.step_rad = -(g(6) - coupling.dot(pose.solve(g.head<6>()))) / information;
  return out;
}

ElevationCalibration::ElevationCalibration(double initial_deg, double gain, double max_change_deg)
    : initial_deg_(initial_deg), gain_(gain), max_change_deg_(max_change_deg),
      correction_deg_(initial_deg) {}

double ElevationCalibration::update(const std::vector<PlaneMatch>& matches,
                                    const Eigen::Isometry3d& T_world_lidar) {
  const ElevationStep step = elevation_step(matches, T_world_lidar, 0.1);
  if (step.information > 0) {
    // At most 0.05 deg per frame: a bad frame (a wrong match, a ramp) moves it little.
    const double change_deg = std::clamp(gain_ * step.step_rad * 180.0 / M_PI, -0.05, 0.05);
    correction_deg_ = std::clamp(correction_deg_ + change_deg, initial_deg_ - max_change_deg_,
                                 initial_deg_ + max_change_deg_);
  }
  return correction_deg_;
}

}  // namespace scfloam
