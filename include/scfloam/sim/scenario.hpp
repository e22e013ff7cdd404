// A scenario = a world plus the lidar trajectory driven through it, ready to render.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "scfloam/sim/city.hpp"
#include "scfloam/sim/route.hpp"
#include "scfloam/sim/world.hpp"

namespace scfloam::sim {

// Rings missing from every scan of frames [first_frame, end_frame) (degenerate.hpp).
struct BeamLoss {
  std::size_t first_frame = 0, end_frame = 0;
  int keep_every = 1;            // 2: only even rings remain (every other beam absent)
  double upper_share_lost = 0;   // 0.5: the upper half of the beams (ring 0 = top) is absent
};

struct Scenario {
  World world;
  // The vehicle's pose at the sensor's mount point (the sensor's, for a level mount;
  // sim::sensor_pose_at turns it by a tilted one); frame k is at t = frame_time(k).
  SampledTrajectory trajectory;
  std::size_t frames = 0;
  double frame_period_s = 0.1;
  double route_length_m = 0;
  CityStats stats;
  std::string description;  // one line: what route and world this is
  // Faults of the degenerate scenes (degenerate.hpp); every other route leaves them empty.
  std::vector<double> frame_times_s;  // frame k's time (empty: k * frame_period_s)
  std::vector<BeamLoss> beam_losses;
  // [first, end): the frames where the scene is degenerate (0, 0: none).
  std::size_t degenerate_first_frame = 0, degenerate_end_frame = 0;
  double frame_time(std::size_t k) const {
    return frame_times_s.empty() ? k * frame_period_s : frame_times_s.at(k);
  }
  Pose frame_pose(std::size_t k) const { return trajectory.at(frame_time(k)); }
};

// Grid city with a route that loops: a loop around city blocks back to the start, a
// same-direction revisit of the first street, then a drive around the neighbouring block
// the other way that returns along the first loop in the opposite direction; routes long
// enough (>= ~3000 frames) make the first loop longer than 1 km. Blocks get smaller for
// short routes so that 1000 frames (~850 m) already hold both kinds of revisit. Longer
// routes continue with a random drive through the grid (more revisits).
Scenario make_loops_scenario(std::uint64_t seed, std::size_t frames, double mount_height_m = 1.73);

// A long, gently curving avenue with side streets: odometry without loops.
Scenario make_straight_scenario(std::uint64_t seed, std::size_t frames, double mount_height_m = 1.73);

// Replays lidar poses T_lidar0_lidarK sampled at 10 Hz (e.g. a KITTI ground truth converted
// with camera_to_lidar_poses): the street follows the path, side streets branch off it,
// buildings stand back from it; frames = min(frames, poses) (0 = all). x, y and rotation
// are replayed exactly; z is the terrain (fitted to the file's heights) + mount height,
// because real ground truths drift vertically between passes of the same street.
Scenario make_replay_scenario(const PoseList& T_lidar0_lidar, std::uint64_t seed,
                              std::size_t frames, double mount_height_m = 1.73);

}  // namespace scfloam::sim
