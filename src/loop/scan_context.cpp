#include "scfloam/loop/scan_context.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "scfloam/error.hpp"

namespace scfloam {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

void check_config(const ScanContextConfig& c) {
  if (c.num_rings < 1 || c.num_sectors < 2 || !(c.max_radius_m > 0.0))
    throw Error("scan context: need num_rings >= 1, num_sectors >= 2 and max_radius_m > 0 (got " +
                std::to_string(c.num_rings) + ", " + std::to_string(c.num_sectors) + ", " +
                std::to_string(c.max_radius_m) + ")");
}

int wrap_index(int i, int n) { return ((i % n) + n) % n; }

}  // namespace

ScanContextBuilder::ScanContextBuilder(const ScanContextConfig& config, float lateral_offset_m)
    : config_(config), lateral_offset_m_(lateral_offset_m) {
  check_config(config_);
  ring_width_m_ = static_cast<float>(config_.max_radius_m / config_.num_rings);
  sector_width_rad_ = static_cast<float>(kTwoPi / config_.num_sectors);
  max_radius_sq_ = static_cast<float>(config_.max_radius_m * config_.max_radius_m);
  // Bins start at 0 and keep a max, so points below the ground level never mark a bin.
  bins_ = Eigen::MatrixXf::Zero(config_.num_rings, config_.num_sectors);
}

void ScanContextBuilder::add_point(float x, float y_sensor, float z) {
  const float y = y_sensor - lateral_offset_m_;
  const float r_sq = x * x + y * y;
  if (!(r_sq < max_radius_sq_) || r_sq <= 0.0f) return;  // also drops NaN
  float azimuth = std::atan2(y, x);
  if (azimuth < 0.0f) azimuth += static_cast<float>(kTwoPi);
  const int ring = std::min(static_cast<int>(std::sqrt(r_sq) / ring_width_m_), config_.num_rings - 1);
  const int sector =
      std::min(static_cast<int>(azimuth / sector_width_rad_), config_.num_sectors - 1);
  float& bin = bins_(ring, sector);
  bin = std::max(bin, z + static_cast<float>(config_.sensor_height_m));
}

void ScanContextBuilder::add(const std::vector<Eigen::Vector3f>& points_lidar) {
  for (const auto& p : points_lidar) add_point(p.x(), p.y(), p.z());
}

void ScanContextBuilder::add(const std::vector<LidarPoint>& points_lidar) {
  for (const auto& p : points_lidar) add_point(p.x, p.y, p.z);
}

ScanContext ScanContextBuilder::finish() const {
  ScanContext sc;
  sc.bins = bins_;
  sc.ring_key = bins_.rowwise().mean();
  sc.sector_key = bins_.colwise().mean().transpose();
  sc.column_norms = bins_.colwise().norm().transpose();
  return sc;
}

ScanContext make_scan_context(const std::vector<Eigen::Vector3f>& points_lidar,
                              const ScanContextConfig& config) {
  ScanContextBuilder builder(config);
  builder.add(points_lidar);
  return builder.finish();
}

ScanContext make_scan_context(const std::vector<LidarPoint>& points_lidar,
                              const ScanContextConfig& config) {
  ScanContextBuilder builder(config);
  builder.add(points_lidar);
  return builder.finish();
}

ScanContext make_scan_context(const std::vector<Eigen::Vector3f>& edges_lidar,
                              const std::vector<Eigen::Vector3f>& planes_lidar,
                              const ScanContextConfig& config) {
  ScanContextBuilder builder(config);
  builder.add(edges_lidar);
  builder.add(planes_lidar);
  return builder.finish();
}

double column_distance(const ScanContext& current, const ScanContext& loop, int shift_sectors) {
  const int n = static_cast<int>(loop.bins.cols());
  double similarity_sum = 0.0;
  int pairs = 0;
  for (int j = 0; j < n; ++j) {
    const int jc = wrap_index(j + shift_sectors, n);
    const float norm_product = loop.column_norms[j] * current.column_norms[jc];
    if (norm_product <= 0.0f) continue;
    similarity_sum += loop.bins.col(j).dot(current.bins.col(jc)) / norm_product;
    ++pairs;
  }
  return pairs == 0 ? 1.0 : 1.0 - similarity_sum / pairs;
}

double shift_to_yaw_rad(int shift_sectors, int num_sectors) {
  // Current column j + s sees what loop column j sees: azimuth_current = azimuth_loop - yaw,
  // hence yaw = -s sectors, wrapped in whole sectors to (-pi, pi].
  int sectors = -wrap_index(shift_sectors, num_sectors);
  if (2 * sectors <= -num_sectors) sectors += num_sectors;
  return sectors * kTwoPi / num_sectors;
}

ColumnAlignment align_scan_contexts(const ScanContext& current, const ScanContext& loop,
                                    double fine_search_ratio) {
  const int n = static_cast<int>(loop.bins.cols());
  if (current.bins.rows() != loop.bins.rows() || current.bins.cols() != n)
    throw Error("scan context: descriptors of different sizes cannot be aligned");

  // Coarse: the shift that best matches the sector keys (squared difference).
  int coarse = 0;
  float best_key_error = std::numeric_limits<float>::infinity();
  for (int s = 0; s < n; ++s) {
    float error = 0.0f;
    for (int j = 0; j < n; ++j) {
      const float d = current.sector_key[wrap_index(j + s, n)] - loop.sector_key[j];
      error += d * d;
    }
    if (error < best_key_error) {
      best_key_error = error;
      coarse = s;
    }
  }

  // Fine: full column comparison around the coarse shift.
  const int radius = std::min(static_cast<int>(std::lround(fine_search_ratio * n)), n / 2);
  ColumnAlignment best;
  best.distance = std::numeric_limits<double>::infinity();
  for (int ds = -radius; ds <= radius; ++ds) {
    const int s = wrap_index(coarse + ds, n);
    const double d = column_distance(current, loop, s);
    if (d < best.distance) {
      best.distance = d;
      best.shift_sectors = s;
    }
  }
  best.yaw_loop_current_rad = shift_to_yaw_rad(best.shift_sectors, n);
  return best;
}

}  // namespace scfloam
