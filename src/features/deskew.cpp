#include "scfloam/features/deskew.hpp"

namespace scfloam {

void deskew_constant_velocity(std::vector<LidarPoint>& points, const Eigen::Vector3d& omega_rad_s,
                              const Eigen::Vector3d& velocity_m_s, double reference_s) {
  const Eigen::Vector3f w = omega_rad_s.cast<float>(), v = velocity_m_s.cast<float>();
  const auto t_ref = static_cast<float>(reference_s);
  for (auto& pt : points) {
    const float t = pt.time_s - t_ref;
    const Eigen::Vector3f p(pt.x, pt.y, pt.z);
    const Eigen::Vector3f a = w * t;
    const Eigen::Vector3f ap = a.cross(p);
    const Eigen::Vector3f q = p + ap + 0.5f * a.cross(ap) + v * t;
    pt.x = q.x();
    pt.y = q.y();
    pt.z = q.z();
  }
}

}  // namespace scfloam
