// map.pcd from raw sweeps: the keyframes' scans are deskewed as the odometry deskewed them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "pipeline/scan_list_source.hpp"
#include "scfloam/pipeline/outputs.hpp"
#include "scfloam/sim/simulate.hpp"
#include "support/wall_ahead.hpp"

namespace scfloam {
namespace {

// support/wall_ahead.hpp's drive, each sweep stamped at its start and cast along the motion (a
// raw sensor); the run's poses are the truth.
struct WallDrive {
  test::ScanListSource source;
  RunResult result;
};

WallDrive wall_drive() {
  const test::WallAhead wall = test::wall_ahead(5);
  const sim::Scenario& sc = wall.scenario;
  sim::SimConfig cfg;
  cfg.motion_distortion = true;
  cfg.sweep_stamp = "start";
  std::vector<Scan> scans;
  RunResult result;
  for (std::size_t k = 0; k < sc.frames; ++k) {
    scans.push_back(sim::render_frame(sc, wall.sensor, wall.calibration, cfg, k));
    scans.back().has_time = true;
    result.stamps_s.push_back(sc.frame_time(k));
    result.T_world_lidar.push_back(sc.frame_pose(k));
  }
  result.keyframe_frames = {2};
  return {test::ScanListSource(std::move(scans)), std::move(result)};
}

// The wall's points in the map (relative to the first frame, whose sensor is at x = 0): how
// far the farthest is from the face.
double worst_wall_offset(const std::vector<LidarPoint>& map) {
  double worst = 0;
  std::size_t n = 0;
  for (const LidarPoint& p : map) {
    if (p.x < 25 || p.z < -1.0) continue;  // the wall above the ground
    worst = std::max(worst, std::abs(p.x - 30.0));
    ++n;
  }
  EXPECT_GT(n, 500u);
  return worst;
}

TEST(MapAssembly, RawSweepsAreDeskewedWhereTheOdometryDeskewed) {
  WallDrive drive = wall_drive();
  OutputOptions options;
  options.map_voxel_m = 0.05;
  drive.result.deskewed_scans = true;
  // Deskewed at the trajectory's velocity the face is a plane (voxel centroids within 5 cm
  // cells, hdl64's KITTI-like elevation bias adds a few mm).
  EXPECT_LT(worst_wall_offset(assemble_map(drive.source, drive.result, options)), 0.03);
  // As scanned, each point is seen from where the sensor was at its time: the wall, swept 30-70
  // ms after the stamp, lies 0.3-0.7 m too near (measured: 0.70 m worst).
  drive.result.deskewed_scans = false;
  EXPECT_GT(worst_wall_offset(assemble_map(drive.source, drive.result, options)), 0.3);
}

}  // namespace
}  // namespace scfloam
