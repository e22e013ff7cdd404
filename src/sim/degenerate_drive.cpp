// Driving a lane with a given arclength over time (stops and periodic laps, which the
// curvature-limited drive_path cannot do), and the beam-loss fault.
#include <algorithm>
#include <cmath>

#include "scfloam/error.hpp"
#include "scfloam/sim/degenerate.hpp"

namespace scfloam::sim {
using Vec2 = Eigen::Vector2d;

namespace {
// Arclength table over a polyline; closed lanes wrap around.
class LaneTable {
 public:
  LaneTable(const std::vector<Vec2>& lane, bool closed) : pts_(lane), closed_(closed) {
    if (pts_.size() < 2) throw Error("a lane needs at least two points");
    if (closed_ && (pts_.back() - pts_.front()).norm() > 1e-9) pts_.push_back(pts_.front());
    s_.assign(pts_.size(), 0);
    for (std::size_t i = 1; i < pts_.size(); ++i) s_[i] = s_[i - 1] + (pts_[i] - pts_[i - 1]).norm();
  }
  double length() const { return s_.back(); }
  Vec2 at(double s) const {
    if (closed_) s -= std::floor(s / length()) * length();
    // Open lanes extrapolate along their end segments (tangents at the ends stay defined).
    const auto it = std::upper_bound(s_.begin(), s_.end(), s);
    const std::size_t i = std::clamp<std::size_t>(it - s_.begin(), 1, s_.size() - 1);
    const double a = (s - s_[i - 1]) / std::max(s_[i] - s_[i - 1], 1e-12);
    return pts_[i - 1] + a * (pts_[i] - pts_[i - 1]);
  }

 private:
  std::vector<Vec2> pts_;
  std::vector<double> s_;
  bool closed_;
};
}  // namespace

double ease(double t, double t0, double t1, double v0, double v1) {
  if (t <= t0) return v0;
  if (t >= t1) return v1;
  return v0 + (v1 - v0) * 0.5 * (1 - std::cos(M_PI * (t - t0) / (t1 - t0)));
}

std::vector<double> integrate_speed(const std::function<double(double)>& speed_mps, double duration_s,
                                    double dt_s) {
  const std::size_t n = static_cast<std::size_t>(std::ceil(duration_s / dt_s)) + 1;
  std::vector<double> s(n, 0.0);
  for (std::size_t k = 1; k < n; ++k) s[k] = s[k - 1] + std::max(0.0, speed_mps((k - 0.5) * dt_s)) * dt_s;
  return s;
}

SampledTrajectory drive_arclength(const std::vector<Vec2>& lane, bool closed, const std::vector<double>& s_m,
                                  double dt_s, const std::function<double(double, double)>& ground_height,
                                  double mount_height_m) {
  const LaneTable table(lane, closed);
  auto tangent = [&](double s) { return Vec2((table.at(s + 1.0) - table.at(s - 1.0)).normalized()); };
  SampledTrajectory traj;
  traj.dt_s = dt_s;
  const std::size_t n = s_m.size();
  traj.T_world_lidar.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double s = s_m[k];
    const std::size_t a = k > 0 ? k - 1 : 0, b = std::min(k + 1, n - 1);
    const double speed = b > a ? (s_m[b] - s_m[a]) / ((b - a) * dt_s) : 0.0;
    const double accel = (k > 0 && k + 1 < n) ? (s_m[b] - 2 * s + s_m[a]) / (dt_s * dt_s) : 0.0;
    const Vec2 p = table.at(s), t = tangent(s);
    const Vec2 ta = tangent(s - 2.0), tb = tangent(s + 2.0);
    const double curvature = std::atan2(ta.x() * tb.y() - ta.y() * tb.x(), ta.dot(tb)) / 4.0;
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
    // Same suspension model as drive_path: squat/dive with acceleration, roll in turns.
    const double pitch_up = 0.0035 * accel;
    const double roll_left_up = 0.005 * speed * speed * curvature;
    R = R * Eigen::AngleAxisd(-pitch_up, Eigen::Vector3d::UnitY()).toRotationMatrix() *
        Eigen::AngleAxisd(roll_left_up, Eigen::Vector3d::UnitX()).toRotationMatrix();
    Pose T = Pose::Identity();
    T.linear() = R;
    T.translation() = Eigen::Vector3d(p.x(), p.y(), g) + normal * mount_height_m;
    traj.T_world_lidar.push_back(T);
  }
  return traj;
}

void apply_beam_losses(const Scenario& scenario, std::size_t frame, int beams, Scan* scan) {
  for (const BeamLoss& loss : scenario.beam_losses) {
    if (frame < loss.first_frame || frame >= loss.end_frame) continue;
    const int every = std::max(1, loss.keep_every);
    const int first_kept_ring = static_cast<int>(std::lround(loss.upper_share_lost * beams));
    auto& pts = scan->points;
    pts.erase(std::remove_if(pts.begin(), pts.end(),
                             [&](const LidarPoint& p) {
                               return p.ring < first_kept_ring || (p.ring % every) != 0;
                             }),
              pts.end());
  }
}

}  // namespace scfloam::sim
