// Single point-cloud files: PCD (ascii, binary, binary_compressed) and PLY (ascii, binary
// little/big endian) read with any field layout; the formats this project writes.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "scfloam/io/point_fields.hpp"
#include "scfloam/types.hpp"

namespace scfloam {

// One file as read: the scan (non-finite points dropped) and what the file declared.
struct PointCloudFile {
  Scan scan;
  std::vector<CloudField> fields;  // as declared, offsets within one packed point
  std::string format;              // "PCD binary_compressed", "PLY binary_big_endian", ...
  std::size_t declared_points = 0; // points in the file, including dropped NaN ones
};

enum class PcdEncoding { kAscii, kBinary, kBinaryCompressed };
enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

// Error naming the file and the problem (bad header, truncated data, corrupt compression).
PointCloudFile read_pcd(const std::filesystem::path& path);
PointCloudFile read_ply(const std::filesystem::path& path);
// By extension: .pcd, .ply or .bin (KITTI float32 x y z reflectance).
PointCloudFile read_point_cloud_file(const std::filesystem::path& path);

// Fields x y z intensity (float32), plus ring (uint16) and time (float32, s) when `with_ring_time`.
// Unorganized (HEIGHT 1). Written atomically.
void write_pcd(const std::filesystem::path& path, const std::vector<LidarPoint>& points,
               PcdEncoding encoding, bool with_ring_time = false);
// Vertex element with float x y z intensity. Written atomically.
void write_ply(const std::filesystem::path& path, const std::vector<LidarPoint>& points,
               PlyEncoding encoding);

// The whole file as bytes; Error naming the file when it cannot be read.
std::string read_file_bytes(const std::filesystem::path& path);

// PCD v0.7, DATA binary, fields x y z intensity (float32), unorganized. Written atomically.
void write_pcd_binary(const std::filesystem::path& path, const std::vector<LidarPoint>& points);

}  // namespace scfloam
