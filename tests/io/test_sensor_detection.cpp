// The --sensor preset `scfloam run` takes from the scans' beams when none is given
// (io/sensor_detection.hpp): each simulated sensor is told apart from the others, KITTI's real
// scans keep the defaults, and what cannot be told keeps them too.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scfloam/io/kitti.hpp"
#include "scfloam/io/sensor_detection.hpp"
#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/sensor.hpp"
#include "scfloam/sim/world.hpp"
#include "test_paths.hpp"

namespace scfloam {
namespace {

// A courtyard: flat ground and four 30 m walls 15-25 m away, so that every beam of every
// preset (up to +22.5 deg) meets something.
sim::World courtyard() {
  sim::World w;
  w.terrain_m.reset(-200, -200, 4.0, 101, 101, 0.0f);
  w.road_edge_distance.reset(-200, -200, 4.0, 101, 101, -10.0f);
  w.primitives.push_back(sim::make_box(20.5, 0, 0, 0.5, 40, -1, 30, sim::SurfaceKind::building, 0.4f));
  w.primitives.push_back(sim::make_box(-15.5, 0, 0, 0.5, 40, -1, 30, sim::SurfaceKind::building, 0.3f));
  w.primitives.push_back(sim::make_box(0, 25.5, 0, 40, 0.5, -1, 30, sim::SurfaceKind::building, 0.5f));
  w.primitives.push_back(sim::make_box(0, -18.5, 0, 40, 0.5, -1, 30, sim::SurfaceKind::building, 0.35f));
  w.build_index();
  return w;
}

// One scan of the simulator's sensor, with its default noise, dropouts and per-beam errors.
std::vector<LidarPoint> scan_of(const sim::World& world, const std::string& sensor_name) {
  const sim::SensorModel sensor = sim::sensor_preset(sensor_name);
  sim::SweepPoses poses;
  poses.T_world_lidar = Pose::Identity();
  poses.T_world_lidar.translation() = Eigen::Vector3d(1.0, 2.0, sensor.mount_height_m);
  return sim::render_scan(world, sensor, sim::draw_beam_calibration(sensor, 7), poses, 7, 0).points;
}

TEST(SensorDetection, EachSimulatedSensorGetsItsOwnPreset) {
  const sim::World world = courtyard();
  // The simulator's HDL-64E is KITTI's (with its elevation error): the defaults. A VLP-32C has
  // no ring table of its own: rings from its learned beams.
  const std::pair<const char*, const char*> expected[] = {
      {"hdl64", "kitti"}, {"vlp16", "vlp16"},     {"hdl32", "hdl32"},
      {"os1-64", "os1-64"}, {"os1-128", "os1-128"}, {"vlp32c", "auto"}};
  for (const auto& [sensor, preset] : expected) {
    const SensorGuess guess = guess_sensor(scan_of(world, sensor));
    EXPECT_EQ(guess.preset, preset) << sensor << ": " << guess.reason;
    EXPECT_EQ(static_cast<int>(guess.layout.elevations_deg.size()), sim::sensor_preset(sensor).beams())
        << sensor << ": " << guess.reason;
  }
}

TEST(SensorDetection, TopBeamsUnderOpenSkyStillMatchTheirFanButEveryOtherBeamDoesNot) {
  // Drop the returns of the top beams, as under open sky: the rest is still the sensor's fan.
  const sim::World world = courtyard();
  std::vector<LidarPoint> vlp16 = scan_of(world, "vlp16");
  auto without_above = [](std::vector<LidarPoint> pts, double elevation_deg) {
    pts.erase(std::remove_if(pts.begin(), pts.end(),
                             [&](const LidarPoint& p) {
                               return std::atan2(p.z, std::hypot(p.x, p.y)) * 180 / M_PI > elevation_deg;
                             }),
              pts.end());
    return pts;
  };
  EXPECT_EQ(guess_sensor(without_above(vlp16, 14.0)).preset, "vlp16");  // 15 of 16 beams
  EXPECT_EQ(guess_sensor(without_above(vlp16, 6.0)).preset, "vlp16");   // 11: the fan's lower beams
  EXPECT_EQ(guess_sensor(without_above(vlp16, 0.0)).preset, "vlp16");   // 8, the lower half
  EXPECT_EQ(guess_sensor(without_above(vlp16, -2.0)).preset, "auto");   // 7: too few to say
  std::vector<LidarPoint> hdl32 = scan_of(world, "hdl32");
  EXPECT_EQ(guess_sensor(without_above(hdl32, 3.0)).preset, "hdl32");   // 26 of 32
  // Every other beam of a fan is another sensor (an OS1-32 is half an OS1-64): its own beams.
  std::vector<LidarPoint> os64 = scan_of(world, "os1-64");
  os64.erase(std::remove_if(os64.begin(), os64.end(), [](const LidarPoint& p) { return p.ring % 2 == 1; }),
             os64.end());
  const SensorGuess half = guess_sensor(os64);
  EXPECT_EQ(half.layout.elevations_deg.size(), 32u) << half.reason;
  EXPECT_EQ(half.preset, "auto") << half.reason;
}

TEST(SensorDetection, TooFewReturnsKeepTheDefaults) {
  std::vector<LidarPoint> few = scan_of(courtyard(), "vlp16");
  few.resize(kMinLayoutPoints - 1);
  const SensorGuess guess = guess_sensor(few);
  EXPECT_EQ(guess.preset, "kitti");
  EXPECT_NE(guess.reason.find("too few"), std::string::npos) << guess.reason;
}

TEST(SensorDetection, KittiRealScansKeepTheDefaults) {
  // KITTI's HDL-64E lasers sit at different heights: their elevations blur (docs/odometry.md,
  // "Session 21"), and the defaults are made for exactly these scans.
  for (const char* seq : {"kitti/scans/00", "kitti/scans/05", "kitti/scans/08"}) {
    SCFLOAM_SHARED_DATA_OR_SKIP(dir, seq);
    const SensorGuess guess = guess_sensor(read_kitti_bin(dir / "velodyne" / "000000.bin"));
    EXPECT_EQ(guess.preset, "kitti") << seq << ": " << guess.reason;
    EXPECT_NE(guess.reason.find("blurred"), std::string::npos) << seq << ": " << guess.reason;
  }
}

}  // namespace
}  // namespace scfloam
