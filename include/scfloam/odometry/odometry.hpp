// F-LOAM odometry: one call per scan returns the scan's pose and its feature clouds.
// The pipeline (src/pipeline) only uses this header; the odometry's internals stay in
// src/features, src/registration and src/odometry.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scfloam/config.hpp"
#include "scfloam/features/feature_extractor.hpp"
#include "scfloam/features/sweep_times.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

struct OdometryResult {
  Eigen::Isometry3d T_world_lidar = Eigen::Isometry3d::Identity();
  FeatureCloud edges;   // downsampled edge features, lidar frame (after deskew)
  FeatureCloud planes;  // downsampled plane features, lidar frame (after deskew)
  // Deskewed a second time at the velocity of this frame's own solve, and solved again
  // (PreprocessConfig::redeskew).
  bool redeskewed = false;
  double features_ms = 0;      // preprocessing + feature extraction
  double registration_ms = 0;  // prediction + scan-to-map + map update
  bool degenerate = false;     // the solve was poorly constrained in some direction
  // Diagnostics of the scan-to-map solve (zero on the first frame).
  int registration_rounds = 0;  // correspondence rounds run
  int edge_matches = 0;
  int plane_matches = 0;
  double mean_residual_m = 0;
  double min_translation_eigenvalue = 0;  // of J^T J; see RegistrationConfig
  double min_rotation_eigenvalue = 0;
  // All eigenvalues of the two blocks (ascending), for diagnostics of the degeneracy test.
  Eigen::Vector3d translation_eigenvalues = Eigen::Vector3d::Zero();
  Eigen::Vector3d rotation_eigenvalues = Eigen::Vector3d::Zero();
  // Weak directions (rotation + translation) where the pose kept the constant-velocity
  // prediction (RegistrationConfig::degeneracy_fallback); 6 when nothing matched.
  int weak_directions = 0;
  double elevation_correction_deg = 0;  // applied to this frame's features
  // Results for earlier frames, oldest first, in the same world frame, replacing the ones
  // returned for the last `revised.size()` frames before this one; a caller that keeps a
  // frame's result while `Odometry::may_revise()` can take them (the pipeline does). Set
  // - on the frame where a setting check switched to the other setting (this frame's result is
  //   then that setting's): the trial's earlier frames as that setting made them; this frame's
  //   pose continues the revised ones, against the unrevised track it may jump;
  // - on frame 1 when frame 0 was solved away from its stamp (a deskewed sweep not centred on
  //   it): frame 0 with its features moved to its stamp, which frame 1's velocity tells.
  std::vector<OdometryResult> revised;
};

// What one of the odometry's setting checks found (PreprocessConfig::deskew_check,
// elevation_check): the scans run both ways for a while, each way in its own map, and the
// setting whose solves fit their map better is kept.
struct SettingCheck {
  // Deskew: "off" (deskew not configured, or no frame yet), "unchecked" (deskew_check off), "no
  // per-point times" (deskew configured, no timed scan yet), "trial" (still measuring),
  // "distorted" (deskew kept), "compensated" (deskew turned off), "undecided" (deskew kept).
  // Elevation: "off" (no correction configured, or it is estimated online), "unchecked"
  // (elevation_check off), "waiting" (for the deskew check), "trial", "offset" (the
  // correction kept), "no offset" (the correction removed), "undecided" (the correction kept).
  // Set when it changes: the odometry's own test is a flag, not this text.
  std::string verdict = "off";
  bool decided = false;
  std::size_t decided_at_frame = 0;  // frame index of the decision
  std::size_t frames_compared = 0;   // frames in motion whose two solves were compared (so far)
  // Median over the last 15 of them of the configured way's mean residual / the other way's
  // (deskewed / raw; corrected / uncorrected).
  double residual_ratio = 0;
};

class Odometry {
 public:
  explicit Odometry(const OdometryConfig& config);
  ~Odometry();
  Odometry(const Odometry&) = delete;
  Odometry& operator=(const Odometry&) = delete;

  OdometryResult process(const Scan& scan);
  // Where the feature extraction's rings come from (a table, learned beams, the ring field).
  const RingLayoutInfo& ring_layout() const;
  // Whether scans with per-point times are deskewed now (configured, and not turned off by the
  // deskew check).
  bool deskews() const;
  const SettingCheck& deskew_check() const;
  const SettingCheck& elevation_check() const;
  // For scans without point times, deskewed: the last one's sweep as its order showed it
  // and the times it was given (when usable); nullopt before any such scan.
  const std::optional<SweepLayout>& azimuth_times() const;
  // The frames returned since some point may still be revised (OdometryResult::revised): a
  // setting check is measuring, or frame 0 waits for frame 1.
  bool may_revise() const;

  // After a loop closure the pipeline moves past keyframes: rebuild the local map from
  // (corrected pose, features) pairs and continue from `T_world_lidar_now`.
  void reset_map(const std::vector<std::pair<Eigen::Isometry3d, const FeatureCloud*>>& edges_by_pose,
                 const std::vector<std::pair<Eigen::Isometry3d, const FeatureCloud*>>& planes_by_pose,
                 const Eigen::Isometry3d& T_world_lidar_now);

 private:
  void redeskew_first_frames(const Eigen::Vector3d& omega_rad_s, const Eigen::Vector3d& velocity_m_s);
  // One frame in the odometry's own world frame (see Impl::T_out_own).
  OdometryResult process_frame(const Scan& scan);
  // A setting check's comparison of this frame's solve with the shadow odometry's (the other
  // setting); may continue as the shadow, and then makes `own` the shadow's result, with the
  // trial's earlier frames revised.
  void compare_with_shadow(const Scan& scan, OdometryResult& own, const OdometryResult& other);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scfloam
