// A known answer for motion distortion: a flat world with one wall whose face is at x = 30,
// the sensor 1.73 m up driving along x at 10 m/s (x = 10 t) towards it, and a noise-free,
// perfectly calibrated HDL-64E (KITTI's common elevation offset stays: a few mm at the wall).
#pragma once

#include <vector>

#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/scenario.hpp"
#include "scfloam/sim/sensor.hpp"
#include "scfloam/sim/world.hpp"

namespace scfloam::test {

struct WallAhead {
  sim::Scenario scenario;  // frames 0.1 s apart over 1 s of trajectory
  sim::SensorModel sensor;
  sim::BeamCalibration calibration;
};

inline WallAhead wall_ahead(std::size_t frames) {
  WallAhead w;
  sim::World& world = w.scenario.world;
  world.terrain_m.reset(-200, -200, 4.0, 101, 101, 0.0f);
  world.road_edge_distance.reset(-200, -200, 4.0, 101, 101, -10.0f);
  world.primitives.push_back(sim::make_box(30.5, 0, 0, 0.5, 80, -1, 20, sim::SurfaceKind::building, 0.4f));
  world.build_index();
  for (int i = 0; i <= 100; ++i) {
    Pose T = Pose::Identity();
    T.translation() = Eigen::Vector3d(0.1 * i, 0, 1.73);
    w.scenario.trajectory.T_world_lidar.push_back(T);
  }
  w.scenario.frames = frames;
  w.sensor = sim::sensor_preset("hdl64");
  w.sensor.range_noise_m = 0;
  w.sensor.dropout_prob = 0;
  const std::vector<double> zeros(w.sensor.beams(), 0.0);
  w.calibration = sim::BeamCalibration{zeros, zeros, zeros};
  return w;
}

}  // namespace scfloam::test
