// Which `--sensor` preset an input's scans call for, found from their beams, so that
// `scfloam run DATA` without --sensor does not run another sensor on the settings made for
// KITTI's HDL-64E (on a simulated VLP-16 drive that cost 19x in drift: docs/inputs.md).
#pragma once

#include <string>
#include <vector>

#include "scfloam/features/beam_layout.hpp"
#include "scfloam/features/rings.hpp"
#include "scfloam/io/scan_source.hpp"

namespace scfloam {

struct SensorGuess {
  std::string preset;  // a --sensor name: "kitti", "hdl32", "vlp16", "os1-64", "os1-128" or "auto"
  std::string reason;  // one line for the terminal: what in the scans chose it
  BeamLayout layout;   // the beams the guess was made from
};

// The built-in ring tables that describe `layout`: as many beams as the table (up to 1 in 8
// missing), no two beams in one ring, at most 1 in 20 of the table's beams outside its field
// of view; or, for the uniform fans, at least half of the fan's beams, consecutive, each within
// a fifth of the spacing of its nominal elevation (the top beams under open sky). In the order
// hdl64, hdl32, vlp16, os1-64, os1-128.
std::vector<LidarModel> matching_ring_tables(const BeamLayout& layout);

// From the beams of `points` (all returns in the sensor frame; several scans may be joined):
// - too few returns, or elevations blurred as in KITTI's HDL-64E scans (its lasers sit at
//   different heights), or an HDL-64E's layout: "kitti", the defaults;
// - a layout one of the other tables matches: that preset;
// - distinct beams no table matches: "auto" (rings from the learned beams).
SensorGuess guess_sensor(const std::vector<LidarPoint>& points);

// guess_sensor over a few of the source's first scans (0, 10, 20: beams that see nothing in
// one place are seen in another; the beams' elevations do not depend on the pose).
SensorGuess guess_sensor(const ScanSource& source);

}  // namespace scfloam
