#include "scfloam/io/sensor_detection.hpp"

#include <cmath>
#include <cstdio>

namespace scfloam {
namespace {

// The range crop of the beams' histogram: past the ego car, within any sensor's reach.
constexpr double kMinRangeM = 1.0, kMaxRangeM = 200.0;

const char* preset_of(LidarModel model) {
  switch (model) {
    case LidarModel::hdl64: return "kitti";
    case LidarModel::hdl32: return "hdl32";
    case LidarModel::vlp16: return "vlp16";
    case LidarModel::os1_64: return "os1-64";
    case LidarModel::os1_128: return "os1-128";
  }
  return "auto";
}

// A uniform fan's beams seen only in part: every learned beam within a fifth of the spacing
// of one of the fan's beams, the learned ones consecutive (what is missing is at the top or the
// bottom: open sky, the car's own body), at least half of them. A sensor with every other
// beam of a fan (an OS1-32 against the OS1-64's fan) is not consecutive and does not match.
bool is_end_cut_of_fan(LidarModel model, const std::vector<double>& elevations_deg) {
  if (model == LidarModel::hdl64) return false;  // two blocks, not a uniform fan
  const BeamFan f = beam_fan(model);
  const double spacing = (f.highest_deg - f.lowest_deg) / (f.beams - 1);
  if (static_cast<int>(elevations_deg.size()) * 2 < f.beams) return false;
  long previous = -1;
  for (double e : elevations_deg) {  // highest first
    const double pos = (f.highest_deg - e) / spacing;
    const long index = std::lround(pos);
    if (std::abs(pos - static_cast<double>(index)) > 0.2 || index < 0 || index >= f.beams) return false;
    if (previous >= 0 && index != previous + 1) return false;
    previous = index;
  }
  return true;
}

}  // namespace

std::vector<LidarModel> matching_ring_tables(const BeamLayout& layout) {
  std::vector<LidarModel> out;
  if (!layout.confident) return out;
  const int beams = static_cast<int>(layout.elevations_deg.size());
  for (LidarModel m : {LidarModel::hdl64, LidarModel::hdl32, LidarModel::vlp16, LidarModel::os1_64,
                       LidarModel::os1_128}) {
    const int n = num_beams(m);
    if (beams > n) continue;
    // Nearly all beams (up to 1 in 8 missing) in rings of their own, or a fan cut at its ends.
    const TableFit fit = check_table_fit(m, layout);
    if ((beams * 8 >= n * 7 && fit.fits && fit.dropped_beams * 20 <= n) ||
        is_end_cut_of_fan(m, layout.elevations_deg))
      out.push_back(m);
  }
  return out;
}

SensorGuess guess_sensor(const std::vector<LidarPoint>& points) {
  SensorGuess guess;
  guess.layout = learn_beam_layout(points, kMinRangeM, kMaxRangeM);
  const BeamLayout& layout = guess.layout;
  char line[256];
  if (layout.points_used < kMinLayoutPoints) {
    guess.preset = "kitti";
    std::snprintf(line, sizeof line, "only %d usable returns, too few to tell the beams: the defaults (KITTI's HDL-64E)",
                  layout.points_used);
  } else if (!layout.confident) {
    guess.preset = "kitti";
    std::snprintf(line, sizeof line,
                  "elevations blurred (%.0f %% of returns on %zu peaks), as in KITTI's HDL-64E scans: the defaults",
                  100.0 * layout.clustered_fraction, layout.elevations_deg.size());
  } else {
    const auto tables = matching_ring_tables(layout);
    guess.preset = tables.empty() ? "auto" : preset_of(tables.front());
    std::snprintf(line, sizeof line, "%zu beams, %+.2f .. %+.2f deg: %s", layout.elevations_deg.size(),
                  layout.elevations_deg.front(), layout.elevations_deg.back(),
                  tables.empty() ? "no preset's ring table matches them, rings from the learned beams"
                  : tables.front() == LidarModel::hdl64 ? "an HDL-64E, the defaults (KITTI's; its beam correction kept if the first frames fit better with it)"
                                                        : "its preset's ring table matches them");
  }
  guess.reason = line;
  return guess;
}

SensorGuess guess_sensor(const ScanSource& source) {
  std::vector<LidarPoint> points;
  for (std::size_t i : {0, 10, 20}) {
    if (i >= source.size()) break;
    const Scan scan = source.load(i);
    points.insert(points.end(), scan.points.begin(), scan.points.end());
  }
  return guess_sensor(points);
}

}  // namespace scfloam
