#include "scfloam/eval/alignment.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "scfloam/error.hpp"

namespace scfloam {

Pose umeyama_se3(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst) {
  if (src.empty() || src.size() != dst.size())
    throw Error("alignment: need the same non-zero number of points in both trajectories (got " +
                std::to_string(src.size()) + " and " + std::to_string(dst.size()) + ")");
  const auto n = static_cast<Eigen::Index>(src.size());
  Eigen::Matrix3Xd S(3, n), D(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    S.col(i) = src[i];
    D.col(i) = dst[i];
  }
  Pose T = Pose::Identity();
  if (n < 3) {
    T.translation() = D.rowwise().mean() - S.rowwise().mean();
    return T;
  }
  T.matrix() = Eigen::umeyama(S, D, /*with_scaling=*/false);
  return T;
}

AteResult absolute_trajectory_error(const PoseList& gt, const PoseList& est) {
  if (gt.size() != est.size() || gt.empty())
    throw Error("ATE: ground truth has " + std::to_string(gt.size()) + " poses, the estimate " +
                std::to_string(est.size()) + " (they must be associated one to one)");
  std::vector<Eigen::Vector3d> p_est(est.size()), p_gt(gt.size());
  for (std::size_t i = 0; i < gt.size(); ++i) {
    p_est[i] = est[i].translation();
    p_gt[i] = gt[i].translation();
  }
  AteResult r;
  r.T_gt_est = umeyama_se3(p_est, p_gt);
  r.aligned_est.resize(est.size());
  r.errors_m.resize(est.size());
  double sum = 0, sum_sq = 0;
  for (std::size_t i = 0; i < est.size(); ++i) {
    r.aligned_est[i] = r.T_gt_est * est[i];
    const double e = (p_gt[i] - r.aligned_est[i].translation()).norm();
    r.errors_m[i] = e;
    sum += e;
    sum_sq += e * e;
    r.max_m = std::max(r.max_m, e);
  }
  const double n = static_cast<double>(est.size());
  r.rmse_m = std::sqrt(sum_sq / n);
  r.mean_m = sum / n;
  std::vector<double> sorted = r.errors_m;
  const std::size_t mid = sorted.size() / 2;
  std::nth_element(sorted.begin(), sorted.begin() + mid, sorted.end());
  r.median_m = sorted[mid];
  if (sorted.size() % 2 == 0)
    r.median_m = 0.5 * (r.median_m + *std::max_element(sorted.begin(), sorted.begin() + mid));
  return r;
}

double ate_rmse_m(const PoseList& gt, const PoseList& est) {
  return absolute_trajectory_error(gt, est).rmse_m;
}

}  // namespace scfloam
