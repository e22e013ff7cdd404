#include "scfloam/features/sweep_times.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "scfloam/error.hpp"

namespace scfloam {

namespace {

constexpr double kTwoPi = 2 * M_PI;
// Two consecutive points are one beam's when their elevations (as tan, z / horizontal range)
// differ by less than 0.2 deg: under every preset's beam spacing (1/3 deg and up).
constexpr float kSameBeamTan = 0.0035f;
// A step of one beam counts for the direction when it is under 5 deg (a gap of no returns
// can be larger, and then says nothing about which way the head turns).
constexpr float kDirectionStepRad = static_cast<float>(5 * M_PI / 180);
// In firing order nearly every point lies within this azimuth of the one before (a column's
// lasers may differ by their azimuth offsets, a few degrees; gaps of no return are rare).
constexpr double kNearStepRad = 20 * M_PI / 180;
// Points within this angle of the seam are assigned to the start or the end of their
// revolution by where they are in it (the seam estimate is good to a degree or so).
constexpr double kSeamMarginRad = 5 * M_PI / 180;

double wrap_pi(double a) {  // to (-pi, pi]
  a = std::fmod(a, kTwoPi);
  if (a > M_PI) a -= kTwoPi;
  if (a <= -M_PI) a += kTwoPi;
  return a;
}

double wrap_two_pi(double a) {  // to [0, 2 pi)
  a = std::fmod(a, kTwoPi);
  return a < 0 ? a + kTwoPi : a;
}

struct PointAngles {
  std::vector<float> azimuth, elevation_tan;
  std::vector<std::size_t> index;  // of the points with a horizontal range (the rest: time 0)
};

PointAngles angles_of(const std::vector<LidarPoint>& points) {
  PointAngles a;
  a.azimuth.reserve(points.size());
  a.elevation_tan.reserve(points.size());
  a.index.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const LidarPoint& p = points[i];
    const float r = std::sqrt(p.x * p.x + p.y * p.y);
    if (!(r > 0.05f) || !std::isfinite(r) || !std::isfinite(p.z)) continue;  // no direction to read
    a.azimuth.push_back(fast_atan2(p.y, p.x));
    a.elevation_tan.push_back(p.z / r);
    a.index.push_back(i);
  }
  return a;
}

SweepLayout layout_of(const PointAngles& a) {
  SweepLayout layout;
  const std::size_t n = a.azimuth.size();
  if (n < 100) {
    layout.why = "fewer than 100 points with a horizontal range";
    return layout;
  }
  // The net turn of the whole order: one revolution column by column, one per beam beam by
  // beam; its sign is the direction. One beam's consecutive steps must agree with it.
  std::size_t forward = 0, backward = 0, changes = 0, near = 0;
  double net = 0;
  for (std::size_t i = 1; i < n; ++i) {
    const double step = wrap_pi(double(a.azimuth[i]) - a.azimuth[i - 1]);
    net += step;
    if (std::abs(step) < kNearStepRad) ++near;
    if (std::abs(a.elevation_tan[i] - a.elevation_tan[i - 1]) >= kSameBeamTan) {
      ++changes;
      continue;
    }
    if (step != 0 && std::abs(step) < kDirectionStepRad) (step > 0 ? forward : backward)++;
  }
  layout.clockwise = net < 0;
  const double revolutions = std::abs(net) / kTwoPi;
  layout.ring_major = double(changes) / double(n - 1) < 0.3;
  const std::size_t steps = forward + backward;
  layout.direction_agreement = steps > 0 ? double(layout.clockwise ? backward : forward) / double(steps) : 0.0;
  if (layout.ring_major && (steps < n / 4 || layout.direction_agreement < 0.8)) {
    layout.why = "one beam's consecutive points do not turn one way";
    return layout;
  }
  if (revolutions < 0.5) {
    layout.why = "the order does not run round the sensor";
    return layout;
  }
  if (double(near) < 0.7 * double(n - 1)) {
    layout.why = "consecutive points lie far apart in azimuth";
    return layout;
  }
  const double turn = layout.clockwise ? -1.0 : 1.0;  // sweep angle = turn * azimuth
  layout.seam_margin_rad = kSeamMarginRad;
  if (!layout.ring_major) {
    // Column by column: one revolution, starting with the first column. Its lasers may sit a
    // few degrees apart (per-laser azimuth offsets, about the column's own azimuth): the seam
    // is the middle of the first points' spread, less the turn they make (a column's share of
    // the sweep each), and the margin within which a point may belong to either end grows by
    // that spread.
    if (revolutions > 1.5) {
      layout.why = "the order runs through " + std::to_string(revolutions) + " revolutions, not one sweep";
      return layout;
    }
    const std::size_t first = std::min(n, std::max<std::size_t>(16, n / 200));
    double lowest = 0, highest = 0;
    for (std::size_t i = 1; i < first; ++i) {
      const double angle = turn * wrap_pi(double(a.azimuth[i]) - a.azimuth[0]);
      lowest = std::min(lowest, angle);
      highest = std::max(highest, angle);
    }
    const double advance = kTwoPi * double(first - 1) / double(n);
    layout.seam_rad = wrap_pi(a.azimuth[0] + turn * 0.5 * (lowest + highest - advance));
    layout.seam_margin_rad = kSeamMarginRad + (highest - lowest);
  } else {
    // Beam by beam: every beam's revolution starts at the seam, so the passes from one beam to
    // the next gather there (other elevation changes, e.g. over an object's edge with a
    // beam's vertical offset, scatter). Only passes between neighbouring azimuths count: a
    // beam that starts late (sky behind the sensor) or ends early would pull the estimate.
    // The seam: the densest 4-deg window of those passes.
    constexpr int kBins = 720;  // 0.5 deg
    constexpr double kAdjacentRad = 2 * M_PI / 180;
    std::vector<int> hist(kBins, 0);
    std::vector<double> mids;
    for (std::size_t i = 1; i < n; ++i) {
      if (std::abs(a.elevation_tan[i] - a.elevation_tan[i - 1]) < kSameBeamTan) continue;
      const double step = wrap_pi(double(a.azimuth[i]) - a.azimuth[i - 1]);
      if (std::abs(step) > kAdjacentRad) continue;
      const double mid = wrap_pi(a.azimuth[i - 1] + 0.5 * step);
      if (!std::isfinite(mid)) continue;
      mids.push_back(mid);
      hist[static_cast<int>(wrap_two_pi(mid) / kTwoPi * kBins) % kBins]++;
    }
    int best = 0, best_count = -1;
    for (int b = 0; b < kBins; ++b) {
      int count = 0;
      for (int d = -4; d <= 4; ++d) count += hist[(b + d + kBins) % kBins];
      if (count > best_count) best_count = count, best = b;
    }
    if (best_count < 4 || best_count < 0.25 * double(mids.size())) {
      layout.seam_unclear = true;
      layout.why = "the passes from one beam to the next do not meet at one azimuth";
      return layout;
    }
    const double centre = (best + 0.5) / kBins * kTwoPi;
    double s = 0, c = 0;
    for (double m : mids)
      if (std::abs(wrap_pi(m - centre)) <= 2.25 * M_PI / 180) s += std::sin(m), c += std::cos(m);
    layout.seam_rad = std::atan2(s, c);
  }
  layout.usable = true;
  return layout;
}

}  // namespace

SweepLayout sweep_layout(const std::vector<LidarPoint>& points) {
  return layout_of(angles_of(points));
}

double sweep_stamp_fraction(const std::string& stamp) {
  if (stamp == "start") return 0.0;
  if (stamp == "middle") return 0.5;
  if (stamp == "end") return 1.0;
  throw Error("sweep stamp must be start, middle or end, not '" + stamp + "'");
}

SweepLayout assign_times_from_azimuth(std::vector<LidarPoint>& points, double sweep_period_s, double stamp_fraction,
                                      const SweepLayout* earlier) {
  const PointAngles a = angles_of(points);
  SweepLayout layout = layout_of(a);
  if (!layout.usable && layout.seam_unclear && earlier && earlier->usable &&
      earlier->clockwise == layout.clockwise && earlier->ring_major == layout.ring_major) {
    layout.seam_rad = earlier->seam_rad;
    layout.seam_margin_rad = earlier->seam_margin_rad;
    layout.seam_from_earlier = layout.usable = true;
    layout.why.clear();
  }
  if (!layout.usable) return layout;
  layout.sweep_period_s = sweep_period_s;
  layout.stamp_fraction = stamp_fraction;
  const double turn = layout.clockwise ? -1.0 : 1.0;
  // Points with no direction to read (no horizontal range, not finite): the sweep's middle.
  const auto middle = static_cast<float>((0.5 - stamp_fraction) * sweep_period_s);
  for (auto& p : points) p.time_s = middle;
  // Walk the order through each revolution: the angle from the seam grows; near the seam
  // (within the seam estimate's margin) a point is the revolution's start until the walk has
  // passed half of it, its end after. Beam by beam, a pass to the next beam that falls back by
  // more than half a turn starts the next revolution.
  const double margin = layout.seam_margin_rad;
  bool late = false;
  double previous = 0;
  for (std::size_t i = 0; i < a.azimuth.size(); ++i) {
    const double raw = wrap_two_pi(turn * (double(a.azimuth[i]) - layout.seam_rad));
    const bool next_beam = i > 0 && std::abs(a.elevation_tan[i] - a.elevation_tan[i - 1]) >= kSameBeamTan;
    // (Read as a start, so that the seam estimate's error cannot hide the fall.)
    const double as_start = raw > kTwoPi - margin ? raw - kTwoPi : raw;
    if (layout.ring_major && next_beam && as_start < previous - M_PI) late = false;
    double angle = raw;
    if (!late && angle > kTwoPi - margin) angle -= kTwoPi;
    if (late && angle < margin) angle += kTwoPi;
    if (angle >= M_PI) late = true;
    previous = angle;
    points[a.index[i]].time_s = static_cast<float>((angle / kTwoPi - stamp_fraction) * sweep_period_s);
  }
  return layout;
}

}  // namespace scfloam
