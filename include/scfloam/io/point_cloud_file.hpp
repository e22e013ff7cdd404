// Point-cloud files users open in CloudCompare, PCL or Open3D: binary PCD (x y z intensity).
#pragma once

#include <filesystem>
#include <vector>

#include "scfloam/types.hpp"

namespace scfloam {

// PCD v0.7, DATA binary, fields x y z intensity (float32), unorganized. Written atomically.
void write_pcd_binary(const std::filesystem::path& path, const std::vector<LidarPoint>& points);

}  // namespace scfloam
