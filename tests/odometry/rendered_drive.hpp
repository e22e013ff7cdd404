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
  std::vector<Scan> scans;
  std::vector<Eigen::Isometry3d> gts;  // ground truth relative to the first frame
  Eigen::Vector3d world_up;            // the world's up in the first frame's axes
};

// `firing_order`: points column by column, as a raw driver emits them (the simulator writes
// them beam by beam).
inline RenderedDrive render_drive(const sim::SimConfig& cfg, bool firing_order = false) {
  const sim::SensorModel sensor = sim::sensor_for(cfg);
  const sim::Scenario sc = sim::build_scenario(cfg);
  const sim::BeamCalibration calib = sim::draw_beam_calibration(sensor, cfg.seed);
  RenderedDrive drive;
  drive.route = cfg.route;
  const Eigen::Isometry3d T0_inv = sc.frame_pose(0).inverse();
  drive.world_up = T0_inv.linear() * Eigen::Vector3d::UnitZ();
  for (std::size_t k = 0; k < sc.frames; ++k) {
    sim::SweepPoses poses;
    const double t = sc.frame_time(k);
    poses.T_world_lidar = sc.trajectory.at(t);
    poses.motion_distortion = cfg.motion_distortion;
    poses.T_world_lidar_start = sc.trajectory.at(t - 0.5 * sensor.sweep_period_s);
    poses.T_world_lidar_end = sc.trajectory.at(t + 0.5 * sensor.sweep_period_s);
    Scan scan = sim::render_scan(sc.world, sensor, calib, poses, cfg.seed, k);
    scan.timestamp_s = t;
    if (firing_order) {
      const double step = sensor.azimuth_step_deg() * M_PI / 180;
      std::stable_sort(scan.points.begin(), scan.points.end(), [&](const LidarPoint& a, const LidarPoint& b) {
        return std::lround((std::atan2(a.y, a.x) + M_PI) / step) < std::lround((std::atan2(b.y, b.x) + M_PI) / step);
      });
    }
    drive.scans.push_back(std::move(scan));
    drive.gts.push_back(T0_inv * poses.T_world_lidar);
  }
  return drive;
}

}  // namespace scfloam::test
