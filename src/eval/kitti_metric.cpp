#include "scfloam/eval/kitti_metric.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <limits>

#include "scfloam/error.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRadToDeg = 180.0 / M_PI;

}  // namespace

std::vector<double> trajectory_distances_m(const PoseList& poses) {
  std::vector<double> dist(poses.size(), 0.0);
  for (std::size_t i = 1; i < poses.size(); ++i)
    dist[i] = dist[i - 1] + (poses[i].translation() - poses[i - 1].translation()).norm();
  return dist;
}

long last_frame_from_segment_length(const std::vector<double>& dist_m, std::size_t first_frame,
                                    double length_m) {
  if (first_frame >= dist_m.size()) return -1;
  const double target_m = dist_m[first_frame] + length_m;
  for (std::size_t i = first_frame; i < dist_m.size(); ++i)
    if (dist_m[i] > target_m) return static_cast<long>(i);
  return -1;
}

std::optional<Eigen::Vector3d> ground_truth_up(const PoseList& gt) {
  if (gt.size() < 3) return std::nullopt;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Pose& p : gt) mean += p.translation();
  mean /= static_cast<double>(gt.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Pose& p : gt) cov += (p.translation() - mean) * (p.translation() - mean).transpose();
  cov /= static_cast<double>(gt.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);  // ascending
  const Eigen::Vector3d spread = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  if (!(spread(1) >= 5.0) || !(spread(0) <= 0.25 * spread(1))) return std::nullopt;
  const Eigen::Vector3d normal = eig.eigenvectors().col(0);
  // The plane only says which of the vehicle's axes points up: the world's up is that axis
  // averaged over the drive (a hilly route tilts the plane of the positions by several
  // degrees; the vehicle's mean up does not tilt with it).
  Eigen::Matrix3d mean_axes = Eigen::Matrix3d::Zero();  // column k: vehicle axis k, averaged
  for (const Pose& p : gt) mean_axes += p.linear();
  mean_axes /= static_cast<double>(gt.size());
  Eigen::Index k = 0;
  (mean_axes.transpose() * normal).cwiseAbs().maxCoeff(&k);
  Eigen::Vector3d up = mean_axes.col(k);
  if (!(up.norm() > 0.5)) return std::nullopt;  // the axis turned over: no steady up
  up.normalize();
  // A drive that never turns (a straight road over a crest) spans a plane that is not the
  // ground's: its directions of travel, across the up found, must scatter (8 deg RMS or more).
  Eigen::Matrix3d directions = Eigen::Matrix3d::Zero();
  double travelled = 0;
  for (std::size_t i = 1; i < gt.size(); ++i) {
    Eigen::Vector3d step = gt[i].translation() - gt[i - 1].translation();
    step -= step.dot(up) * up;
    const double length = step.norm();
    if (!(length > 1e-6)) continue;
    directions += (step / length) * (step / length).transpose() * length;
    travelled += length;
  }
  if (!(travelled > 0)) return std::nullopt;
  const Eigen::Vector3d scatter = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(directions / travelled).eigenvalues();
  if (!(scatter(1) >= 0.02)) return std::nullopt;  // scatter(0) is along up, ~0
  return up;
}

KittiMetric kitti_metric(const PoseList& gt, const PoseList& est) {
  if (gt.empty()) throw Error("KITTI metric: the ground truth has no poses");
  if (gt.size() != est.size())
    throw Error("KITTI metric: ground truth has " + std::to_string(gt.size()) +
                " poses but the estimate has " + std::to_string(est.size()) +
                " (the metric needs a pose for every frame)");
  KittiMetric m;
  const std::vector<double> dist = trajectory_distances_m(gt);
  m.path_length_m = dist.back();

  std::array<double, kKittiSegmentLengthsM.size()> t_sum{}, r_sum{};
  double t_total = 0, r_total = 0, vertical_total = 0, horizontal_total = 0;
  const std::optional<Eigen::Vector3d> up = ground_truth_up(gt);
  for (std::size_t first = 0; first < gt.size(); first += kKittiStepFrames) {
    for (std::size_t li = 0; li < kKittiSegmentLengthsM.size(); ++li) {
      const double len = kKittiSegmentLengthsM[li];
      const long last = last_frame_from_segment_length(dist, first, len);
      if (last < 0) continue;
      const Pose delta_gt = gt[first].inverse() * gt[last];
      const Pose delta_est = est[first].inverse() * est[last];
      const Pose E = delta_est.inverse() * delta_gt;
      KittiSegmentError s;
      s.first_frame = first;
      s.last_frame = static_cast<std::size_t>(last);
      s.length_m = len;
      s.t_err_ratio = E.translation().norm() / len;
      s.r_err_rad_per_m = rotation_angle_rad(E.linear()) / len;
      if (up) {
        // t(E) = R(delta_est)^T d with d = t(delta_gt) - t(delta_est) in the first frame's
        // axes: the same vector (same norm) turned into the world's by the first pose.
        const Eigen::Vector3d error_world =
            gt[first].linear() * (delta_gt.translation() - delta_est.translation());
        const double vertical = error_world.dot(*up);
        s.vertical_ratio = std::abs(vertical) / len;
        s.horizontal_ratio = (error_world - vertical * *up).norm() / len;
        vertical_total += s.vertical_ratio;
        horizontal_total += s.horizontal_ratio;
      } else {
        s.vertical_ratio = s.horizontal_ratio = kNaN;
      }
      t_sum[li] += s.t_err_ratio;
      r_sum[li] += s.r_err_rad_per_m;
      t_total += s.t_err_ratio;
      r_total += s.r_err_rad_per_m;
      ++m.per_length[li].segments;
      m.segment_errors.push_back(s);
    }
  }

  m.segments = m.segment_errors.size();
  for (std::size_t li = 0; li < kKittiSegmentLengthsM.size(); ++li) {
    auto& pl = m.per_length[li];
    pl.length_m = kKittiSegmentLengthsM[li];
    const double n = static_cast<double>(pl.segments);
    pl.t_err_pct = pl.segments ? 100.0 * t_sum[li] / n : kNaN;
    pl.r_err_deg_per_100m = pl.segments ? 100.0 * kRadToDeg * r_sum[li] / n : kNaN;
  }
  if (m.segments > 0) {
    const double n = static_cast<double>(m.segments);
    m.t_err_pct = 100.0 * t_total / n;
    m.r_err_deg_per_100m = 100.0 * kRadToDeg * r_total / n;
    m.t_err_vertical_pct = up ? 100.0 * vertical_total / n : kNaN;
    m.t_err_horizontal_pct = up ? 100.0 * horizontal_total / n : kNaN;
  } else {
    m.t_err_vertical_pct = m.t_err_horizontal_pct = kNaN;
    m.t_err_pct = kNaN;
    m.r_err_deg_per_100m = kNaN;
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "no KITTI segments: the ground-truth path is %.1f m, shorter than the "
                  "shortest segment (100 m); t_err and r_err are undefined",
                  m.path_length_m);
    m.note = buf;
  }
  return m;
}

}  // namespace scfloam
