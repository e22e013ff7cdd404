// Smooth, physically plausible driving along a planned 2D path.
#include "scfloam/sim/route.hpp"

#include <algorithm>
#include <cmath>

#include "scfloam/se3.hpp"
#include "scfloam/sim/rng.hpp"

namespace scfloam::sim {
using Vec2 = Eigen::Vector2d;

Pose SampledTrajectory::at(double t_s) const {
  if (T_world_lidar.empty()) return Pose::Identity();
  if (T_world_lidar.size() == 1) return T_world_lidar.front();
  const double f = t_s / dt_s;
  // Beyond the ends, extrapolate with the first/last interval (motion distortion needs it).
  const std::size_t last = T_world_lidar.size() - 1;
  const std::size_t i = static_cast<std::size_t>(std::clamp(std::floor(f), 0.0, static_cast<double>(last - 1)));
  const double alpha = f - static_cast<double>(i);
  const Pose& a = T_world_lidar[i];
  const Pose& b = T_world_lidar[i + 1];
  if (alpha >= 0 && alpha <= 1) {
    if (!smooth) return interpolate(a, b, alpha);
    // At a sample, the sample itself (frame times reach here as f = k -+ 1e-15).
    if (alpha < 1e-9) return a;
    if (alpha > 1 - 1e-9) return b;
    // The four samples around, as rotation vectors and translations in a's frame (at the
    // ends the missing neighbour mirrors the other: a constant velocity there).
    const auto rel = [&](const Pose& T) {
      const Pose d = a.inverse() * T;
      Eigen::Matrix<double, 6, 1> xi;
      xi << so3_log(d.linear()), d.translation();
      return xi;
    };
    const Eigen::Matrix<double, 6, 1> p1 = rel(b);
    const Eigen::Matrix<double, 6, 1> p_1 = i > 0 ? rel(T_world_lidar[i - 1]) : Eigen::Matrix<double, 6, 1>(-p1);
    const Eigen::Matrix<double, 6, 1> p2 = i + 2 <= last ? rel(T_world_lidar[i + 2]) : Eigen::Matrix<double, 6, 1>(2 * p1);
    // Catmull-Rom through p0 = 0 and p1, tangents (p1 - p_1) / 2 and (p2 - 0) / 2.
    const double a2 = alpha * alpha, a3 = a2 * alpha;
    const Eigen::Matrix<double, 6, 1> xi =
        0.5 * ((-a3 + 2 * a2 - alpha) * p_1 + (-3 * a3 + 4 * a2 + alpha) * p1 + (a3 - a2) * p2);
    Pose step = Pose::Identity();
    step.linear() = so3_exp(xi.head<3>());
    step.translation() = xi.tail<3>();
    return a * step;
  }
  // Extrapolate: apply the relative motion of the interval |alpha| times (small angles).
  const Pose delta = a.inverse() * b;
  Eigen::Matrix<double, 6, 1> xi;
  xi.head<3>() = so3_log(delta.linear()) * alpha;
  xi.tail<3>() = delta.translation() * alpha;
  Pose step = Pose::Identity();
  step.linear() = so3_exp(xi.head<3>());
  step.translation() = xi.tail<3>();
  return a * step;
}

std::vector<Vec2> smooth_path(const std::vector<Vec2>& path, double step_m, double sigma_m) {
  std::vector<Vec2> dense;
  if (path.empty()) return dense;
  dense.push_back(path.front());
  double carry = 0;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Vec2 a = path[i - 1], b = path[i];
    const double len = (b - a).norm();
    double s = step_m - carry;
    for (; s <= len; s += step_m) dense.push_back(a + (b - a) * (s / len));
    carry = len - (s - step_m);
  }
  if ((dense.back() - path.back()).norm() > 1e-6) dense.push_back(path.back());
  const int half = static_cast<int>(std::ceil(3 * sigma_m / step_m));
  std::vector<double> kernel(2 * half + 1);
  for (int k = -half; k <= half; ++k) kernel[k + half] = std::exp(-0.5 * std::pow(k * step_m / sigma_m, 2));
  std::vector<Vec2> out(dense.size());
  const int n = static_cast<int>(dense.size());
  for (int i = 0; i < n; ++i) {
    Vec2 acc = Vec2::Zero();
    double wsum = 0;
    for (int k = -half; k <= half; ++k) {
      const int j = std::clamp(i + k, 0, n - 1);
      acc += kernel[k + half] * dense[j];
      wsum += kernel[k + half];
    }
    out[i] = acc / wsum;
  }
  return out;
}

std::vector<Vec2> offset_path(const std::vector<Vec2>& path, double right_m) {
  std::vector<Vec2> out(path.size());
  for (std::size_t i = 0; i < path.size(); ++i) {
    const Vec2 t = (path[std::min(i + 1, path.size() - 1)] - path[i > 0 ? i - 1 : 0]).normalized();
    out[i] = path[i] + Vec2(t.y(), -t.x()) * right_m;
  }
  return out;
}

namespace {
void gaussian_smooth(std::vector<double>& v, int half) {
  std::vector<double> out(v.size());
  const int n = static_cast<int>(v.size());
  for (int i = 0; i < n; ++i) {
    double acc = 0, wsum = 0;
    for (int k = -half; k <= half; ++k) {
      const double w = std::exp(-4.5 * k * k / (double(half) * half + 1e-9));
      acc += w * v[std::clamp(i + k, 0, n - 1)];
      wsum += w;
    }
    out[i] = acc / wsum;
  }
  v.swap(out);
}
}  // namespace

SampledTrajectory drive_path(const std::vector<Vec2>& path, double duration_s,
                             const std::function<double(double, double)>& ground_height,
                             const DriveLimits& limits, std::uint64_t seed, double dt_s) {
  constexpr double kStep = 0.5;
  const std::vector<Vec2> pts = smooth_path(path, kStep, 1.0);  // resample; geometry is already smooth
  const std::size_t n = pts.size();
  std::vector<double> s(n, 0), heading(n, 0), curvature(n, 0);
  for (std::size_t i = 1; i < n; ++i) s[i] = s[i - 1] + (pts[i] - pts[i - 1]).norm();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 d = pts[std::min(i + 1, n - 1)] - pts[i > 0 ? i - 1 : 0];
    heading[i] = std::atan2(d.y(), d.x());
  }
  for (std::size_t i = 1; i + 1 < n; ++i) {
    double dh = heading[i + 1] - heading[i - 1];
    dh = std::atan2(std::sin(dh), std::cos(dh));
    curvature[i] = dh / std::max(s[i + 1] - s[i - 1], 1e-6);
  }
  gaussian_smooth(curvature, 4);

  // Speed: a smooth random cruise speed, slowed in curves, with bounded acceleration.
  Rng rng(hash_combine(seed, 0xD41E5ULL));
  const double l1 = rng.uniform(250, 450), l2 = rng.uniform(80, 160);
  const double p1 = rng.uniform(0, 2 * M_PI), p2 = rng.uniform(0, 2 * M_PI);
  const double mid = 0.5 * (limits.min_speed_mps + limits.max_speed_mps);
  const double span = 0.5 * (limits.max_speed_mps - limits.min_speed_mps);
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) {
    double cruise = mid + span * (0.55 * std::sin(2 * M_PI * s[i] / l1 + p1) + 0.25 * std::sin(2 * M_PI * s[i] / l2 + p2));
    const double k = std::abs(curvature[i]);
    if (k > 1e-6) cruise = std::min(cruise, std::sqrt(limits.max_lateral_mps2 / k));
    v[i] = std::clamp(cruise, limits.min_speed_mps, limits.max_speed_mps);
  }
  const double a_max = limits.max_accel_mps2 * 0.8;  // margin for the smoothing below
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 1; i < n; ++i) v[i] = std::min(v[i], std::sqrt(v[i - 1] * v[i - 1] + 2 * a_max * (s[i] - s[i - 1])));
    for (std::size_t i = n - 1; i-- > 0;) v[i] = std::min(v[i], std::sqrt(v[i + 1] * v[i + 1] + 2 * a_max * (s[i + 1] - s[i])));
    gaussian_smooth(v, 20);  // +-10 m: limits jerk
    for (auto& x : v) x = std::clamp(x, limits.min_speed_mps, limits.max_speed_mps);
  }

  auto lerp = [&](const std::vector<double>& f, double at) {
    const auto it = std::upper_bound(s.begin(), s.end(), at);
    const std::size_t i = std::clamp<std::size_t>(it - s.begin(), 1, n - 1);
    const double a = std::clamp((at - s[i - 1]) / std::max(s[i] - s[i - 1], 1e-9), 0.0, 1.0);
    return f[i - 1] + a * (f[i] - f[i - 1]);
  };
  auto point = [&](double at) {
    const auto it = std::upper_bound(s.begin(), s.end(), at);
    const std::size_t i = std::clamp<std::size_t>(it - s.begin(), 1, n - 1);
    const double a = std::clamp((at - s[i - 1]) / std::max(s[i] - s[i - 1], 1e-9), 0.0, 1.0);
    return Vec2(pts[i - 1] + a * (pts[i] - pts[i - 1]));
  };
  // Small suspension motion from road roughness: a few sines of arc length.
  const double bump_l1 = rng.uniform(3, 6), bump_l2 = rng.uniform(7, 13);
  const double bump_p1 = rng.uniform(0, 2 * M_PI), bump_p2 = rng.uniform(0, 2 * M_PI);

  SampledTrajectory traj;
  traj.dt_s = dt_s;
  const std::size_t samples = static_cast<std::size_t>(std::ceil(duration_s / dt_s)) + 1;
  double pos = 0, prev_v = lerp(v, 0);
  for (std::size_t k = 0; k < samples && pos < s.back(); ++k) {
    const double speed = lerp(v, pos);
    const double accel = (speed - prev_v) / dt_s;
    prev_v = speed;
    const Vec2 p = point(pos);
    const Vec2 t = (point(pos + 1.0) - point(pos - 1.0)).normalized();
    const double g = ground_height(p.x(), p.y());
    const Vec2 ex = p + t, ey = p + Vec2(-t.y(), t.x());
    const Eigen::Vector3d forward(t.x(), t.y(), ground_height(ex.x(), ex.y()) - g);
    const Eigen::Vector3d left(-t.y(), t.x(), ground_height(ey.x(), ey.y()) - g);
    const Eigen::Vector3d normal = forward.cross(left).normalized();
    const Eigen::Vector3d x_axis = (forward - forward.dot(normal) * normal).normalized();
    Eigen::Matrix3d R;
    R.col(0) = x_axis;
    R.col(1) = normal.cross(x_axis);
    R.col(2) = normal;
    const double lateral = speed * speed * lerp(curvature, pos);
    const double bump = std::sin(2 * M_PI * pos / bump_l1 + bump_p1) + 0.7 * std::sin(2 * M_PI * pos / bump_l2 + bump_p2);
    const double pitch_up = 0.0035 * accel + 0.0008 * bump;  // squat when accelerating
    const double roll_left_up = 0.005 * lateral + 0.0005 * bump;
    R = R * Eigen::AngleAxisd(-pitch_up, Eigen::Vector3d::UnitY()).toRotationMatrix() *
        Eigen::AngleAxisd(roll_left_up, Eigen::Vector3d::UnitX()).toRotationMatrix();
    Pose T = Pose::Identity();
    T.linear() = R;
    T.translation() = Eigen::Vector3d(p.x(), p.y(), g) + normal * (limits.mount_height_m + 0.006 * bump);
    traj.T_world_lidar.push_back(T);
    pos += speed * dt_s;
  }
  return traj;
}

}  // namespace scfloam::sim
