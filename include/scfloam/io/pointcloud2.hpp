// sensor_msgs/PointCloud2 as both ROS generations carry it, and its one conversion to a Scan.
// The ROS 1 and CDR (ROS 2) decoders fill a PointCloud2View; pointcloud2_to_scan maps the
// fields by name, whatever their datatype, offsets, point step and byte order.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "scfloam/types.hpp"

namespace scfloam {

// sensor_msgs/PointField datatype codes (the same numbers in ROS 1 and ROS 2).
enum class PointFieldType : std::uint8_t {
  INT8 = 1, UINT8 = 2, INT16 = 3, UINT16 = 4, INT32 = 5, UINT32 = 6, FLOAT32 = 7, FLOAT64 = 8
};

struct PointField {
  std::string name;
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;  // PointFieldType code
  std::uint32_t count = 1;
};

// A decoded message whose point bytes still live in the caller's buffer.
struct PointCloud2View {
  std::int64_t stamp_sec = 0;
  std::uint32_t stamp_nanosec = 0;
  std::string frame_id;
  std::uint32_t height = 0, width = 0;
  std::vector<PointField> fields;
  bool is_bigendian = false;
  std::uint32_t point_step = 0, row_step = 0;
  const std::uint8_t* data = nullptr;
  std::size_t data_size = 0;
  bool is_dense = false;

  double stamp_s() const { return static_cast<double>(stamp_sec) + 1e-9 * stamp_nanosec; }
};

// Size in bytes of a datatype code, 0 for an unknown code.
std::size_t point_field_size(std::uint8_t datatype);
// "float32", "uint16", ... ("type<N>" for an unknown code).
std::string point_field_type_name(std::uint8_t datatype);
// "x:float32", "ring:uint16", "rgb:float32[3]" for `scfloam info`.
std::vector<std::string> describe_point_fields(const std::vector<PointField>& fields);

// Name of the field read as per-point time (see pointcloud2_to_scan), empty when none.
std::string point_time_field(const std::vector<PointField>& fields);

// Decoders of the two wire formats. `where` names the file, topic and message index for errors.
PointCloud2View decode_ros1_pointcloud2(const std::uint8_t* bytes, std::size_t size,
                                        const std::string& where);
PointCloud2View decode_cdr_pointcloud2(const std::uint8_t* bytes, std::size_t size,
                                       const std::string& where);

// The Scan of a cloud: points with a non-finite x, y or z are dropped (organized clouds mark
// missing returns with NaN). Intensity from `intensity` (else `reflectivity`, else 0); ring
// from `ring` or `channel`; per-point time from `time`, `t`, `time_offset`, `timestamp`,
// `offset_time` or `ts`, converted to seconds relative to the header stamp (see docs/bags.md
// for the rule). has_ring / has_time only when the field exists (so every point has it).
// Error (prefixed by `where`) for missing x/y/z, fields past point_step, short data.
Scan pointcloud2_to_scan(const PointCloud2View& cloud, const std::string& where);

}  // namespace scfloam
