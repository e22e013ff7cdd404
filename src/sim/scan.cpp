// One sweep: cast every (column, beam) ray in parallel over columns, then emit the returns
// ring by ring. Every random draw is keyed by (seed, frame, column, beam).
#include "scfloam/sim/scan.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "scfloam/se3.hpp"
#include "scfloam/sim/rng.hpp"

namespace scfloam::sim {
namespace {

// The pose at `frac` (0 ... 1) of a sweep sampled evenly at `along` (two or more poses).
Pose along_sweep(const std::vector<Pose>& along, double frac) {
  const double f = std::clamp(frac, 0.0, 1.0) * static_cast<double>(along.size() - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(f), along.size() - 2);
  return interpolate(along[i], along[i + 1], f - static_cast<double>(i));
}

}  // namespace

Scan render_scan(const World& world, const SensorModel& sensor, const BeamCalibration& calib,
                 const SweepPoses& poses, std::uint64_t seed, std::uint64_t frame,
                 const Traffic* traffic, double scan_time_s) {
  const int beams = sensor.beams(), columns = sensor.columns;
  constexpr double kDeg = M_PI / 180.0;
  std::vector<double> sin_el(beams), cos_el(beams), sin_el_true(beams), cos_el_true(beams);
  std::vector<double> cos_az_off(beams), sin_az_off(beams);
  for (int b = 0; b < beams; ++b) {
    const double el = sensor.elevations_deg[b] * kDeg;
    sin_el[b] = std::sin(el);
    cos_el[b] = std::cos(el);
    sin_el_true[b] = std::sin(el + calib.elevation_offset_rad[b]);
    cos_el_true[b] = std::cos(el + calib.elevation_offset_rad[b]);
    cos_az_off[b] = std::cos(calib.azimuth_offset_rad[b]);
    sin_az_off[b] = std::sin(calib.azimuth_offset_rad[b]);
  }
  std::vector<LidarPoint> slots(static_cast<std::size_t>(beams) * columns);
  std::vector<std::uint8_t> valid(slots.size(), 0);
  const std::uint64_t frame_seed = hash_combine(hash_combine(seed, 0x5CA7ULL), frame);

  const bool tilted_mount = sensor.mount_roll_deg != 0 || sensor.mount_pitch_deg != 0;
  const auto [bottom_it, top_it] = std::minmax_element(sensor.elevations_deg.begin(), sensor.elevations_deg.end());
  const double top_el = (beams > 0 ? *top_it + 1.0 : 0.0) * M_PI / 180;  // + 1 deg: calibration errors
  const double bottom_el = (beams > 0 ? *bottom_it - 1.0 : 0.0) * M_PI / 180;
  tbb::parallel_for(tbb::blocked_range<int>(0, columns, 16), [&](const tbb::blocked_range<int>& range) {
    std::vector<Primitive> movers, column_movers;
    for (int c = range.begin(); c != range.end(); ++c) {
      const double frac = (c + 0.5) / columns;
      // Clockwise from behind the car: azimuth +180 deg -> -180 deg.
      const double az = M_PI - 2 * M_PI * frac;
      const Pose T_world_col = poses.motion_distortion && poses.T_world_lidar_along.size() >= 2
                                   ? along_sweep(poses.T_world_lidar_along, frac)
                                   : poses.T_world_lidar;
      const Eigen::Vector3d origin = T_world_col.translation();
      const double cos_az = std::cos(az), sin_az = std::sin(az);
      const float time_s = static_cast<float>((frac - 0.5) * sensor.sweep_period_s);
      // Moving objects where they are when this column fires (a sweep takes 0.1 s whether
      // or not the ego motion is compensated), kept if they can cross this column's rays.
      column_movers.clear();
      if (traffic) {
        movers.clear();
        traffic->primitives_at(scan_time_s + time_s, origin.head<2>(), sensor.max_range_m, &movers);
        const Eigen::Vector3d fwd = T_world_col.linear() * Eigen::Vector3d(cos_az, sin_az, 0);
        const double col_bearing = std::atan2(fwd.y(), fwd.x());
        // A sensor tilted on its mount turns its column's rays out of one vertical plane: their
        // bearings spread up to the top and bottom beams'. (Level: one plane, no spread, and
        // the same culling as before the mount existed.)
        double spread = 0;
        if (tilted_mount) {
          for (const double el : {top_el, bottom_el}) {
            const Eigen::Vector3d ray =
                T_world_col.linear() * Eigen::Vector3d(std::cos(el) * cos_az, std::cos(el) * sin_az, std::sin(el));
            spread = std::max(spread, std::abs(std::remainder(std::atan2(ray.y(), ray.x()) - col_bearing, 2 * M_PI)));
          }
        }
        for (const Primitive& p : movers) {
          const double dx = p.cx - origin.x(), dy = p.cy - origin.y();
          const double dist = std::hypot(dx, dy), radius = std::hypot(p.hx, p.hy);
          const double diff = std::abs(std::remainder(std::atan2(dy, dx) - col_bearing, 2 * M_PI));
          if (dist <= radius + 0.5 || diff < std::asin(radius / dist) + 0.03 + spread) column_movers.push_back(p);
        }
      }
      for (int b = 0; b < beams; ++b) {
        Rng rng(hash_combine(frame_seed, static_cast<std::uint64_t>(c) * 4096 + b));
        // Direction of the true (miscalibrated) beam: azimuth az + offset.
        const double cos_true = cos_az * cos_az_off[b] - sin_az * sin_az_off[b];
        const double sin_true = sin_az * cos_az_off[b] + cos_az * sin_az_off[b];
        const Eigen::Vector3d dir_true(cos_el_true[b] * cos_true, cos_el_true[b] * sin_true, sin_el_true[b]);
        const Eigen::Vector3d dir_world = T_world_col.linear() * dir_true;
        RayHit hit;
        bool found = world.cast(origin, dir_world, sensor.max_range_m, rng.next(), &hit);
        for (const Primitive& p : column_movers) {
          double t;
          Eigen::Vector3d n;
          if (world.hit_primitive(p, 0, origin, dir_world, found ? hit.range_m : sensor.max_range_m, 0, &t, &n)) {
            found = true;
            hit.range_m = t;
            hit.normal = n;
            hit.kind = p.kind;
            hit.reflectance = p.reflectance;
          }
        }
        if (!found) continue;
        const double cos_inc = std::abs(hit.normal.dot(dir_world));
        // Dropouts: random, more at grazing incidence, and weak returns far away.
        double p_drop = sensor.dropout_prob;
        if (cos_inc < 0.1) p_drop += 0.6 * (1 - cos_inc / 0.1);
        const double far = std::max(1.0, hit.range_m / 30.0);
        if (hit.reflectance * std::max(cos_inc, 0.05) / (far * far) < 0.004) continue;
        if (rng.uniform() < p_drop) continue;
        const double range = hit.range_m + calib.range_bias_m[b] + rng.normal(0, sensor.range_noise_m);
        if (range < sensor.min_range_m || range > sensor.max_range_m) continue;
        // The driver reports the point along the nominal beam direction, in the sensor frame
        // at the firing time: with motion distortion that frame moves during the sweep.
        const Eigen::Vector3d p = range * Eigen::Vector3d(cos_el[b] * cos_az, cos_el[b] * sin_az, sin_el[b]);
        const double intensity = hit.reflectance * (0.6 + 0.4 * cos_inc) + rng.normal(0, 0.02);
        LidarPoint& out = slots[static_cast<std::size_t>(b) * columns + c];
        out.x = static_cast<float>(p.x());
        out.y = static_cast<float>(p.y());
        out.z = static_cast<float>(p.z());
        out.intensity = static_cast<float>(std::clamp(intensity, 0.0, 0.99));
        out.time_s = time_s;
        out.ring = static_cast<std::int16_t>(b);
        valid[static_cast<std::size_t>(b) * columns + c] = 1;
      }
    }
  });

  Scan scan;
  scan.has_ring = scan.has_time = true;
  scan.points.reserve(std::count(valid.begin(), valid.end(), 1));
  for (std::size_t i = 0; i < slots.size(); ++i)
    if (valid[i]) scan.points.push_back(slots[i]);
  return scan;
}

}  // namespace scfloam::sim
