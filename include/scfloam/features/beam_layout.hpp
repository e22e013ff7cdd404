// A spinning LiDAR's beam elevations learned from one scan, for sensors whose layout none of
// the built-in ring tables describes and whose scans carry no ring field (docs/odometry.md,
// "Session 21"). Every return of one beam has the same elevation seen from the sensor origin,
// so a scan's elevation histogram is a comb of narrow peaks, one per beam.
#pragma once

#include <cstdint>
#include <vector>

#include "scfloam/features/rings.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

struct BeamLayout {
  std::vector<double> elevations_deg;  // beam centres, highest first (ring 0 = highest)
  std::vector<int> returns;            // returns per beam, same order
  int points_used = 0;                 // finite returns within the range crop
  // Share of those returns within a quarter of the gap to the next beam of their beam's
  // centre: ~1 for a sensor whose beams all start at one origin; KITTI's HDL-64E scans, whose
  // lasers sit at different heights, reach ~0.6.
  double clustered_fraction = 0;
  // Distinct, narrow beams (clustered_fraction >= 0.9, 2..kMaxLearnedBeams beams): usable as
  // a ring table. Otherwise the comb is blurred and a built-in table is the safer choice.
  bool confident = false;
};

constexpr int kMaxLearnedBeams = 128;
constexpr int kMinLayoutPoints = 2000;  // fewer usable returns: no layout is learned

// The beams of `points` with a horizontal range within [min_range_m, max_range_m]. Peaks of
// the elevation histogram (0.01 deg bins) at least 0.08 deg apart, each with ≥ 1 % of the
// median beam's returns. Empty with fewer than kMinLayoutPoints usable returns.
BeamLayout learn_beam_layout(const std::vector<LidarPoint>& points, double min_range_m,
                             double max_range_m);

// Elevation to ring for a learned layout: boundaries halfway between neighbouring beams, half
// a gap of margin beyond the outer beams; a lookup table at 0.01 deg makes it one index.
class LearnedRingTable {
 public:
  explicit LearnedRingTable(const std::vector<double>& elevations_deg);
  int beams() const { return beams_; }
  // Ring in [0, beams()), or -1 outside the layout's field of view.
  int ring(float elevation_deg) const {
    const float pos = (elevation_deg - lowest_deg_) * kBinsPerDeg;
    if (!(pos >= 0.0f) || pos >= static_cast<float>(lut_.size())) return -1;
    return lut_[static_cast<std::size_t>(pos)];
  }

 private:
  static constexpr float kBinsPerDeg = 100.0f;
  int beams_ = 0;
  float lowest_deg_ = 0;
  std::vector<std::int16_t> lut_;
};

// Whether a built-in ring table serves the learned layout: no two beams fall into one of its
// rings (in firing order their points would interleave on one "ring", a zigzag that reads as
// curvature everywhere and buries the real corners). Beams outside its field of view are only
// counted: cropping is a table's choice (F-LOAM's HDL-64E table ends at -24.33 deg and drops
// KITTI's two lowest beams), and using them measured no better (docs/odometry.md, "Session 21").
struct TableFit {
  bool fits = true;
  int merged_beams = 0;   // beams sharing a ring with another beam
  int dropped_beams = 0;  // beams outside the table's field of view
  double dropped_fraction = 0;
};
TableFit check_table_fit(LidarModel model, const BeamLayout& layout);

}  // namespace scfloam
