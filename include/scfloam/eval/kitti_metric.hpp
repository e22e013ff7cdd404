// The KITTI odometry devkit metric (evaluate_odometry.cpp), in double precision.
// Inputs are KITTI camera-0 poses (T_cam0_cam0I), or both trajectories in one common body
// convention: the relative motions compared are expressed in the pose's own frame, so a
// lidar-frame estimate against camera-frame ground truth is meaningless (docs/evaluation.md).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "scfloam/types.hpp"

namespace scfloam {

// The devkit's segment lengths and first-frame step (every 10th frame: once a second at 10 Hz).
inline constexpr std::array<double, 8> kKittiSegmentLengthsM = {100, 200, 300, 400,
                                                                500, 600, 700, 800};
inline constexpr std::size_t kKittiStepFrames = 10;

// One evaluated segment: errors of the relative motion first -> last, divided by its length.
struct KittiSegmentError {
  std::size_t first_frame = 0, last_frame = 0;
  double length_m = 0;
  double t_err_ratio = 0;     // ||t(E)|| / length (devkit's t_err: multiply by 100 for %)
  double r_err_rad_per_m = 0; // angle(R(E)) / length
  // t(E) in the ground truth's world frame, split along its up (vertical) and across it
  // (horizontal), each / length; NaN when the ground truth gives no up.
  double vertical_ratio = 0, horizontal_ratio = 0;
};

struct KittiLengthError {
  double length_m = 0;
  double t_err_pct = 0;            // NaN when segments == 0
  double r_err_deg_per_100m = 0;   // NaN when segments == 0
  std::size_t segments = 0;
};

struct KittiMetric {
  // Means over every segment of every length, as the devkit's stats.txt (scaled to % and
  // deg/100 m). NaN when the ground-truth path is shorter than 100 m (segments == 0).
  double t_err_pct = 0;
  double r_err_deg_per_100m = 0;
  std::size_t segments = 0;
  double path_length_m = 0;  // along the ground truth
  // Means over every segment of |vertical| and |horizontal| error, in %, like t_err (not its
  // parts: t_err is the mean of their root sum of squares). Loop closure reduces the
  // horizontal part; a sensor's elevation offset makes the vertical one (docs/evaluation.md).
  // NaN without segments or without an up.
  double t_err_vertical_pct = 0, t_err_horizontal_pct = 0;
  std::array<KittiLengthError, kKittiSegmentLengthsM.size()> per_length{};
  std::vector<KittiSegmentError> segment_errors;
  bool has_segments() const { return segments > 0; }
  // "" when there are segments; otherwise why t_err/r_err are undefined.
  std::string note;
};

// Cumulative path length along the poses' translations; [0] = 0 (devkit trajectoryDistances).
std::vector<double> trajectory_distances_m(const PoseList& poses);

// The first frame i >= first_frame with dist[i] > dist[first_frame] + length_m, or -1 when the
// path ends before (devkit lastFrameFromSegmentLength).
long last_frame_from_segment_length(const std::vector<double>& dist_m, std::size_t first_frame,
                                    double length_m);

// The ground truth's up, up to its sign, whatever its axis convention (camera 0's y down or a
// LiDAR's z up): the vehicle axis nearest the normal of the plane its positions span, averaged
// over the drive. None when they span no plane (second-smallest spread under 5 m RMS, or the
// smallest over a quarter of it: a straight line, a standstill) or the drive never turns (its
// directions of travel across that up scatter by less than ~8 deg RMS: a straight road over a
// crest, whose plane stands on edge).
std::optional<Eigen::Vector3d> ground_truth_up(const PoseList& gt);

// Throws scfloam::Error when the two lists differ in length or are empty (the devkit needs a
// pose for every frame).
KittiMetric kitti_metric(const PoseList& gt, const PoseList& est);

}  // namespace scfloam
