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

// Per-point time to LidarPoint::time_s = t * scale - subtract_s (seconds relative to the scan
// stamp): the bag readers' PointCloud2 rule. The first reading in this order that puts every
// point within 1.5 s of the stamp wins: float relative seconds (Velodyne `time`), float
// absolute seconds (Hesai `timestamp`), float absolute nanoseconds (livox_ros_driver2),
// relative nanoseconds (integers: Ouster `t`, Livox `offset_time`); none -> no per-point time.
// `stamp_s` 0 (PCD/PLY have no stamp): the earliest point's time stands for the stamp in the
// absolute readings, and the rule then sets the scan's stamp to it (sets_stamp).
struct TimeRule {
  bool valid = false;
  double scale = 1, subtract_s = 0;
  bool sets_stamp = false;
};
// The rule for a time field whose finite values span [lo, hi] (lo > hi: none finite).
TimeRule time_rule_for_range(double lo, double hi, bool integer_field, double stamp_s);

// Appends `count` points of `stride` bytes starting at `data` to `scan`, dropping points whose
// x, y or z is not finite (organized clouds). Sets scan.has_ring / has_time when the layout has
// those fields (every point then carries them; has_time only when the time rule found a
// reading). `big_endian` for PLY data.
void append_points(const unsigned char* data, std::size_t count, std::size_t stride,
                   const std::vector<CloudField>& fields, const PointLayout& layout,
                   bool big_endian, Scan& scan);
// The same for fields stored one after another, each as `count` packed values (PCD
// binary_compressed's struct of arrays), little endian.
void append_columns(const unsigned char* columns, std::size_t count, const std::vector<CloudField>& fields,
                    const PointLayout& layout, Scan& scan);

// The conversion every reader ends in (PCD, PLY, PointCloud2), field by field over blocks of
// points rather than value by value (docs/inputs.md: a 127k-point PCD 2.9 -> 1.9 ms).
struct FieldSlot {
  std::size_t offset = 0;  // bytes from the start of the data to the first point's value
  FieldType type = FieldType::kFloat32;
  std::size_t stride = 0;  // bytes from one point's value to the next; 0: the run's stride
};
struct PointSlots {
  FieldSlot x, y, z;
  std::optional<FieldSlot> intensity, ring, time;
};
// Appends `count` points of `stride` bytes to `out`: points whose x, y or z is not finite as a
// float are dropped; an intensity that does not fit a float reads 0; ring by ring_from_value;
// time_s = t * rule.scale - rule.subtract_s when rule.valid (0 when that is not finite).
// `swap`: the data's byte order is not the host's.
void append_point_run(const unsigned char* data, std::size_t count, std::size_t stride,
                      const PointSlots& slots, bool swap, const TimeRule& rule,
                      std::vector<LidarPoint>& out);
// Widens [lo, hi] by the field's finite values over `count` points.
void widen_field_range(const unsigned char* data, std::size_t count, std::size_t stride,
                       FieldSlot slot, bool swap, double& lo, double& hi);
bool host_is_big_endian();

// "x:float32" per field (count > 1 as "normal:float32[3]"), as `scfloam info` prints them.
std::vector<std::string> describe_fields(const std::vector<CloudField>& fields);

}  // namespace scfloam

namespace scfloam {
// Writes `value` as `type` in native byte order at `dst` (ASCII readers pack their rows with it).
void store_field_value(unsigned char* dst, FieldType type, double value);
}  // namespace scfloam
