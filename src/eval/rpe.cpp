#include "scfloam/eval/rpe.hpp"

#include <cmath>

#include "scfloam/error.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {

RpeResult relative_pose_error(const PoseList& gt, const PoseList& est) {
  if (gt.size() != est.size())
    throw Error("RPE: ground truth has " + std::to_string(gt.size()) + " poses, the estimate " +
                std::to_string(est.size()) + " (they must be associated one to one)");
  RpeResult r;
  if (gt.size() < 2) return r;
  const std::size_t n = gt.size() - 1;
  r.trans_m.resize(n);
  r.rot_deg.resize(n);
  double t_sum = 0, t_sq = 0, r_sum = 0, r_sq = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const Pose E = (gt[k].inverse() * gt[k + 1]).inverse() * (est[k].inverse() * est[k + 1]);
    const double t = E.translation().norm();
    const double a = rotation_angle_rad(E.linear()) * 180.0 / M_PI;
    r.trans_m[k] = t;
    r.rot_deg[k] = a;
    t_sum += t;
    t_sq += t * t;
    r_sum += a;
    r_sq += a * a;
  }
  const double dn = static_cast<double>(n);
  r.trans_mean_m = t_sum / dn;
  r.trans_rmse_m = std::sqrt(t_sq / dn);
  r.rot_mean_deg = r_sum / dn;
  r.rot_rmse_deg = std::sqrt(r_sq / dn);
  return r;
}

}  // namespace scfloam
