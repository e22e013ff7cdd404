// A simulated drive rendered in memory (no traffic), for tests that run several odometry
// settings on the same scans: rendering costs more than the odometry.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/simulate.hpp"

namespace scfloam::test {

struct RenderedDrive {
  std::string route;
  std::vector<Scan> scans;  // stamped at the middle of their sweeps, as the simulator does
  std::vector<Eigen::Isometry3d> gts;  // ground truth relative to the first frame
  Eigen::Vector3d world_up;            // the world's up in the first frame's axes
  double sweep_period_s = 0.1;
  // The sensor at the start and the end of each sweep, relative to the first sweep's.
  std::vector<Eigen::Isometry3d> gts_at_sweep_start, gts_at_sweep_end;
  // The sensor at the middle of the first sweep, seen from the sensor at its start.
  Eigen::Isometry3d first_middle_from_start = Eigen::Isometry3d::Identity();
};

// `firing_order`: points column by column, as a raw driver emits them (the simulator writes
// them beam by beam). The scans are stamped at the middle of their sweeps (cfg.sweep_stamp is
// not used: stamped_at below gives the same sweeps stamped otherwise). `first_frames` > 0
// renders only the first frames of the cfg.frames-long scenario (its route depends on its
// length).
inline RenderedDrive render_drive(sim::SimConfig cfg, bool firing_order = false, std::size_t first_frames = 0) {
  cfg.sweep_stamp = "middle";
  const sim::SensorModel sensor = sim::sensor_for(cfg);
  const sim::Scenario sc = sim::build_scenario(cfg);
  const sim::BeamCalibration calib = sim::draw_beam_calibration(sensor, cfg.seed);
  RenderedDrive drive;
  drive.route = cfg.route;
  // The sensor's poses (the vehicle's turned by the mount, as render_frame casts them).
  const auto at = [&](double t) { return sim::sensor_pose_at(sc, sensor, t); };
  const Eigen::Isometry3d T0_inv = at(sc.frame_time(0)).inverse();
  drive.sweep_period_s = sensor.sweep_period_s;
  const Eigen::Isometry3d T0_start_inv = at(sc.frame_time(0) - 0.5 * sensor.sweep_period_s).inverse();
  const Eigen::Isometry3d T0_end_inv = at(sc.frame_time(0) + 0.5 * sensor.sweep_period_s).inverse();
  drive.first_middle_from_start = T0_start_inv * at(sc.frame_time(0));
  drive.world_up = T0_inv.linear() * Eigen::Vector3d::UnitZ();
  const std::size_t frames = first_frames > 0 ? std::min(first_frames, sc.frames) : sc.frames;
  for (std::size_t k = 0; k < frames; ++k) {
    const double t = sc.frame_time(k);
    Scan scan = sim::render_frame(sc, sensor, calib, cfg, k);
    if (firing_order) {
      const double step = sensor.azimuth_step_deg() * M_PI / 180;
      std::stable_sort(scan.points.begin(), scan.points.end(), [&](const LidarPoint& a, const LidarPoint& b) {
        return std::lround((std::atan2(a.y, a.x) + M_PI) / step) < std::lround((std::atan2(b.y, b.x) + M_PI) / step);
      });
    }
    drive.scans.push_back(std::move(scan));
    drive.gts.push_back(T0_inv * at(t));
    drive.gts_at_sweep_start.push_back(T0_start_inv * at(t - 0.5 * sensor.sweep_period_s));
    drive.gts_at_sweep_end.push_back(T0_end_inv * at(t + 0.5 * sensor.sweep_period_s));
  }
  return drive;
}

// The same sweeps as a driver that stamps each at its start (Ouster, Hesai: point times 0 ...
// 0.1 s) or its end (Velodyne's ROS driver: -0.1 ... 0) gives them, with the ground truth at
// those stamps.
enum class SweepStamp { kStart, kEnd };
inline RenderedDrive stamped_at(const RenderedDrive& drive, SweepStamp stamp) {
  RenderedDrive out = drive;
  const double shift = (stamp == SweepStamp::kStart ? -0.5 : 0.5) * drive.sweep_period_s;
  for (Scan& scan : out.scans) {
    scan.timestamp_s += shift;
    for (LidarPoint& pt : scan.points) pt.time_s -= static_cast<float>(shift);
  }
  out.gts = stamp == SweepStamp::kStart ? drive.gts_at_sweep_start : drive.gts_at_sweep_end;
  return out;
}

}  // namespace scfloam::test
