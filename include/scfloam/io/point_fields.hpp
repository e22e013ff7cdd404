// Per-point fields of the point-cloud formats (PCD, PLY, PointCloud2) mapped to LidarPoint by
// one rule, so that every reader reads intensity, ring and per-point time the same way.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "scfloam/types.hpp"

namespace scfloam {

enum class FieldType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::size_t field_type_size(FieldType type);
const char* field_type_name(FieldType type);  // "float32", "uint16", ...
// PCD's TYPE/SIZE pair ('F', 4) -> float32; nullopt for combinations PCD does not define.
std::optional<FieldType> field_type_from_pcd(char type, std::size_t size);
// PLY's type names (float, float32, uchar, uint8, ...); nullopt when unknown.
std::optional<FieldType> field_type_from_ply(const std::string& name);

struct CloudField {
  std::string name;
  std::size_t offset = 0;  // bytes from the start of a point
  FieldType type = FieldType::kFloat32;
  std::size_t count = 1;   // elements; only the first is read
};

// Which field feeds which LidarPoint member, by name (case-insensitive; the first name of each
// list that is present wins): x, y, z; intensity | reflectivity | reflectance | i;
// ring | channel; time | t | time_offset | offset_time | timestamp | ts.
// Indices into the field list, -1 when absent. Throws Error when x, y or z is missing.
struct PointLayout {
  int x = -1, y = -1, z = -1, intensity = -1, ring = -1, time = -1;
};
PointLayout map_point_fields(const std::vector<CloudField>& fields);

// Per-point time to LidarPoint::time_s (seconds relative to the scan stamp), decided once per
// scan from the type and the first point's value (the bag readers' PointCloud2 rule too):
//   integer types        -> nanoseconds relative to the scan (Ouster `t`, Livox offset_time)
//   floats up to 1e6     -> seconds relative to the scan (Velodyne `time`)
//   floats above 1e6     -> absolute seconds (Hesai/Livox `timestamp`): minus the scan stamp,
//                           or, when the scan has none (PCD/PLY), the first point's time
//                           becomes the scan stamp
enum class TimeEncoding { kRelativeSeconds, kRelativeNanoseconds, kAbsoluteSeconds };
TimeEncoding time_encoding(FieldType type, double first_value);

// Appends `count` points of `stride` bytes starting at `data` to `scan`, dropping points whose
// x, y or z is not finite (organized clouds). Sets scan.has_ring / has_time when the layout has
// those fields (every point then carries them). `big_endian` for PLY/PointCloud2 data.
void append_points(const unsigned char* data, std::size_t count, std::size_t stride,
                   const std::vector<CloudField>& fields, const PointLayout& layout,
                   bool big_endian, Scan& scan);

// "x:float32" per field (count > 1 as "normal:float32[3]"), as `scfloam info` prints them.
std::vector<std::string> describe_fields(const std::vector<CloudField>& fields);

}  // namespace scfloam

namespace scfloam {
// Writes `value` as `type` in native byte order at `dst` (ASCII readers pack their rows with it).
void store_field_value(unsigned char* dst, FieldType type, double value);
}  // namespace scfloam
