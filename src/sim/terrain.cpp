// Ground height fields: rolling terrain for the grid city, and a smooth surface through a
// replayed trajectory's ground points.
#include <algorithm>
#include <cmath>

#include "scfloam/sim/city.hpp"
#include "scfloam/sim/rng.hpp"

namespace scfloam::sim {
namespace {
constexpr double kTerrainCell = 4.0;
Raster2D empty_raster(const WorldBounds& b) {
  Raster2D r;
  const int nx = static_cast<int>(std::ceil((b.xmax - b.xmin) / kTerrainCell)) + 2;
  const int ny = static_cast<int>(std::ceil((b.ymax - b.ymin) / kTerrainCell)) + 2;
  r.reset(b.xmin - kTerrainCell, b.ymin - kTerrainCell, kTerrainCell, nx, ny, 0.0f);
  return r;
}
}  // namespace

WorldBounds bounds_of(const std::vector<Street>& streets, double margin_m) {
  WorldBounds b{1e18, 1e18, -1e18, -1e18};
  for (const auto& s : streets)
    for (const auto& p : s.centerline) {
      b.xmin = std::min(b.xmin, p.x());
      b.ymin = std::min(b.ymin, p.y());
      b.xmax = std::max(b.xmax, p.x());
      b.ymax = std::max(b.ymax, p.y());
    }
  b.xmin -= margin_m;
  b.ymin -= margin_m;
  b.xmax += margin_m;
  b.ymax += margin_m;
  return b;
}

Raster2D make_rolling_terrain(const WorldBounds& bounds, std::uint64_t seed, double max_slope) {
  Raster2D r = empty_raster(bounds);
  Rng rng(hash_combine(seed, 0x7E88A1ULL));
  struct Wave { double kx, ky, phase, amp; };
  std::vector<Wave> waves;
  const int count = 3;
  for (int i = 0; i < count; ++i) {
    const double wavelength = rng.uniform(250, 700), dir = rng.uniform(0, 2 * M_PI);
    const double k = 2 * M_PI / wavelength;
    // Each wave's steepest slope is amp * k; together they stay within max_slope.
    const double amp = rng.uniform(0.5, 1.0) * max_slope / count / k;
    waves.push_back({k * std::cos(dir), k * std::sin(dir), rng.uniform(0, 2 * M_PI), amp});
  }
  for (int iy = 0; iy < r.ny; ++iy)
    for (int ix = 0; ix < r.nx; ++ix) {
      const double x = r.x0 + ix * r.cell_m, y = r.y0 + iy * r.cell_m;
      double h = 0;
      for (const auto& w : waves) h += w.amp * std::sin(w.kx * x + w.ky * y + w.phase);
      r.at(ix, iy) = static_cast<float>(h);
    }
  return r;
}

Raster2D fit_terrain(const WorldBounds& bounds, const std::vector<Eigen::Vector3d>& ground_points,
                     double max_slope) {
  Raster2D r = empty_raster(bounds);
  // Gaussian-weighted average of nearby path heights; far from the path it fades to the mean.
  const double sigma = 15.0, radius = 3 * sigma;
  double mean = 0;
  for (const auto& p : ground_points) mean += p.z();
  if (!ground_points.empty()) mean /= ground_points.size();
  std::vector<double> wsum(r.values.size(), 1e-3), hsum(r.values.size(), 1e-3 * mean);
  for (const auto& p : ground_points) {
    const int ix0 = std::max(0, static_cast<int>((p.x() - radius - r.x0) / r.cell_m));
    const int ix1 = std::min(r.nx - 1, static_cast<int>((p.x() + radius - r.x0) / r.cell_m) + 1);
    const int iy0 = std::max(0, static_cast<int>((p.y() - radius - r.y0) / r.cell_m));
    const int iy1 = std::min(r.ny - 1, static_cast<int>((p.y() + radius - r.y0) / r.cell_m) + 1);
    for (int iy = iy0; iy <= iy1; ++iy)
      for (int ix = ix0; ix <= ix1; ++ix) {
        const double dx = r.x0 + ix * r.cell_m - p.x(), dy = r.y0 + iy * r.cell_m - p.y();
        const double w = std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma));
        const std::size_t i = static_cast<std::size_t>(iy) * r.nx + ix;
        wsum[i] += w;
        hsum[i] += w * p.z();
      }
  }
  for (std::size_t i = 0; i < r.values.size(); ++i) r.values[i] = static_cast<float>(hsum[i] / wsum[i]);
  // Where a trajectory passes the same place twice at different heights (ground-truth drift)
  // no single ground fits both: relax such spots until no slope exceeds max_slope.
  const double max_step = max_slope * r.cell_m;
  for (int iter = 0; iter < 200; ++iter) {
    bool changed = false;
    for (int iy = 0; iy < r.ny; ++iy)
      for (int ix = 0; ix < r.nx; ++ix)
        for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
          if (ix + dx >= r.nx || iy + dy >= r.ny) continue;
          float& a = r.at(ix, iy);
          float& b = r.at(ix + dx, iy + dy);
          const double excess = std::abs(a - b) - max_step;
          if (excess <= 1e-4) continue;
          const float shift = static_cast<float>(0.5 * excess) * (a > b ? 1.0f : -1.0f);
          a -= shift;
          b += shift;
          changed = true;
        }
    if (!changed) break;
  }
  return r;
}

}  // namespace scfloam::sim
