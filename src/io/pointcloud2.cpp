#include "scfloam/io/pointcloud2.hpp"

#include <array>
#include <limits>
#include <optional>

#include "scfloam/error.hpp"
#include "scfloam/io/field_names.hpp"
#include "scfloam/io/point_fields.hpp"

namespace scfloam {
namespace {

// A field the conversion has checked (check_field: known datatype) as the shared readers'
// slot; the PointField codes 1..8 are FieldType's order.
FieldSlot slot_of(const PointField& f) {
  return {f.offset, static_cast<FieldType>(f.datatype - 1)};
}

template <typename Names>
const PointField* find_field(const std::vector<PointField>& fields, const Names& names) {
  for (const char* name : names)
    for (const PointField& f : fields)
      if (f.name == name) return &f;
  return nullptr;
}

template <typename Names>
const PointField* find_field(const PointCloud2View& cloud, const Names& names) {
  return find_field(cloud.fields, names);
}

const PointField* find_time_field(const std::vector<PointField>& fields) {
  return find_field(fields, field_names::kTime);
}

void check_field(const PointCloud2View& cloud, const PointField* f, const std::string& where) {
  if (!f) return;
  const std::size_t size = point_field_size(f->datatype);
  if (size == 0)
    throw Error(where + ": field '" + f->name + "' has unknown datatype " +
                std::to_string(f->datatype));
  if (std::size_t{f->offset} + size > cloud.point_step)
    throw Error(where + ": field '" + f->name + "' at offset " + std::to_string(f->offset) +
                " (" + std::to_string(size) + " bytes) runs past point_step " +
                std::to_string(cloud.point_step));
}

bool is_integer_type(std::uint8_t datatype) {
  return datatype >= 1 && datatype <= 6;
}


// The time field's reading (float relative seconds, absolute seconds or nanoseconds, integer
// relative nanoseconds) is point_fields' rule, shared with PCD and PLY; this only walks the
// padded rows for the field's range.
TimeRule pointcloud2_time_rule(const PointCloud2View& cloud, const PointField& ft, bool swap) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  // width 0: no rows to walk (a fuzzed cloud of 0 x 4e9 points hung here).
  for (std::size_t r = 0; r < cloud.height && cloud.width > 0; ++r)
    widen_field_range(cloud.data + r * cloud.row_step, cloud.width, cloud.point_step, slot_of(ft), swap, lo, hi);
  return time_rule_for_range(lo, hi, is_integer_type(ft.datatype), cloud.stamp_s());
}

}  // namespace

std::size_t point_field_size(std::uint8_t datatype) {
  switch (datatype) {
    case 1: case 2: return 1;
    case 3: case 4: return 2;
    case 5: case 6: case 7: return 4;
    case 8: return 8;
    default: return 0;
  }
}

std::string point_field_type_name(std::uint8_t datatype) {
  static const char* names[] = {"", "int8", "uint8", "int16", "uint16",
                                "int32", "uint32", "float32", "float64"};
  if (datatype >= 1 && datatype <= 8) return names[datatype];
  return "type" + std::to_string(datatype);
}

std::string point_time_field(const std::vector<PointField>& fields) {
  const PointField* f = find_time_field(fields);
  return f ? f->name : std::string();
}

std::vector<std::string> describe_point_fields(const std::vector<PointField>& fields) {
  std::vector<std::string> out;
  for (const PointField& f : fields) {
    std::string s = f.name + ":" + point_field_type_name(f.datatype);
    if (f.count != 1) s += "[" + std::to_string(f.count) + "]";
    out.push_back(s);
  }
  return out;
}

Scan pointcloud2_to_scan(const PointCloud2View& cloud, const std::string& where) {
  const PointField* fx = find_field(cloud, std::array{"x"});
  const PointField* fy = find_field(cloud, std::array{"y"});
  const PointField* fz = find_field(cloud, std::array{"z"});
  if (!fx || !fy || !fz) {
    std::string names;
    for (const PointField& f : cloud.fields) names += (names.empty() ? "" : " ") + f.name;
    throw Error(where + ": PointCloud2 has no x, y and z fields (fields: " +
                (names.empty() ? std::string("none") : names) + ")");
  }
  const PointField* fi = find_field(cloud, field_names::kIntensity);
  const PointField* fr = find_field(cloud, field_names::kRing);
  const PointField* ft = find_time_field(cloud.fields);
  for (const PointField* f : {fx, fy, fz, fi, fr, ft}) check_field(cloud, f, where);

  const std::size_t width = cloud.width, height = cloud.height;
  const std::size_t point_step = cloud.point_step;
  const std::size_t row_step = cloud.row_step;
  if (width * height > 0) {
    if (point_step == 0) throw Error(where + ": PointCloud2 point_step is 0");
    if (row_step < width * point_step)
      throw Error(where + ": PointCloud2 row_step " + std::to_string(row_step) +
                  " < width * point_step " + std::to_string(width * point_step));
    const std::size_t needed = (height - 1) * row_step + width * point_step;
    if (cloud.data_size < needed || cloud.data_size < width * height * point_step)
      throw Error(where + ": PointCloud2 data has " + std::to_string(cloud.data_size) +
                  " bytes, " + std::to_string(width) + "x" + std::to_string(height) +
                  " points of " + std::to_string(point_step) + " bytes need " +
                  std::to_string(needed));
  }

  Scan scan;
  scan.timestamp_s = cloud.stamp_s();
  scan.has_ring = fr != nullptr;
  scan.points.reserve(width * height);
  const bool swap = cloud.is_bigendian != host_is_big_endian();

  const TimeRule time_rule = ft ? pointcloud2_time_rule(cloud, *ft, swap) : TimeRule{};
  scan.has_time = time_rule.valid;
  if (time_rule.sets_stamp) scan.timestamp_s = time_rule.subtract_s;  // stamp 0: the earliest point

  auto slot = [](const PointField* f) { return f ? std::optional<FieldSlot>(slot_of(*f)) : std::nullopt; };
  const PointSlots slots{slot_of(*fx), slot_of(*fy), slot_of(*fz), slot(fi), slot(fr), slot(ft)};
  for (std::size_t r = 0; r < height && width > 0; ++r)  // width 0: no rows to walk
    append_point_run(cloud.data + r * row_step, width, point_step, slots, swap, time_rule, scan.points);
  return scan;
}

}  // namespace scfloam
