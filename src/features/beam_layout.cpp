#include "scfloam/features/beam_layout.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "scfloam/error.hpp"

namespace scfloam {

namespace {
constexpr double kBinDeg = 0.01;
constexpr int kMinSeparationBins = 8;  // 0.08 deg: finer than any spinning sensor's spacing
}  // namespace

BeamLayout learn_beam_layout(const std::vector<LidarPoint>& points, double min_range_m,
                             double max_range_m) {
  BeamLayout layout;
  std::vector<double> elevation;
  elevation.reserve(points.size());
  double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
  for (const LidarPoint& p : points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const double h = std::hypot(static_cast<double>(p.x), static_cast<double>(p.y));
    if (h <= 0 || h < min_range_m || h > max_range_m) continue;
    const double a = std::atan2(static_cast<double>(p.z), h) * 180.0 / M_PI;
    elevation.push_back(a);
    lo = std::min(lo, a);
    hi = std::max(hi, a);
  }
  layout.points_used = static_cast<int>(elevation.size());
  if (layout.points_used < kMinLayoutPoints) return layout;

  // Histogram with three empty bins of margin either side, smoothed by a 5-bin triangle.
  lo -= 3 * kBinDeg;
  const int bins = static_cast<int>(std::ceil((hi - lo) / kBinDeg)) + 4;
  std::vector<double> count(static_cast<std::size_t>(bins), 0.0), smooth(count.size(), 0.0);
  for (double a : elevation)
    count[static_cast<std::size_t>(std::clamp(static_cast<int>((a - lo) / kBinDeg), 0, bins - 1))] += 1;
  for (int i = 2; i + 2 < bins; ++i)
    smooth[i] = (count[i - 2] + 2 * count[i - 1] + 3 * count[i] + 2 * count[i + 1] + count[i + 2]) / 9.0;

  // Local maxima, strongest first, none within kMinSeparationBins of a stronger one.
  std::vector<int> candidates;
  for (int i = 1; i + 1 < bins; ++i)
    if (smooth[i] > 0 && smooth[i] > smooth[i - 1] && smooth[i] >= smooth[i + 1]) candidates.push_back(i);
  std::sort(candidates.begin(), candidates.end(),
            [&](int a, int b) { return smooth[a] > smooth[b] || (smooth[a] == smooth[b] && a < b); });
  std::vector<int> peaks;
  for (int c : candidates) {
    bool near = false;
    for (int p : peaks) near = near || std::abs(p - c) < kMinSeparationBins;
    if (!near) peaks.push_back(c);
  }
  std::sort(peaks.begin(), peaks.end());
  // Drop specks: a peak with < 1 % of the median peak's returns (within +-4 bins).
  const auto mass = [&](int i) {
    double m = 0;
    for (int k = std::max(0, i - 4); k <= std::min(bins - 1, i + 4); ++k) m += count[k];
    return m;
  };
  std::vector<double> masses;
  for (int p : peaks) masses.push_back(mass(p));
  if (masses.empty()) return layout;
  std::vector<double> sorted = masses;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double min_mass = std::max(3.0, 0.01 * sorted[sorted.size() / 2]);
  std::vector<int> beams;
  for (std::size_t k = 0; k < peaks.size(); ++k)
    if (masses[k] >= min_mass) beams.push_back(peaks[k]);

  // Each bin belongs to its nearest beam; it is "clustered" within a quarter of the gap from
  // its beam to the nearer neighbour beam.
  const int B = static_cast<int>(beams.size());
  std::vector<double> centre_sum(B, 0.0), centre_weight(B, 0.0);
  std::vector<int> returns(B, 0);
  double clustered = 0;
  int j = 0;
  for (int i = 0; i < bins; ++i) {
    if (count[i] == 0) continue;
    while (j + 1 < B && std::abs(beams[j + 1] - i) < std::abs(beams[j] - i)) ++j;
    int gap = std::numeric_limits<int>::max();
    if (j > 0) gap = std::min(gap, beams[j] - beams[j - 1]);
    if (j + 1 < B) gap = std::min(gap, beams[j + 1] - beams[j]);
    returns[j] += static_cast<int>(count[i]);
    if (4 * std::abs(i - beams[j]) <= gap) {
      clustered += count[i];
      centre_sum[j] += count[i] * (lo + (i + 0.5) * kBinDeg);
      centre_weight[j] += count[i];
    }
  }
  layout.clustered_fraction = clustered / layout.points_used;
  // Highest first; each centre is the mean of its clustered returns' bins.
  for (int k = B - 1; k >= 0; --k) {
    layout.elevations_deg.push_back(centre_weight[k] > 0 ? centre_sum[k] / centre_weight[k]
                                                         : lo + (beams[k] + 0.5) * kBinDeg);
    layout.returns.push_back(returns[k]);
  }
  layout.confident = B >= 2 && B <= kMaxLearnedBeams && layout.clustered_fraction >= 0.9;
  return layout;
}

LearnedRingTable::LearnedRingTable(const std::vector<double>& elevations_deg)
    : beams_(static_cast<int>(elevations_deg.size())) {
  if (beams_ < 1 || beams_ > kMaxLearnedBeams)
    throw Error("learned ring table: " + std::to_string(beams_) + " beams (expected 1.." +
                std::to_string(kMaxLearnedBeams) + ")");
  std::vector<double> up(elevations_deg.rbegin(), elevations_deg.rend());  // lowest first
  for (int k = 1; k < beams_; ++k)
    if (!(up[k] > up[k - 1])) throw Error("learned ring table: beam elevations must strictly decrease");
  const double first_gap = beams_ > 1 ? up[1] - up[0] : 1.0;
  const double last_gap = beams_ > 1 ? up[beams_ - 1] - up[beams_ - 2] : 1.0;
  const double lowest = up[0] - 0.5 * first_gap, highest = up[beams_ - 1] + 0.5 * last_gap;
  lowest_deg_ = static_cast<float>(lowest);
  lut_.resize(static_cast<std::size_t>(std::ceil((highest - lowest) * kBinsPerDeg)));
  int below = 0;  // beams whose upper boundary lies below the current bin
  for (std::size_t i = 0; i < lut_.size(); ++i) {
    const double e = lowest + (static_cast<double>(i) + 0.5) / kBinsPerDeg;
    while (below + 1 < beams_ && e > 0.5 * (up[below] + up[below + 1])) ++below;
    lut_[i] = static_cast<std::int16_t>(beams_ - 1 - below);
  }
}

TableFit check_table_fit(LidarModel model, const BeamLayout& layout) {
  TableFit fit;
  std::map<int, int> beams_per_ring;
  long dropped_returns = 0, total = 0;
  for (std::size_t k = 0; k < layout.elevations_deg.size(); ++k) {
    total += layout.returns[k];
    const int ring = ring_from_elevation_deg(model, layout.elevations_deg[k]);
    if (ring < 0) {
      ++fit.dropped_beams;
      dropped_returns += layout.returns[k];
    } else {
      ++beams_per_ring[ring];
    }
  }
  for (const auto& [ring, n] : beams_per_ring)
    if (n > 1) fit.merged_beams += n;
  fit.dropped_fraction = total > 0 ? static_cast<double>(dropped_returns) / static_cast<double>(total) : 0;
  fit.fits = fit.merged_beams == 0;
  return fit;
}

}  // namespace scfloam
