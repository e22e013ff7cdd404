// Every number that changes behaviour, one struct per stage, with the paper's defaults
// (../shared/SPEC.md). Loaded from YAML by load_config(); docs/parameters.md explains each.
#pragma once

#include <filesystem>
#include <string>

#include "scfloam/backend/pose_graph_config.hpp"
#include "scfloam/loop/config.hpp"
#include "scfloam/loop/loop_registration_config.hpp"

namespace scfloam {

// Range crop and motion compensation of the raw scan.
struct PreprocessConfig {
  double min_range_m = 3.0;   // horizontal range sqrt(x^2+y^2) kept in [min, max] (KITTI launch)
  double max_range_m = 90.0;
  // Constant-velocity deskew using per-point time_s; only applied when the scan has times.
  // Off for KITTI: its scans are already motion-compensated.
  bool deskew = false;
  // With deskew on, whether the scans are in fact motion-distorted is measured rather than
  // assumed: some drivers and datasets compensate the motion but keep the time field, and
  // deskewing such scans again drifts 10-15x (docs/odometry.md, "Session 31"). The odometry
  // also runs without deskew alongside, each in its own map, until the frames in motion
  // (the sweep moves its points >= 0.2 m: sweep x (speed + turn rate x the points' mean
  // range)) say which of the two fits its map better (13 of the last 15 agree, their median
  // ratio of mean residuals 5 % off 1), and keeps that one; undecided after 100 such frames
  // (or 300 frames in all), it keeps deskew.
  bool deskew_check = true;
  // Scans without per-point times (KITTI-style .bin, older Velodyne drivers, exported PCD
  // folders) get them from the azimuth when deskew is on: the point order gives the sweep's
  // direction and seam (features/sweep_times.hpp), times count from the sweep's middle. A
  // cloud whose order shows no sweep keeps no times (and is not deskewed).
  bool deskew_times_from_azimuth = true;
  // The sweep's duration for those times; 0: the interval between the scans' stamps (0.1 s
  // until two stamps 0.02-0.25 s apart are seen; a longer gap keeps the last interval).
  double sweep_period_s = 0;
  // With deskew: a frame whose solved motion differs from the last interval's (by which the
  // sweep was deskewed) enough to move the sweep's ends by these amounts is deskewed again
  // at its own velocity and solved once more (a turn starting or ending, a spinning robot,
  // a hand-held sensor, hard braking; docs/odometry.md, "Session 38").
  bool redeskew = true;
  double redeskew_min_rotation_deg = 0.2;
  double redeskew_min_translation_m = 0.02;
  // Where in its sweep a scan without point times is stamped, for those times: "middle"
  // (KITTI, the simulator's default), "start" (Ouster, Hesai) or "end" (Velodyne's ROS
  // driver). Wrong, the poses are reported up to a sweep off in time, not distorted.
  std::string sweep_stamp = "middle";
  // Raises every feature point's elevation by this angle (degrees). KITTI's HDL-64E scans
  // report beams about 0.22 deg too low (IMLS-SLAM, Deschaud 2018; CT-ICP uses 0.205), which
  // bends the trajectory into a bowl: a steady pitch drift no loop closure can see. 0.22 is
  // the published figure for KITTI, the default input; other sensor presets set 0.
  double elevation_correction_deg = 0.22;
  // With a correction configured, whether the scans need it is measured rather than assumed:
  // an HDL-64E whose beams are where its calibration says (any but KITTI's) drifts 13-44x
  // with KITTI's correction (docs/odometry.md, "Session 32"), and the beams of the two look
  // alike. As deskew_check (after it, when both run): the odometry also runs without the
  // correction, each in its own map, until the frames in motion (0.2 m or more between
  // frames) say which fits its map better, and keeps that one; undecided, it keeps the
  // correction. Not with the online estimators below, which move the correction themselves.
  bool elevation_check = true;
  // Estimates the correction online, starting from elevation_correction_deg, from each
  // frame's plane matches (odometry/elevation_calibration.hpp), within 1 deg of that start.
  // Off in every preset: it recovers most of a wrong or unknown offset on 64- and 128-beam
  // sensors (0.32 -> 0.06 % t_err on a simulated city) but wanders by ~0.05 deg where the
  // start is right and by ~0.1 deg on 16/32 beams, which costs more than it gains there
  // (docs/odometry.md, "Session 20"). The estimate is in summary.json.
  bool online_elevation_calibration = false;
  double elevation_calibration_gain = 0.3;  // share of each frame's estimated step applied
  // Estimates the correction online from the road: the heights of one spot of road seen from
  // two places 6-30 m apart (odometry/ground_elevation.hpp), pooled over the drive and used
  // from the 10th such pair, within 1 deg of elevation_correction_deg. For a vehicle on a road
  // with a 64/128-beam sensor (it harmed an HDL-32E; a VLP-16's rings are too sparse for pairs,
  // so it stays at the configured value); not with online_elevation_calibration. Off by
  // default: the beams' own elevation errors and range biases bias it by up to ~0.05 deg
  // (docs/odometry.md, "Session 25" and "Session 26").
  bool ground_elevation_calibration = false;
};

// Which beam each point belongs to.
struct RingConfig {
  // Elevation table: "hdl64" (KITTI two-block layout), "hdl32", "vlp16", "os1-64", "os1-128",
  // or "auto": the beam elevations learned from the first full scan (beam_layout.hpp).
  std::string lidar = "hdl64";
  bool use_ring_field = true;     // take LidarPoint::ring when the scan carries it
  // When the first scan's beams are distinct but `lidar`'s table does not fit them (two beams
  // in one ring, or beams outside its field of view), use the learned beams instead.
  bool adopt_learned_layout = true;
  int min_points_per_ring = 131;  // F-LOAM skips sparser rings
};

// Curvature and edge/plane selection per ring.
struct FeatureConfig {
  int curvature_half_window = 5;     // neighbours each side on the ring
  int sectors_per_ring = 6;
  int max_edges_per_sector = 20;
  double edge_min_curvature = 0.1;   // squared-norm curvature, F-LOAM's unit (m^2)
  // An edge's curvature must also exceed this x the median curvature of its ring (0 = off).
  // Most of a ring lies on smooth surfaces, so the median measures the curvature that range
  // noise alone makes there; with 2 cm noise, near ground reaches 0.1 on one point in ten.
  double edge_noise_factor = 40.0;
  double suppression_gap_m = 0.2236; // neighbours of an edge are suppressed while closer than this
  // LOAM's occlusion test: at a depth jump between neighbours at nearly the same bearing
  // (gap / range < occlusion_gap_ratio), the far side's points are hidden or revealed as the
  // sensor moves, so they may not become edges.
  bool reject_occluded = true;
  double occlusion_gap_ratio = 0.1;
  double edge_leaf_m = 0.4;  // voxel-grid downsampling of the feature clouds
  double plane_leaf_m = 0.8;
};

// The most map neighbours a registration match may use (VoxelMap keeps them on the stack).
inline constexpr int kMaxRegistrationKnn = 12;

// Scan-to-map registration (also used by loop registration).
struct RegistrationConfig {
  // Map neighbours of a feature point. F-LOAM's 5 often lie on one ring trace, which any tilted
  // plane fits and which looks like a line on a wall (docs/parameters.md).
  int knn = 8;
  double max_neighbor_dist_m = 1.0;  // the k-th neighbour must lie within this
  double edge_line_ratio = 3.0;      // largest covariance eigenvalue > ratio * second
  double plane_max_dist_m = 0.1;     // every neighbour within this of the fitted plane (F-LOAM: 0.2)
  // An edge match is dropped when the point lies farther than this from its line (0 = never,
  // as F-LOAM). Coarse passes, whose start is farther off, do not apply it. Opt-in: 0.1 takes
  // 5-60 % off t_err on simulated HDL-64 drives (other sensors: within 0.001) but moves one
  // real KITTI 08 frame past its test's bound (docs/odometry.md, "Session 22").
  double edge_max_residual_m = 0.0;
  // An edge matches only map points seen from within this horizontal angle of its own viewing
  // direction (0 = any, as F-LOAM): a pole's or trunk's silhouette seen from elsewhere is
  // another line, and matched to it the pose slides towards the map's viewpoints (behind). The
  // local map then keeps points of different views side by side. Loop registration, whose
  // keyframes come from other directions, never applies it. Off in the 16/32-beam presets,
  // where it gained nothing after loops (docs/odometry.md, "Session 23").
  double edge_view_tolerance_deg = 20.0;
  // Reject a plane match whose neighbours spread along one line only (second covariance
  // eigenvalue < ratio * largest): a single ring's trace fits any plane through it (0 = off).
  double plane_min_spread_ratio = 0.0;
  double huber_delta_m = 0.05;      // F-LOAM / SPEC: 0.1 (docs/odometry.md, "Session 15")
  int inner_iterations = 4;          // Ceres iterations per correspondence round
  int outer_iterations = 2;          // correspondence rounds per frame in steady state
  int outer_iterations_initial = 12; // rounds on the first frame, decreasing by one per frame
  // A point's match is kept from the previous round when the point moved less than this
  // (0 = search every round): later rounds move the pose by millimetres.
  double match_refresh_m = 0.05;
  // Stop the rounds early once one moves the pose less than both of these.
  double converged_translation_m = 0.001;
  double converged_rotation_deg = 0.01;
  // Rounds past the frame's count while the last one still moved the pose more than either of
  // these (a jolt or a turn harder than the constant-velocity model): at most
  // outer_iterations_max rounds in all (<= the frame's count = never more).
  int outer_iterations_max = 12;
  double unconverged_translation_m = 0.01;
  double unconverged_rotation_deg = 0.05;
  // Inside a round, Ceres stops once an accepted step's tangent norm |[omega; v]| (rad, m) is
  // below this (0 = always run inner_iterations).
  double solver_step_tolerance = 1e-4;
  // Smallest eigenvalue of the translation block of J^T J (in units of "well-constrained
  // residuals") below which a solve is reported degenerate.
  double degeneracy_min_eigenvalue = 50.0;
  // Same for the rotation block (units: residuals x lever arm^2 in m^2; a frame's structure
  // 5-30 m away gives 10^4 and more, a flat open field ~0 about the vertical).
  double degeneracy_min_rotation_eigenvalue = 50.0;
  // Along the weak eigenvectors (of either block) the constant-velocity prediction enters the
  // solve as a prior with the weights below, so the matches decide there only as far as their
  // information outweighs it (docs/odometry.md, "Degenerate scenes").
  bool degeneracy_fallback = true;
  // The prior's weight along a weak translation (rotation) direction, in the units of J^T J:
  // (residual noise / prediction error per frame)^2. Translation: ~5 cm residuals against a
  // car's 1.6 m/s^2 changing a 10 Hz step by 1.6 cm: 10 (3 before session 40, for 3 m/s^2;
  // along a weak direction the few matches lie on one or two surfaces and share their map
  // fit's error, so they are worth less than their count. With 3, a distorted VLP-16 drive
  // starting on an open square lost 4 % of its speed for 50 frames and ended at 0.92 % t_err;
  // 10 moved 44 other sparse-sensor worlds by at most 0.002 % and helped the degenerate scenes,
  // docs/odometry.md "Session 40"). Rotation: 0.5 rad/s^2, 0.005 rad: 100 m^2. A direction
  // with no information keeps the prediction; one matched by 50 residuals moves 83 % of the
  // way to where they say. 0: the weak directions keep the prediction exactly (solution
  // remapping, Zhang et al. 2016).
  double degeneracy_prior_translation_weight = 10.0;
  double degeneracy_prior_rotation_weight = 100.0;
  // Relative test (registration/degeneracy.hpp): an eigenvalue of the translation (rotation)
  // block below this fraction of the block's largest is weak. Measured per frame (session 6,
  // docs/degenerate.md): simulated city, KITTI-05-like and real KITTI >= 0.17 and >= 0.058;
  // inside the tunnel median 0.035 and <= 0.017 past the portals.
  double degeneracy_min_translation_ratio = 0.1;
  double degeneracy_min_rotation_ratio = 0.05;
  // Odometry: the second frame's prediction is a guess (zero velocity), so a coarse pass first
  // aligns it to the first frame's features with this search radius, wider than
  // max_neighbor_dist_m's basin (0 = no coarse pass). Gaps are handled apart (odometry.cpp).
  double coarse_neighbor_dist_m = 3.0;
  int num_threads = 2;               // TBB correspondence search and Ceres evaluation
};

// The local feature map around the current pose.
struct LocalMapConfig {
  double edge_spacing_m = 0.2;   // a new map point closer than this to a stored one is dropped
  double plane_spacing_m = 0.4;
  int max_points_per_cell = 20;  // hash cells are max_neighbor_dist_m wide
  double radius_m = 100.0;       // cells farther than this from the pose are removed
};

struct OdometryConfig {
  PreprocessConfig preprocess;
  RingConfig rings;
  FeatureConfig features;
  RegistrationConfig registration;
  LocalMapConfig map;
};

// How the three stages are joined.
struct PipelineConfig {
  // Loop work done in frame order on the odometry's thread: the same input gives the same
  // output (tests, evaluation). Otherwise the stages run on their own threads.
  bool deterministic = false;
  int queue_capacity = 256;        // keyframes waiting between stages
  // The odometry waits before scan f until the loop stages have finished every keyframe made
  // before scan f - max_loop_lag_frames: corrections then reach its map as they would live,
  // where a 10 Hz sensor gives the loop stages 100 ms per scan. Without the bound, a file read
  // at 8x real time leaves the loop stages keyframes behind and the odometry drifts on an
  // uncorrected map (docs/loop_closure.md). -1: never wait (only a full queue blocks).
  int max_loop_lag_frames = 1;
  // The loop detection and closure threads run this much nicer (0-19) than the odometry, so
  // that when both want the two cores the odometry gets them and the loop stages catch up in
  // its idle time (the queues above give them hundreds of keyframes of slack).
  int loop_thread_nice = 10;
  // While keyframes wait for the closure stage, an accepted loop's graph solve waits too, for
  // at most this many loops: the backlog is worked off and solved once (a whole-graph solve
  // per loop is slower than real time on graphs of thousands of keyframes). 0: solve after
  // every loop. Deterministic mode has no queue and always solves per loop.
  int max_deferred_loops = 16;
  bool rebuild_map_after_loop = true;  // the odometry continues on the corrected map
  // A correction that moves no keyframe near the odometry by more than this (relative to the
  // newest keyframe; rotation counted at 30 m) leaves the map as it is, unless the odometry
  // travelled a fifth of the map radius since the last rebuild. 0: rebuild after every loop.
  double map_rebuild_min_shift_m = 0.05;
  double raw_leaf_m = 0.4;         // raw keyframe clouds (baseline descriptor, ICP) downsampling
  // Keyframes whose clouds stay in memory; the least recently used beyond are spilled to a
  // file in spill_dir (empty: the temp folder) and read back when needed. 0: keep all.
  int resident_keyframes = 2000;
  std::string spill_dir;
  // Map rebuild after a correction: of the keyframes within the map radius, only the newest
  // per cube of this size (m) is used, so revisits do not pile up. 0: every keyframe.
  double map_rebuild_cell_m = 1.0;
};

struct SlamConfig {
  OdometryConfig odometry;
  LoopDetectionConfig loop_detection;
  LoopRegistrationConfig loop_registration;
  PoseGraphConfig pose_graph;
  PipelineConfig pipeline;
};

// Reads a YAML file; unknown keys and wrong types are errors naming the file and the key.
SlamConfig load_config(const std::filesystem::path& path);
// The whole config as YAML (every key, current values); load_config reads it back unchanged.
std::string config_to_yaml(const SlamConfig& config);
void save_config(const std::filesystem::path& path, const SlamConfig& config);

}  // namespace scfloam
