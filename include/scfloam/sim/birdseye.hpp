// Bird's-eye map of a sequence: scans accumulated with given poses, each cell shaded by the
// vertical extent of its points (walls, poles, trunks bright; ground dark), trajectory in red.
// Smeared or doubled walls show a bad pose; crisp one-pixel walls show consistent ones.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "scfloam/io/kitti.hpp"
#include "scfloam/types.hpp"

namespace scfloam::sim {

struct BirdseyeOptions {
  std::size_t every = 1;       // use every N-th scan
  double resolution_m = 0.1;   // metres per pixel (coarsened if the image would be too big)
  double max_range_m = 60;     // ignore points farther from the sensor
  std::size_t max_pixels = 16'000'000;
};

struct BirdseyeImage {
  int width = 0, height = 0;
  double x0 = 0, y_top = 0, resolution_m = 0.1;  // pixel (0,0) is at (x0, y_top), +x right, +y up
  std::vector<std::uint8_t> rgb;
};

// T_lidar0_lidar: one pose per scan of the sequence (lidar frame, e.g. ground_truth_lidar()).
BirdseyeImage render_birdseye(const KittiSequence& seq, const PoseList& T_lidar0_lidar,
                              const BirdseyeOptions& options, bool progress);

void write_png_rgb(const std::filesystem::path& path, int width, int height,
                   const std::vector<std::uint8_t>& rgb);

}  // namespace scfloam::sim
