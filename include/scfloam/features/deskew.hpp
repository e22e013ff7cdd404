// Motion compensation of one scan under constant velocity.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "scfloam/types.hpp"

namespace scfloam {

// Moves every point into the sensor frame at the reference time (time_s = reference_s;
// the stamp by default), given the sensor's body-frame angular velocity (rad/s) and linear
// velocity (m/s) there: with t = time_s - reference_s, p0 = exp(omega * t) p + v * t.
// Second-order rotation (error ~ |omega t|^3 / 6 * range: under 1 mm at 1 rad/s, 0.1 s, 50 m).
void deskew_constant_velocity(std::vector<LidarPoint>& points, const Eigen::Vector3d& omega_rad_s,
                              const Eigen::Vector3d& velocity_m_s, double reference_s = 0);

}  // namespace scfloam
