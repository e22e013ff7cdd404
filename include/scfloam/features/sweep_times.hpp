// Per-point times of a spinning LiDAR's sweep from the points' azimuths, for scans whose
// source gives none (KITTI-style .bin files, older Velodyne drivers, exported PCD folders):
// without times a motion-distorted sweep cannot be deskewed.
#pragma once

#include <string>
#include <vector>

#include "scfloam/features/fast_atan.hpp"  // fast_atan2, one per point of every scan
#include "scfloam/types.hpp"

namespace scfloam {

// How a cloud's point order lays out its sweep.
struct SweepLayout {
  bool usable = false;
  std::string why;             // when not usable: what the order did not show
  bool clockwise = true;       // seen from above (as the simulator and bench/foreign_world.py turn)
  bool ring_major = false;     // each beam's whole revolution in turn (else column by column)
  double seam_rad = 0;         // azimuth (atan2(y, x)) where the sweep starts and ends
  double direction_agreement = 0;  // share of one beam's consecutive steps in that direction
  // The order is one sweep's, but this scan does not show where it starts (few beams return on
  // both sides of the seam).
  bool seam_unclear = false;
  // How far from the seam a point may belong to either end of its revolution.
  double seam_margin_rad = 0;
  bool seam_from_earlier = false;  // this scan's seam was unclear: an earlier scan's is used
  // The times assign_times_from_azimuth gave: the sweep's period and where in it the stamp is.
  double sweep_period_s = 0, stamp_fraction = 0;
};

// Reads the sweep from the order of the points: the direction from consecutive points of one
// beam, the seam from where the order starts (column by column) or from where it passes from
// one beam to the next (beam by beam: every beam starts at the seam). Needs the order the
// sensor fired in, as drivers and KITTI's files keep it; a cloud that was sorted or filtered
// out of order is refused.
SweepLayout sweep_layout(const std::vector<LidarPoint>& points);

// Sets every point's time_s to its place in the sweep, (fraction - stamp_fraction) *
// sweep_period_s, fraction 0 at the seam where the sweep starts: times from the scan's stamp
// when the stamp is that far into the sweep (0 start, 0.5 middle as KITTI and the simulator,
// 1 end). Returns the layout; points are untouched when it is not usable. A driver cuts its
// sweeps at a fixed azimuth: where this scan's seam is unclear (few beams return on both sides
// of it) but its order turns as `earlier` (a usable layout of the same source) says, that
// seam is used.
SweepLayout assign_times_from_azimuth(std::vector<LidarPoint>& points, double sweep_period_s,
                                      double stamp_fraction = 0.5, const SweepLayout* earlier = nullptr);

// "start", "middle", "end" -> 0, 0.5, 1; anything else throws scfloam::Error.
double sweep_stamp_fraction(const std::string& stamp);

}  // namespace scfloam
