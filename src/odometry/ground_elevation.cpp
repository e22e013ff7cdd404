#include "scfloam/odometry/ground_elevation.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

namespace scfloam {
namespace {

// The band: the road just ahead of and behind the sensor. Inside 5 m the car itself and the
// steepest beams; beyond 40 m the ground's returns are sparse and its bends large.
constexpr double kHalfWidthM = 3.0, kMinAlongM = 5.0, kMaxAlongM = 40.0;
constexpr int kBins = 80;              // 1 m bins along the band, -40 .. 40 m
constexpr int kMinPointsPerSide = 40;
constexpr double kMinSideSpanM = 10.0; // along the band, so range and offset are told apart
constexpr double kMaxSpreadM = 0.05;   // rougher ground (kerbs, rubble, a hill's bend) is skipped
constexpr double kMaxGrade = 0.1;      // 6 deg of pitch between sensor and road: not a road

// One sample of a surface fit z = a + b * along + c * across + slope * range.
struct GroundPoint {
  double along, across, range, z;
};

// Least squares of z on [1, along, across, range] over the kept points; false if singular.
// `H`, `b`: its normal equations.
bool fit(const std::vector<GroundPoint>& g, const std::vector<char>& keep, Eigen::Vector4d& c,
         Eigen::Matrix4d& H, Eigen::Vector4d& b) {
  H.setZero();
  b.setZero();
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (!keep[i]) continue;
    const Eigen::Vector4d a(1.0, g[i].along, g[i].across, g[i].range);
    H.noalias() += a * a.transpose();
    b.noalias() += a * g[i].z;
  }
  const Eigen::LDLT<Eigen::Matrix4d> ldlt(H);
  if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-12)) return false;
  c = ldlt.solve(b);
  return c.allFinite();
}

double residual(const GroundPoint& p, const Eigen::Vector4d& c) {
  return p.z - (c[0] + c[1] * p.along + c[2] * p.across + c[3] * p.range);
}

// Fits, then keeps the points within 3 robust sigmas (at least `floor_m`) of the fit, a few
// times; returns the robust sigma of the last fit (infinity if a fit failed).
double trimmed_fit(const std::vector<GroundPoint>& g, std::vector<char>& keep, Eigen::Vector4d& c,
                   double floor_m, int rounds) {
  std::vector<double> abs_res;
  double sigma = std::numeric_limits<double>::infinity();
  Eigen::Matrix4d H;
  Eigen::Vector4d b;
  for (int round = 0; round < rounds; ++round) {
    if (!fit(g, keep, c, H, b)) return std::numeric_limits<double>::infinity();
    abs_res.clear();
    for (std::size_t i = 0; i < g.size(); ++i)
      if (keep[i]) abs_res.push_back(std::abs(residual(g[i], c)));
    if (abs_res.empty()) return sigma;
    std::nth_element(abs_res.begin(), abs_res.begin() + abs_res.size() / 2, abs_res.end());
    sigma = 1.4826 * abs_res[abs_res.size() / 2];
    const double gate = std::max(3.0 * sigma, floor_m);
    for (std::size_t i = 0; i < g.size(); ++i) keep[i] = std::abs(residual(g[i], c)) < gate;
  }
  return sigma;
}

}  // namespace

GroundConeFit fit_ground_cone(const std::vector<LidarPoint>& points, const Eigen::Vector2d& direction) {
  GroundConeFit out;
  if (!(direction.norm() > 1e-9)) return out;
  const Eigen::Vector2d u = direction.normalized(), v(-u.y(), u.x());
  std::vector<GroundPoint> band;
  std::array<int, kBins> lowest;  // index into `band` of each bin's lowest return, -1: none
  lowest.fill(-1);
  for (const LidarPoint& p : points) {
    const double along = p.x * u.x() + p.y * u.y(), across = p.x * v.x() + p.y * v.y();
    if (!(std::abs(across) < kHalfWidthM) || !(std::abs(along) >= kMinAlongM) ||
        !(std::abs(along) < kMaxAlongM) || !std::isfinite(p.z))
      continue;
    int& low = lowest[static_cast<std::size_t>(std::floor(along + kMaxAlongM))];
    if (low < 0 || p.z < band[static_cast<std::size_t>(low)].z) low = static_cast<int>(band.size());
    band.push_back({along, across, std::hypot(static_cast<double>(p.x), static_cast<double>(p.y)), p.z});
  }
  // A first surface through the lowest return of each 1 m bin (cars, kerbs and walls stand on
  // the road, so the lowest return is the road where the road is seen at all), then every
  // point near that surface, trimmed to the road itself.
  std::vector<GroundPoint> seeds;
  for (const int i : lowest)
    if (i >= 0) seeds.push_back(band[static_cast<std::size_t>(i)]);
  if (seeds.size() < 10) return out;
  std::vector<char> keep(seeds.size(), 1);
  Eigen::Vector4d c;
  if (!std::isfinite(trimmed_fit(seeds, keep, c, 0.05, 4))) return out;
  keep.assign(band.size(), 0);
  for (std::size_t i = 0; i < band.size(); ++i) keep[i] = std::abs(residual(band[i], c)) < 0.15;
  const double sigma = trimmed_fit(band, keep, c, 0.03, 3);
  if (!std::isfinite(sigma)) return out;
  double min_ahead = kMaxAlongM, max_ahead = 0, min_behind = kMaxAlongM, max_behind = 0;
  for (std::size_t i = 0; i < band.size(); ++i) {
    if (!keep[i]) continue;
    const double along = band[i].along;
    if (along > 0) {
      ++out.ahead;
      min_ahead = std::min(min_ahead, along), max_ahead = std::max(max_ahead, along);
    } else {
      ++out.behind;
      min_behind = std::min(min_behind, -along), max_behind = std::max(max_behind, -along);
    }
  }
  out.slope_rad = c[3];
  out.spread_m = sigma;
  out.ok = out.ahead >= kMinPointsPerSide && out.behind >= kMinPointsPerSide &&
           max_ahead - min_ahead >= kMinSideSpanM && max_behind - min_behind >= kMinSideSpanM &&
           sigma <= kMaxSpreadM && std::abs(c[1]) <= kMaxGrade;
  if (out.ok) {
    out.road.reserve(static_cast<std::size_t>(out.ahead + out.behind));
    for (std::size_t i = 0; i < band.size(); ++i)
      if (keep[i]) {
        const Eigen::Vector2d xy = band[i].along * u + band[i].across * v;
        out.road.emplace_back(static_cast<float>(xy.x()), static_cast<float>(xy.y()), static_cast<float>(band[i].z));
      }
  }
  return out;
}

namespace {

// A spot of road seen by both scans: the later view's position in the earlier scan's frame,
// the height difference (later - earlier) and the difference of the ranges they saw it from.
struct SpotPair {
  double x, y, dz, range_difference;
};

}  // namespace

// A scan's road points on a 0.5 m grid, for the pairs' nearest-point search: built once per
// scan (each is the earlier scan of up to five pairs).
struct RoadGrid {
  static constexpr double kCellM = 0.5;
  static std::int64_t cell_of(double v) { return static_cast<std::int64_t>(std::floor(v / kCellM)); }
  // Both cells' low 32 bits side by side (unsigned: shifting a negative value is undefined).
  static std::uint64_t key(std::int64_t cx, std::int64_t cy) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(cx)) << 32) |
           static_cast<std::uint32_t>(cy);
  }
  explicit RoadGrid(std::vector<Eigen::Vector3f> road) : points(std::move(road)) {
    cells.reserve(points.size() / 2);
    for (std::size_t i = 0; i < points.size(); ++i)
      cells[key(cell_of(points[i].x()), cell_of(points[i].y()))].push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<Eigen::Vector3f> points;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells;
};

namespace {

std::vector<SpotPair> match_road(const RoadGrid& earlier, const std::vector<Eigen::Vector3f>& later,
                                 const Eigen::Isometry3d& T_earlier_later) {
  // For each later point the earlier point nearest to it, within 0.1 m: both see the same
  // spot of road, whatever its shape, and the nearest lies on either side alike, so the
  // road's slope between them averages out.
  constexpr double kNearM = 0.1;
  std::vector<SpotPair> pairs;
  for (const Eigen::Vector3f& p : later) {
    const Eigen::Vector3d q = T_earlier_later * p.cast<double>();
    const std::int64_t cx = RoadGrid::cell_of(q.x()), cy = RoadGrid::cell_of(q.y());
    double best = kNearM * kNearM;
    const Eigen::Vector3f* nearest = nullptr;
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const auto it = earlier.cells.find(RoadGrid::key(cx + dx, cy + dy));
        if (it == earlier.cells.end()) continue;
        for (const std::uint32_t i : it->second) {
          const double d2 = (earlier.points[i].head<2>().cast<double>() - q.head<2>()).squaredNorm();
          if (d2 < best) best = d2, nearest = &earlier.points[i];
        }
      }
    if (!nearest) continue;
    pairs.push_back({q.x(), q.y(), q.z() - nearest->z(),
                     std::hypot(p.x(), p.y()) - std::hypot(nearest->x(), nearest->y())});
  }
  return pairs;
}

}  // namespace

std::optional<GroundPairEquation> pair_equation(const RoadGrid& earlier,
                                                const std::vector<Eigen::Vector3f>& later,
                                                const Eigen::Isometry3d& T_earlier_later) {
  constexpr int kMinPerSide = 100;
  const std::vector<SpotPair> spots = match_road(earlier, later, T_earlier_later);
  if (spots.size() < 2 * kMinPerSide) return std::nullopt;
  // dz = a + b x + c y + k * range_difference, where k = -offset: a point seen from dr
  // further away appears dr * offset lower. a, b, c are the relative pose's error.
  std::vector<GroundPoint> rows;
  rows.reserve(spots.size());
  for (const SpotPair& s : spots) rows.push_back({s.x, s.y, s.range_difference, s.dz});
  std::vector<char> keep(rows.size(), 1);
  Eigen::Vector4d c;
  if (!std::isfinite(trimmed_fit(rows, keep, c, 0.03, 3))) return std::nullopt;
  // The step needs both signs of range difference (road ahead of both, behind both).
  int nearer = 0, farther = 0;
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (keep[i]) {
      nearer += rows[i].range < -1.0;
      farther += rows[i].range > 1.0;
    }
  if (nearer < kMinPerSide || farther < kMinPerSide) return std::nullopt;
  Eigen::Matrix4d H;
  Eigen::Vector4d b;
  if (!fit(rows, keep, c, H, b)) return std::nullopt;
  // The offset's own equation, with a, b, c eliminated (Schur complement).
  const Eigen::LDLT<Eigen::Matrix3d> nuisance(H.topLeftCorner<3, 3>());
  const Eigen::Vector3d cross = H.block<3, 1>(0, 3);
  GroundPairEquation e;
  e.information = H(3, 3) - cross.dot(nuisance.solve(cross));
  e.vector = -(b(3) - cross.dot(nuisance.solve(b.head<3>())));  // in terms of offset = -k
  if (!(e.information > 0) || !std::isfinite(e.vector)) return std::nullopt;
  return e;
}

std::optional<double> offset_between(const std::vector<Eigen::Vector3f>& earlier,
                                     const std::vector<Eigen::Vector3f>& later,
                                     const Eigen::Isometry3d& T_earlier_later) {
  const auto e = pair_equation(RoadGrid(earlier), later, T_earlier_later);
  if (!e) return std::nullopt;
  return e->offset_rad();
}

struct GroundElevationEstimate::Patch {
  Eigen::Isometry3d T_world_lidar;
  RoadGrid road;
};

GroundElevationEstimate::GroundElevationEstimate(double initial_deg, std::size_t min_pairs,
                                                 double max_change_deg)
    : initial_deg_(initial_deg),
      max_change_deg_(max_change_deg),
      min_pairs_(std::max<std::size_t>(min_pairs, 1)),
      correction_deg_(initial_deg) {}

double GroundElevationEstimate::update(const std::vector<LidarPoint>& points,
                                       const Eigen::Isometry3d& T_world_lidar,
                                       const Eigen::Vector3d& motion_lidar) {
  // Each scan is paired with one earlier scan, at 6, 12, 18, 24 or 30 m back in turn. Short
  // distances overlap most; long ones see the offset over a long baseline, where the beams'
  // own errors weigh less (docs/odometry.md, "Session 25"). Scans are kept every metre.
  constexpr double kPairDistancesM[] = {6.0, 12.0, 18.0, 24.0, 30.0};
  constexpr double kKeepEveryM = 1.0, kKeepWithinM = 36.0;
  const Eigen::Vector2d direction = motion_lidar.head<2>();
  if (!(direction.norm() >= 0.2)) return correction_deg_;
  GroundConeFit f = fit_ground_cone(points, direction);
  if (!f.ok) return correction_deg_;
  const Eigen::Vector3d position = T_world_lidar.translation();
  const auto distance = [&](const std::shared_ptr<const Patch>& p) {
    return (p->T_world_lidar.translation() - position).norm();
  };
  const double want = kPairDistancesM[next_distance_++ % std::size(kPairDistancesM)];
  for (auto it = recent_.rbegin(); it != recent_.rend(); ++it) {
    if (distance(*it) < want) continue;
    const auto e = pair_equation((*it)->road, f.road, (*it)->T_world_lidar.inverse() * T_world_lidar);
    // A pair far outside the allowed range is a mismatch (a wrong pose, a moving road), not
    // a measurement of the sensor.
    if (e && std::abs(e->offset_rad() * 180.0 / M_PI - initial_deg_) <= max_change_deg_) {
      information_ += e->information;
      vector_ += e->vector;
      ++pairs_;
    }
    break;
  }
  while (!recent_.empty() && distance(recent_.front()) > kKeepWithinM) recent_.erase(recent_.begin());
  if (recent_.empty() || distance(recent_.back()) >= kKeepEveryM)
    recent_.push_back(std::make_shared<const Patch>(Patch{T_world_lidar, RoadGrid(std::move(f.road))}));
  if (pairs_ < min_pairs_) return correction_deg_;
  correction_deg_ = std::clamp(vector_ / information_ * 180.0 / M_PI, initial_deg_ - max_change_deg_,
                               initial_deg_ + max_change_deg_);
  return correction_deg_;
}

}  // namespace scfloam
