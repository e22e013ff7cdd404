#include "scfloam/odometry/odometry.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "scfloam/error.hpp"
#include "scfloam/features/deskew.hpp"
#include "scfloam/features/sweep_times.hpp"
#include "scfloam/features/feature_extractor.hpp"
#include "scfloam/odometry/elevation_calibration.hpp"
#include "scfloam/odometry/ground_elevation.hpp"
#include "scfloam/registration/scan_to_map.hpp"
#include "scfloam/registration/voxel_filter.hpp"
#include "scfloam/se3.hpp"
#include "scfloam/stats.hpp"

namespace scfloam {

struct Odometry::Impl {
  explicit Impl(const OdometryConfig& c)
      : config(c),
        extractor(c.preprocess, c.rings, c.features),
        map(c.registration, c.map),
        registration(c.registration),
        rounds(c.registration.outer_iterations_initial) {
    if (c.preprocess.online_elevation_calibration)
      elevation.emplace(c.preprocess.elevation_correction_deg,
                        c.preprocess.elevation_calibration_gain, 1.0);
    if (c.preprocess.ground_elevation_calibration)
      ground_elevation.emplace(c.preprocess.elevation_correction_deg);
  }

  OdometryConfig config;
  FeatureExtractor extractor;
  VoxelFilter edge_filter, plane_filter;  // one each: each sizes its table from its last call
  FeatureMap map;
  ScanToMapRegistration registration;

  std::vector<LidarPoint> deskewed;
  // Scans without point times, deskewed: times from the azimuth (PreprocessConfig::
  // deskew_times_from_azimuth), over a sweep as long as the scans' stamps are apart. What the
  // input's sweeps showed, not a setting: a switching check hands it to the shadow whole.
  struct AzimuthTimes {
    double sweep_period_s = 0.1;
    std::optional<double> last_stamp_s;
    std::vector<double> stamp_intervals;  // the last ones between stamps, for the period
    std::optional<SweepLayout> layout;    // the last such scan's
    std::optional<SweepLayout> usable;    // the last such scan's that gave times

    // The configured period, else the median of the last intervals between stamps of
    // 0.02-0.25 s (a dropped frame's longer one left out).
    void update_period(double stamp_s, double configured_s) {
      if (last_stamp_s) {
        const double interval = stamp_s - *last_stamp_s;
        const bool dropped = !stamp_intervals.empty() && interval > 1.5 * sweep_period_s;
        if (interval >= 0.02 && interval <= 0.25 && !dropped) {
          stamp_intervals.push_back(interval);
          if (stamp_intervals.size() > 21) stamp_intervals.erase(stamp_intervals.begin());
          std::vector<double> sorted = stamp_intervals;
          std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
          sweep_period_s = sorted[sorted.size() / 2];
        }
      }
      last_stamp_s = stamp_s;
      if (configured_s > 0) sweep_period_s = configured_s;
    }
  } azimuth;

  // The frame's features from these (deskewed) points: edges and the plane runs, downsampled.
  void extract_features(const std::vector<LidarPoint>& pts, bool use_rings, bool full_planes,
                        OdometryResult& result) {
    extractor.extract(pts, use_rings, raw_edges, full_planes ? &raw_planes : nullptr);
    edge_filter.filter(raw_edges, config.features.edge_leaf_m, result.edges);
    plane_filter.filter_runs(extractor.plane_runs(), result.planes);
  }
  // Frames 0 and 1 come before there is a velocity to deskew with: their raw points and poses
  // are kept so that frame 2 can put them into the map again, deskewed.
  std::vector<LidarPoint> early_points[2];
  Eigen::Isometry3d early_poses[2];
  double early_reference_s[2] = {0, 0};
  bool early_has_ring = false;
  FeatureCloud raw_edges, raw_planes;  // raw_planes: filled on the first frame only
  FeatureCloud last_edges, last_planes;  // the previous frame's features, for the coarse pass
  std::size_t frames = 0;
  int rounds;
  // Poses, motion and times are the solves' own: at each scan's reference time (its stamp, or
  // the middle of a deskewed sweep that is not centred on its stamp: sweep_reference_s).
  Eigen::Isometry3d T_last = Eigen::Isometry3d::Identity();  // T_world_lidar of frame k-1
  Eigen::Isometry3d T_delta = Eigen::Isometry3d::Identity(); // T_{k-2}^-1 T_{k-1}
  double last_time_s = 0;
  double delta_dt_s = 0;
  // The last frame's reported pose is T_last * last_to_stamp (identity when its reference
  // time was its stamp).
  Eigen::Isometry3d last_to_stamp = Eigen::Isometry3d::Identity();
  // Frame 0 solved away from its stamp, as reported: frame 1 revises its features.
  std::optional<OdometryResult> frame0_result;
  Eigen::Vector3d last_cleanup_position = Eigen::Vector3d::Zero();
  std::optional<ElevationCalibration> elevation;  // when the config estimates the offset
  std::optional<GroundElevationEstimate> ground_elevation;  // ... or takes it from the road's shape

  // The setting checks (PreprocessConfig::deskew_check, elevation_check), one trial at a
  // time: a shadow odometry runs the same scans with the setting flipped, in its own map, and
  // the per-frame ratios of the two solves' mean residuals decide.
  SettingCheck deskew_check, elevation_check;
  bool deskew_open = false, elevation_open = false;  // configured, no verdict yet
  enum class Trial { kNone, kDeskew, kElevation } trial = Trial::kNone;
  std::unique_ptr<Odometry> shadow;
  // The shadow's result for each frame it has seen: if it wins, they replace the trial's frames
  // (OdometryResult::revised). ~100 KB of features per frame, for at most 300 frames.
  std::vector<OdometryResult> shadow_results;
  std::size_t trial_frames = 0;  // frames the shadow has seen
  std::size_t check_frames = 0;  // frames since the running check began (a shadow may restart)
  // The first frame of the trial as reported (this odometry's) and in the shadow's own frame.
  std::pair<Eigen::Isometry3d, Eigen::Isometry3d> trial_start;
  std::size_t first_frame = 0;   // the caller's index of this odometry's first frame
  std::vector<double> residual_ratios;
  // This odometry's world frame in the caller's: identity, unless a check switched to the
  // shadow, whose world frame differs from the one already reported by the frames of the trial,
  // or frame 0 was solved away from its stamp (the caller's world is the sensor at that stamp).
  Eigen::Isometry3d T_out_own = Eigen::Isometry3d::Identity();
};

namespace {

// How many of the last frame's intervals have passed: 1 when stamps are missing, repeat or run
// backwards (nothing better to go on); capped at 30 (3 s at 10 Hz), beyond which constant
// velocity is a guess either way.
double interval_ratio(double last_interval_s, double interval_s) {
  if (!(last_interval_s > 0) || !(interval_s > 0)) return 1.0;
  return std::min(interval_s / last_interval_s, 30.0);
}

// SO(3)'s left Jacobian V(phi): the translation of exp([phi; v]) is V(phi) v.
Eigen::Matrix3d left_jacobian(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  if (angle < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * K;
  return Eigen::Matrix3d::Identity() + (1 - std::cos(angle)) / (angle * angle) * K +
         (angle - std::sin(angle)) / (angle * angle * angle) * K * K;
}

// A constant twist: exp(ratio * log(T_delta)) on SE(3), so a turning car follows the arc
// (scaling the chord instead puts the end of a 1 s turn a metre to the side). Any real ratio,
// negative ones going back in time.
Eigen::Isometry3d motion_at_same_twist(const Eigen::Isometry3d& T_delta, double ratio) {
  const Eigen::Vector3d phi = so3_log(T_delta.linear());
  const Eigen::Vector3d v = left_jacobian(phi).inverse() * T_delta.translation();
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = so3_exp(ratio * phi);
  out.translation() = left_jacobian(ratio * phi) * (ratio * v);
  return out;
}

// The relative motion `T_delta` continued for `ratio` intervals at the same body-frame velocity.
Eigen::Isometry3d scaled_motion(const Eigen::Isometry3d& T_delta, double ratio) {
  // Regular frames keep exactly the last motion: recorded stamps jitter by a few ms (KITTI's
  // times.txt does) while the spin period does not, so only a clear change (a dropped frame,
  // a rate change) is worth following.
  if (ratio > 1.0 / 1.5 && ratio < 1.5) return T_delta;
  return motion_at_same_twist(T_delta, ratio);
}

// A frame's features re-expressed in the sensor frame `to_stamp` away (the same world points
// under the pose moved by it).
void move_features_to(OdometryResult& result, const Eigen::Isometry3d& to_stamp) {
  const Eigen::Isometry3f stamp_from_solve = to_stamp.inverse().cast<float>();
  for (FeatureCloud* cloud : {&result.edges, &result.planes})
    for (auto& pt : *cloud) pt = stamp_from_solve * pt;
}

// The time, relative to the stamp, at which a deskewed scan is solved: the middle of its
// sweep. Drivers stamp a sweep at its start (Ouster, Hesai: times 0 ... 0.1 s), its end
// (Velodyne's ROS driver: -0.1 ... 0) or its middle (our simulator, KITTI). Deskewing to an end
// puts the points half a sweep from their own times, and the velocity of the last two solves,
// wrong by some small amount, then moves the whole scan by that error times 0.05 s; the solve
// takes the shift into the pose, the next velocity into the next deskew, and the error grows
// from frame to frame (measured: 64 % t_err on bench/foreign_world.py's sweeps, docs/odometry.md,
// "Session 36"). Solved at the middle, an error of the velocity bends the scan symmetrically
// and moves no pose. A sweep centred on its stamp to 1 % of its span keeps the stamp.
double sweep_reference_s(const std::vector<LidarPoint>& points) {
  if (points.empty()) return 0;
  float t_min = points.front().time_s, t_max = t_min;
  for (const LidarPoint& pt : points) t_min = std::min(t_min, pt.time_s), t_max = std::max(t_max, pt.time_s);
  const double middle = 0.5 * (double(t_min) + double(t_max));
  return std::abs(middle) <= 0.01 * (double(t_max) - double(t_min)) ? 0.0 : middle;
}

// The scan aligned to the previous frame alone with a wide search radius, from `T_pred`: the
// local map's radius (max_neighbor_dist_m, ~1 m) is the basin of the fine solve, and the guess
// made without a velocity (frame 1 starts from standing still; a car at 12 m/s is 1.2 m on)
// can lie outside it. Wide matches are coarse, so only the start of the fine solve comes from
// here.
Eigen::Isometry3d coarse_alignment(const OdometryConfig& c, const FeatureCloud& last_edges,
                                   const FeatureCloud& last_planes,
                                   const Eigen::Isometry3d& T_world_last,
                                   const OdometryResult& frame, const Eigen::Isometry3d& T_pred) {
  if (!(c.registration.coarse_neighbor_dist_m > c.registration.max_neighbor_dist_m))
    return T_pred;
  RegistrationConfig coarse = c.registration;
  coarse.max_neighbor_dist_m = c.registration.coarse_neighbor_dist_m;
  // The guess is poor everywhere, so the matches decide wherever they say anything; where
  // they say nothing (less than one match's worth of information: a walk starting along a
  // single wall), the cost is flat and the solve would wander, and the rest of a drive that
  // stays that way would keep the wandered velocity: the guess is kept there.
  coarse.degeneracy_fallback = true;
  coarse.degeneracy_min_eigenvalue = coarse.degeneracy_min_rotation_eigenvalue = 1.0;
  coarse.degeneracy_min_translation_ratio = coarse.degeneracy_min_rotation_ratio = 0;
  coarse.degeneracy_prior_translation_weight = coarse.degeneracy_prior_rotation_weight = 0;
  coarse.edge_max_residual_m = 0;  // the start may be a metre off: every line within reach counts
  coarse.edge_view_tolerance_deg = 0;
  LocalMapConfig coarse_map = c.map;
  // Cells are the search radius wide: keep the density of the fine map's cells.
  const double area_ratio = std::pow(coarse.max_neighbor_dist_m / c.registration.max_neighbor_dist_m, 2);
  coarse_map.max_points_per_cell = static_cast<int>(std::ceil(c.map.max_points_per_cell * area_ratio));
  FeatureMap map(coarse, coarse_map);
  map.insert(last_edges, last_planes, T_world_last);
  ScanToMapRegistration registration(coarse);
  return registration
      .align(frame.edges, frame.planes, map, T_pred, c.registration.outer_iterations_initial)
      .T_world_lidar;
}

}  // namespace

Odometry::Odometry(const OdometryConfig& config) : impl_(std::make_unique<Impl>(config)) {
  const auto& p = config.preprocess;
  if (!(p.min_range_m >= 0) || !(p.max_range_m > p.min_range_m))
    throw Error("odometry config: need 0 <= min_range_m < max_range_m");
  if (config.registration.outer_iterations < 1 || config.registration.inner_iterations < 1)
    throw Error("odometry config: outer_iterations and inner_iterations must be >= 1");
  if (p.online_elevation_calibration && !(p.elevation_calibration_gain > 0 && p.elevation_calibration_gain <= 5))
    throw Error("odometry config: elevation_calibration_gain must be in (0, 5]");
  sweep_stamp_fraction(p.sweep_stamp);  // throws on anything but start, middle, end
  if (p.online_elevation_calibration && p.ground_elevation_calibration)
    throw Error("odometry config: online_elevation_calibration and ground_elevation_calibration both "
                "estimate the elevation correction: choose one");
}

Odometry::~Odometry() = default;

const RingLayoutInfo& Odometry::ring_layout() const { return impl_->extractor.ring_layout(); }

const SettingCheck& Odometry::deskew_check() const { return impl_->deskew_check; }
bool Odometry::deskews() const { return impl_->config.preprocess.deskew; }
const std::optional<SweepLayout>& Odometry::azimuth_times() const {
  return impl_->azimuth.usable ? impl_->azimuth.usable : impl_->azimuth.layout;
}
const SettingCheck& Odometry::elevation_check() const { return impl_->elevation_check; }
bool Odometry::may_revise() const { return impl_->trial != Impl::Trial::kNone || impl_->frame0_result; }

OdometryResult Odometry::process(const Scan& scan) {
  Impl& s = *impl_;
  const PreprocessConfig& p = s.config.preprocess;
  if (p.deskew && p.deskew_times_from_azimuth && !scan.has_time) {
    Stopwatch timing;  // the times are part of the frame's feature step
    Impl::AzimuthTimes& az = s.azimuth;
    az.update_period(scan.timestamp_s, p.sweep_period_s);
    Scan timed = scan;
    const double stamp_fraction = sweep_stamp_fraction(p.sweep_stamp);
    // The last usable scan's seam serves where this one's is unclear (drivers cut at a fixed
    // azimuth).
    az.layout = assign_times_from_azimuth(timed.points, az.sweep_period_s, stamp_fraction,
                                          az.usable ? &*az.usable : nullptr);
    if (az.layout->usable) az.usable = az.layout;
    if (az.usable) {
      // A scan whose order gave no times, in a drive whose scans do: all its points at the
      // sweep's middle (a rigid sweep), so that its solve stays at the middle as its
      // neighbours' do (solved at the stamp instead, a start- or end-stamped drive's motion
      // would be measured over half an interval).
      if (!az.layout->usable)
        for (LidarPoint& pt : timed.points) pt.time_s = static_cast<float>((0.5 - stamp_fraction) * az.sweep_period_s);
      timed.has_time = true;
      const double times_ms = timing.elapsed_ms();
      OdometryResult result = process(timed);
      result.features_ms += times_ms;
      return result;
    }
  }
  if (s.frames == 0) {
    if (p.deskew) {
      s.deskew_check.verdict = p.deskew_check ? "no per-point times" : "unchecked";
      s.deskew_open = p.deskew_check;
    }
    // The online estimators move the correction themselves.
    if (p.elevation_correction_deg != 0 && !p.online_elevation_calibration && !p.ground_elevation_calibration) {
      s.elevation_check.verdict = p.elevation_check ? "waiting" : "unchecked";
      s.elevation_open = p.elevation_check;
    }
  }
  // A trial runs to its verdict; the deskew check goes first (on timed scans), since whether
  // the scans are distorted changes every residual the elevation check compares.
  if (s.trial == Impl::Trial::kNone) {
    if (s.deskew_open && scan.has_time) s.trial = Impl::Trial::kDeskew;
    else if (s.elevation_open) s.trial = Impl::Trial::kElevation;
    s.check_frames = 0;
  }
  OdometryResult other;
  if (s.trial != Impl::Trial::kNone) {
    if (!s.shadow) {
      OdometryConfig flipped = s.config;
      flipped.preprocess.deskew_check = flipped.preprocess.elevation_check = false;
      if (s.trial == Impl::Trial::kDeskew) {
        flipped.preprocess.deskew = false;
        s.deskew_check.verdict = "trial";
      } else {
        flipped.preprocess.elevation_correction_deg = 0;
        s.elevation_check.verdict = "trial";
      }
      s.shadow = std::make_unique<Odometry>(flipped);
      s.shadow_results.clear();
      s.trial_frames = 0;
    }
    other = s.shadow->process(scan);
    // The shadow's own revisions (its frame 0) replace what it returned before.
    for (std::size_t i = 0; i < other.revised.size(); ++i)
      s.shadow_results.at(s.shadow_results.size() - other.revised.size() + i) = std::move(other.revised[i]);
    other.revised.clear();
    ++s.trial_frames;
    ++s.check_frames;
  }
  OdometryResult result = process_frame(scan);
  result.T_world_lidar = s.T_out_own * result.T_world_lidar;
  if (s.trial != Impl::Trial::kNone) {
    // The trial's cost shows in the frame's timings.
    result.features_ms += other.features_ms;
    result.registration_ms += other.registration_ms;
    if (s.trial_frames == 1) s.trial_start = {result.T_world_lidar, other.T_world_lidar};
    s.shadow_results.push_back(other);
    compare_with_shadow(scan, result, other);  // may replace impl_ (and `s` with it)
  }
  return result;
}

void Odometry::compare_with_shadow(const Scan& scan, OdometryResult& own, const OdometryResult& other) {
  Impl& s = *impl_;
  const bool deskew = s.trial == Impl::Trial::kDeskew;
  SettingCheck& check = deskew ? s.deskew_check : s.elevation_check;
  // Only frames in motion tell the two apart. Deskew: how far the sweep's points move while it
  // lasts, 0.2 m at 2 m/s; a turn moves them too, by their range times its angle (a hand-held
  // walk, 1.4 m/s, sways 0.03-0.08 rad per sweep: until session 41 it was never "in motion",
  // and its check ran 300 frames of a second odometry, undecided). Elevation: a wrong offset
  // lifts a point by its range times the error, so it shows where a surface is seen from two
  // places at different ranges: 0.2 m between frames, turns do not count.
  double moved_m = s.T_delta.translation().norm();
  if (deskew) {
    float t_min = 0, t_max = 0;
    double range_sum = 0;
    std::size_t ranged = 0;
    for (const LidarPoint& pt : scan.points) {
      t_min = std::min(t_min, pt.time_s), t_max = std::max(t_max, pt.time_s);
      const double r = std::sqrt(double(pt.x) * pt.x + double(pt.y) * pt.y + double(pt.z) * pt.z);
      if (std::isfinite(r)) range_sum += r, ++ranged;
    }
    const double mean_range_m = ranged > 0 ? range_sum / static_cast<double>(ranged) : 0.0;
    moved_m += so3_log(s.T_delta.linear()).norm() * mean_range_m;
    moved_m = s.delta_dt_s > 0 ? moved_m / s.delta_dt_s * (t_max - t_min) : 0.0;
  }
  const bool solved = !own.degenerate && !other.degenerate && own.mean_residual_m > 0 && other.mean_residual_m > 0;
  // From the shadow's fifth frame: the first ones match maps of one or two scans.
  if (s.trial_frames > 5 && solved && moved_m >= 0.2)
    s.residual_ratios.push_back(own.mean_residual_m / other.mean_residual_m);
  // The two maps grow apart as each takes in its own version of the scans, so the latest
  // frames say most: of the last 15 compared, 13 must agree on which fits better, and their
  // median ratio must be off 1 by 5 % (10 % to keep deskew, below).
  constexpr std::size_t kWindow = 15, kAgree = 13;
  const std::size_t n = s.residual_ratios.size();
  check.frames_compared = n;
  if (n > 0)
    check.residual_ratio = summarize(std::vector<double>(s.residual_ratios.end() - std::min(n, kWindow),
                                                         s.residual_ratios.end())).median;
  const auto decide = [&](const char* verdict) {
    check.verdict = verdict;
    check.decided = true;
    check.decided_at_frame = s.first_frame + s.frames - 1;
    (deskew ? s.deskew_open : s.elevation_open) = false;
  };
  // Decided, or given up, keeping this odometry's setting.
  const auto close = [&](const char* verdict) {
    decide(verdict);
    s.trial = Impl::Trial::kNone;
    s.shadow.reset();
    std::vector<OdometryResult>().swap(s.shadow_results);
    std::vector<double>().swap(s.residual_ratios);
  };
  const auto own_better = static_cast<std::size_t>(
      std::count_if(s.residual_ratios.end() - std::min(n, kWindow), s.residual_ratios.end(), [](double r) { return r < 1; }));
  // Keeping deskew needs a wider margin: on straight, steady driving a compensated sweep
  // deskewed is sheared little, and both kinds of scans gave median ratios of 0.93-0.95 there
  // (HDL-32E / VLP-16 worlds of seed 11: compensated, kept deskewed at frame ~30, and the turns
  // then failed, 0.66 / 0.64 % t_err); turns mostly tell them apart (0.47-0.90 for five
  // distorted drives after 100 compared frames, > 1.05 for compensated ones). Staying
  // undecided keeps deskew anyway; a compensated drive that does not turn while the check runs
  // stays deskewed, as before (docs/odometry.md, "Session 39").
  const double keep_below = deskew ? 0.9 : 0.95;
  const bool keep = n >= kWindow && own_better >= kAgree && check.residual_ratio < keep_below;
  const bool flip = n >= kWindow && kWindow - own_better >= kAgree && check.residual_ratio > 1.05;
  // Undecided after 100 compared frames, or after 300 frames of the check (hardly any motion,
  // times that span nothing, ratios near 1): the setting changes little here, and the second
  // odometry's cost is not worth carrying further.
  if (keep || (!flip && (n >= 100 || s.check_frames >= 300))) {
    close(!keep ? "undecided" : deskew ? "distorted" : "offset");
    return;
  }
  if (!flip) return;
  // The other setting fits better. Continue as the shadow (world frame below); the checks'
  // records (and any check still to run) come along.
  decide(deskew ? "compensated" : "no offset");
  const SettingCheck deskew_record = s.deskew_check, elevation_record = s.elevation_check;
  const bool deskew_open = s.deskew_open, elevation_open = s.elevation_open;
  // The shadow's track is the better one since the trial began (this odometry's carries what
  // the trial frames' setting did to it: with a wrong elevation offset, a tilt that would stay
  // for the rest of the drive), so its world frame is put where this odometry was at the
  // trial's first frame, and its results replace the trial's: the reported track is the one
  // the winning setting would have made from that frame on, continuous at its start. (Until
  // session 34 the trial's frames stayed as reported and the position continued from this
  // frame's; the keyframes cut from them carried the losing setting's features.)
  const Eigen::Isometry3d T_out_other =
      orthonormalized(s.trial_start.first * s.trial_start.second.inverse());
  std::vector<OdometryResult> revised = std::move(s.shadow_results);
  for (OdometryResult& r : revised) r.T_world_lidar = T_out_other * r.T_world_lidar;
  OdometryResult switched = std::move(revised.back());  // this frame's
  revised.pop_back();
  switched.features_ms = own.features_ms;  // both solves ran on this frame
  switched.registration_ms = own.registration_ms;
  switched.revised = std::move(revised);
  own = std::move(switched);
  // The caller's index of the shadow's first frame (it started with the trial).
  const std::size_t first_frame = s.first_frame + s.frames - s.trial_frames;
  std::unique_ptr<Odometry> shadow = std::move(s.shadow);
  std::swap(impl_, shadow->impl_);
  Impl& now = *impl_;
  now.deskew_check = deskew_record;
  now.elevation_check = elevation_record;
  now.deskew_open = deskew_open;
  now.elevation_open = elevation_open;
  now.first_frame = first_frame;
  // What the scans' times from the azimuth were read with (the shadow saw timed scans only).
  now.azimuth = std::move(shadow->impl_->azimuth);
  now.T_out_own = T_out_other * now.T_out_own;  // the shadow's own frame may have moved (frame 0)
  // `shadow` now holds this odometry's former state, released here.
}

OdometryResult Odometry::process_frame(const Scan& scan) {
  Impl& s = *impl_;
  const OdometryConfig& c = s.config;
  OdometryResult result;
  Stopwatch watch;

  const std::vector<LidarPoint>* points = &scan.points;
  const bool deskew = c.preprocess.deskew && scan.has_time;
  double redeskew_features_ms = 0;
  // The solve's time: the stamp, or the middle of a deskewed sweep (sweep_reference_s); the
  // reported pose and features are moved back to the stamp at the end.
  const double reference_s = deskew ? sweep_reference_s(scan.points) : 0.0;
  const double time_s = scan.timestamp_s + reference_s;
  // Constant velocity from the last two poses, in the sensor's body frame: what the sweep is
  // deskewed with (and what a second deskew compares the frame's own solve against).
  const bool deskewed_at_last_velocity = deskew && s.frames >= 2 && s.delta_dt_s > 0;
  Eigen::Vector3d omega_used = Eigen::Vector3d::Zero(), velocity_used = Eigen::Vector3d::Zero();
  if (deskewed_at_last_velocity) {
    omega_used = so3_log(s.T_delta.linear()) / s.delta_dt_s;
    velocity_used = s.T_delta.translation() / s.delta_dt_s;
    if (s.frames == 2) redeskew_first_frames(omega_used, velocity_used);
    s.deskewed = scan.points;
    deskew_constant_velocity(s.deskewed, omega_used, velocity_used, reference_s);
    points = &s.deskewed;
  }
  if (deskew && s.frames < 2) {
    s.early_points[s.frames] = scan.points;
    s.early_reference_s[s.frames] = reference_s;
    s.early_has_ring = scan.has_ring && c.rings.use_ring_field;
  }
  result.elevation_correction_deg = s.elevation          ? s.elevation->correction_deg()
                                    : s.ground_elevation ? s.ground_elevation->correction_deg()
                                                         : c.preprocess.elevation_correction_deg;
  // Only the first frame needs its planes at full density (below); the others' planes are
  // downsampled from the runs the extractor summed per ring.
  const bool use_rings = scan.has_ring && c.rings.use_ring_field;
  s.extract_features(*points, use_rings, s.frames == 0, result);
  result.features_ms = watch.elapsed_ms();
  watch.restart();

  if (s.frames == 0) {
    result.T_world_lidar = Eigen::Isometry3d::Identity();
  } else {
    // Constant-velocity prediction T_k = T_{k-1} (T_{k-2}^-1 T_{k-1})^r, kept on SO(3), where
    // r = this frame's interval over the last one: after dropped frames (a 1 s gap) the car
    // has moved ten intervals' worth, and the map match only pulls in a good guess.
    const double ratio =
        interval_ratio(s.frames >= 2 ? s.delta_dt_s : 0.0, time_s - s.last_time_s);
    const Eigen::Isometry3d T_pred = orthonormalized(s.T_last * scaled_motion(s.T_delta, ratio));
    // After a gap the prediction is extrapolated over many intervals: give the frame the
    // first frame's rounds, and since a speed change over the gap can put the guess beyond
    // the fine solve's ~1.5 m basin (where it settles in a false minimum), solve from the
    // extrapolation with the motion scaled by 0.6 ... 1.4 as well and keep the alignment with
    // the smallest mean residual (measured on the gap scene: 0.06 m at the truth, >= 0.1 m in
    // a false minimum 1.5-2 m off).
    const bool gap = ratio >= 1.5;
    if (gap) s.rounds = std::max(s.rounds, c.registration.outer_iterations_initial);
    const Eigen::Isometry3d T_start =
        s.frames == 1 ? coarse_alignment(c, s.last_edges, s.last_planes, s.T_last, result, T_pred)
                      : T_pred;
    // The fallback trusts the prediction along weak directions; an extrapolation over r
    // intervals is ~r^2 times less certain (velocity error x time), so over a gap a direction
    // is weak only when its condition ratio is that much smaller, and the prediction's weight
    // there (inverse variance) is r^4 times smaller.
    std::unique_ptr<ScanToMapRegistration> gap_registration;
    if (gap) {
      RegistrationConfig relaxed = c.registration;
      relaxed.degeneracy_min_translation_ratio /= ratio * ratio;
      relaxed.degeneracy_min_rotation_ratio /= ratio * ratio;
      relaxed.degeneracy_prior_translation_weight /= std::pow(ratio, 4);
      relaxed.degeneracy_prior_rotation_weight /= std::pow(ratio, 4);
      gap_registration = std::make_unique<ScanToMapRegistration>(relaxed);
    }
    ScanToMapRegistration& registration = gap ? *gap_registration : s.registration;
    RegistrationResult reg =
        registration.align(result.edges, result.planes, s.map, T_start, s.rounds);
    if (gap) {
      // Over the gap the car may have changed speed and turned more or less than the last
      // interval said: candidate twists with the translation scaled and the turn (about the
      // sensor's z) changed, each solved, the smallest mean residual kept.
      const Eigen::Vector3d phi = so3_log(s.T_delta.linear());
      const Eigen::Vector3d v = left_jacobian(phi).inverse() * s.T_delta.translation();
      const auto matched = [](const RegistrationResult& r) {
        return r.edge_matches + r.plane_matches >= 10;
      };
      for (double scale : {1.0, 0.8, 1.2})
        for (double turn_rad : {0.0, -0.1, 0.1, -0.2, 0.2}) {
          if (scale == 1.0 && turn_rad == 0.0) continue;  // the prediction, solved above
          const Eigen::Vector3d phi_try = ratio * phi + Eigen::Vector3d(0, 0, turn_rad);
          Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
          motion.linear() = so3_exp(phi_try);
          motion.translation() = left_jacobian(phi_try) * (ratio * scale * v);
          RegistrationResult other = registration.align(result.edges, result.planes, s.map,
                                                        orthonormalized(s.T_last * motion), s.rounds);
          if (matched(other) && (!matched(reg) || other.mean_residual_m < reg.mean_residual_m))
            reg = other;
        }
    }
    // The sweep was deskewed at the last interval's velocity. Where the motion changed over
    // this interval (a turn starting or ending, a robot's spin, a hand-held sensor, hard
    // braking), the sweep keeps the difference as distortion: at 4 deg per frame of change
    // the solve fails (docs/odometry.md, "Session 38"). Deskewed again at the velocity just
    // solved and solved once more from there.
    const double interval_s = time_s - s.last_time_s;
    if (deskewed_at_last_velocity && interval_s > 0 && !gap && c.preprocess.redeskew) {
      const Eigen::Isometry3d solved = s.T_last.inverse() * reg.T_world_lidar;
      const Eigen::Vector3d omega = so3_log(solved.linear()) / interval_s;
      const Eigen::Vector3d velocity = solved.translation() / interval_s;
      // What the difference moves a point at the sweep's ends (a sweep lasts about an interval).
      const double half_sweep_s = 0.5 * interval_s;
      if ((omega - omega_used).norm() * half_sweep_s > c.preprocess.redeskew_min_rotation_deg * M_PI / 180 ||
          (velocity - velocity_used).norm() * half_sweep_s > c.preprocess.redeskew_min_translation_m) {
        Stopwatch again;
        s.deskewed = scan.points;
        deskew_constant_velocity(s.deskewed, omega, velocity, reference_s);
        s.extract_features(s.deskewed, use_rings, false, result);
        const double again_ms = again.elapsed_ms();
        result.features_ms += again_ms;
        redeskew_features_ms = again_ms;  // counted in features, not in registration
        reg = registration.align(result.edges, result.planes, s.map, reg.T_world_lidar, s.rounds);
        result.redeskewed = true;
      }
    }
    result.T_world_lidar = orthonormalized(reg.T_world_lidar);
    result.degenerate = reg.degenerate;
    result.registration_rounds = reg.rounds;
    result.edge_matches = reg.edge_matches;
    result.plane_matches = reg.plane_matches;
    result.mean_residual_m = reg.mean_residual_m;
    result.min_translation_eigenvalue = reg.translation_eigenvalues[0];
    result.min_rotation_eigenvalue = reg.rotation_eigenvalues[0];
    result.translation_eigenvalues = reg.translation_eigenvalues;
    result.rotation_eigenvalues = reg.rotation_eigenvalues;
    result.weak_directions =
        reg.fallback_applied ? reg.weak_rotation_dirs + reg.weak_translation_dirs : 0;
    s.rounds = std::max(c.registration.outer_iterations, s.rounds - 1);
    // Not after a gap (an extrapolated start, a candidate search), nor in the first frames,
    // whose map is one or two scans, nor on a degenerate solve: where the pose is weak along
    // some direction, the offset takes up whatever that direction leaves (an open field:
    // 2.9 % t_err became 16 % before this test).
    if (s.elevation && !gap && !result.degenerate && s.frames >= 5) {
      s.extractor.set_elevation_correction_deg(
          s.elevation->update(registration.plane_matches(), result.T_world_lidar));
    }
    s.T_delta = orthonormalized(s.T_last.inverse() * result.T_world_lidar);
    // The road in this scan (raw points, before any correction) against a scan 6-30 m back.
    if (s.ground_elevation && !gap && !result.degenerate)
      s.extractor.set_elevation_correction_deg(
          s.ground_elevation->update(*points, result.T_world_lidar, s.T_delta.translation()));
    s.delta_dt_s = time_s - s.last_time_s;
  }
  // The first frame seeds the map with its full-density features: frame 1 starts from a
  // zero-velocity guess, often 1 m off, and a map of one downsampled frame is too sparse to
  // pull it in (docs/odometry.md, "First frame").
  if (s.frames == 0) s.map.insert(s.raw_edges, s.raw_planes, result.T_world_lidar);
  else s.map.insert(result.edges, result.planes, result.T_world_lidar);
  s.last_edges.assign(s.frames == 0 ? s.raw_edges.begin() : result.edges.begin(),
                      s.frames == 0 ? s.raw_edges.end() : result.edges.end());
  s.last_planes.assign(s.frames == 0 ? s.raw_planes.begin() : result.planes.begin(),
                       s.frames == 0 ? s.raw_planes.end() : result.planes.end());
  // Dropping far cells walks the whole map: do it every 10 m of travel, not every frame.
  const Eigen::Vector3d position = result.T_world_lidar.translation();
  if ((position - s.last_cleanup_position).norm() > 10.0) {
    s.map.remove_far(position, c.map.radius_m);
    s.last_cleanup_position = position;
  }
  if (s.frames < 2) s.early_poses[s.frames] = result.T_world_lidar;
  s.T_last = result.T_world_lidar;
  s.last_time_s = time_s;
  // Solved away from the stamp: report the pose at the stamp, at the velocity just solved,
  // and the features in the sensor frame there (the same points in the world). Frame 0 has
  // no velocity yet: it was reported (the identity) where it was solved; with frame 1's
  // velocity the reported world becomes the sensor frame at frame 0's stamp, and frame 0's
  // result is revised with its features there (the pipeline holds frame 0 until then).
  s.last_to_stamp = Eigen::Isometry3d::Identity();
  if (s.frames == 1 && s.frame0_result) {
    s.frame0_result->T_world_lidar = s.T_out_own * s.frame0_result->T_world_lidar;  // as reported
    if (s.delta_dt_s > 0) {
      const Eigen::Isometry3d frame0_to_stamp =
          motion_at_same_twist(s.T_delta, -s.early_reference_s[0] / s.delta_dt_s);
      s.T_out_own = s.T_out_own * frame0_to_stamp.inverse();
      // Frame 0's pose (the identity) now means its stamp; its features move there too.
      move_features_to(*s.frame0_result, frame0_to_stamp);
    }
    result.revised.push_back(std::move(*s.frame0_result));
    s.frame0_result.reset();
  }
  if (reference_s != 0 && s.frames >= 1 && s.delta_dt_s > 0) {
    s.last_to_stamp = motion_at_same_twist(s.T_delta, -reference_s / s.delta_dt_s);
    result.T_world_lidar = orthonormalized(result.T_world_lidar * s.last_to_stamp);
    move_features_to(result, s.last_to_stamp);
  }
  if (s.frames == 0 && reference_s != 0) s.frame0_result = result;
  ++s.frames;
  result.registration_ms = watch.elapsed_ms() - redeskew_features_ms;
  return result;
}

// The map holds frames 0 and 1 as they were scanned, smeared by the motion during each sweep;
// being the first points in their cells, they would stay while later, deskewed frames are
// turned away from full cells, and the next frames match against the smear (a 1-2 cm
// transient on a distorted drive, docs/odometry.md). Once frame 1 gives a velocity, the map
// is rebuilt from both frames deskewed with it (the car is assumed to have moved the same way
// during the two sweeps), at their estimated poses.
void Odometry::redeskew_first_frames(const Eigen::Vector3d& omega_rad_s,
                                     const Eigen::Vector3d& velocity_m_s) {
  Impl& s = *impl_;
  if (s.early_points[0].empty() || s.early_points[1].empty()) return;
  s.map.clear();
  FeatureCloud edges, planes;
  for (int k = 0; k < 2; ++k) {
    std::vector<LidarPoint>& points = s.early_points[k];
    deskew_constant_velocity(points, omega_rad_s, velocity_m_s, s.early_reference_s[k]);
    s.extractor.extract(points, s.early_has_ring, s.raw_edges, k == 0 ? &s.raw_planes : nullptr);
    if (k == 0) {
      // As on the first pass: frame 0 goes in at full density (see process()).
      s.map.insert(s.raw_edges, s.raw_planes, s.early_poses[0]);
    } else {
      s.edge_filter.filter(s.raw_edges, s.config.features.edge_leaf_m, edges);
      s.plane_filter.filter_runs(s.extractor.plane_runs(), planes);
      s.map.insert(edges, planes, s.early_poses[1]);
    }
    std::vector<LidarPoint>().swap(points);  // not needed again
  }
}

void Odometry::reset_map(
    const std::vector<std::pair<Eigen::Isometry3d, const FeatureCloud*>>& edges_by_pose,
    const std::vector<std::pair<Eigen::Isometry3d, const FeatureCloud*>>& planes_by_pose,
    const Eigen::Isometry3d& T_world_lidar_now) {
  Impl& s = *impl_;
  // A trial compares two maps grown alike; this one is now rebuilt from the keyframes (thinned,
  // corrected), the shadow's is not. Its shadow starts again, with the next frame. (The
  // pipeline defers rebuilds while it holds a trial's frames: this is for other callers.)
  if (s.shadow) {
    s.shadow.reset();
    s.shadow_results.clear();
    s.residual_ratios.clear();
  }
  s.map.clear();
  static const FeatureCloud kEmpty;
  const Eigen::Isometry3d T_own_out = s.T_out_own.inverse();  // the caller's poses in our frame
  for (const auto& [T, cloud] : edges_by_pose) s.map.insert(cloud ? *cloud : kEmpty, kEmpty, T_own_out * T);
  for (const auto& [T, cloud] : planes_by_pose) s.map.insert(kEmpty, cloud ? *cloud : kEmpty, T_own_out * T);
  // Keep the current velocity: T_delta is relative, so it survives the correction unchanged.
  // The caller's pose is at the last stamp; ours at the last solve's time.
  s.T_last = orthonormalized(T_own_out * T_world_lidar_now * s.last_to_stamp.inverse());
  s.map.remove_far(s.T_last.translation(), s.config.map.radius_m);
  s.last_cleanup_position = s.T_last.translation();
}

}  // namespace scfloam
