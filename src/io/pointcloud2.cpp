#include "scfloam/io/pointcloud2.hpp"

#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "scfloam/error.hpp"
#include "scfloam/io/field_names.hpp"
#include "scfloam/io/point_fields.hpp"

namespace scfloam {
namespace {

// One field the Scan needs, resolved once per cloud.
struct FieldReader {
  const PointField* field = nullptr;
  explicit operator bool() const { return field != nullptr; }
};

template <typename T>
T load_swapped(const std::uint8_t* p, bool swap) {
  std::uint8_t b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (swap)
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

bool host_is_little_endian() {
  const std::uint16_t one = 1;
  std::uint8_t first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

double read_value(const std::uint8_t* p, std::uint8_t datatype, bool swap) {
  switch (static_cast<PointFieldType>(datatype)) {
    case PointFieldType::INT8: return static_cast<std::int8_t>(*p);
    case PointFieldType::UINT8: return *p;
    case PointFieldType::INT16: return load_swapped<std::int16_t>(p, swap);
    case PointFieldType::UINT16: return load_swapped<std::uint16_t>(p, swap);
    case PointFieldType::INT32: return load_swapped<std::int32_t>(p, swap);
    case PointFieldType::UINT32: return load_swapped<std::uint32_t>(p, swap);
    case PointFieldType::FLOAT32: return load_swapped<float>(p, swap);
    case PointFieldType::FLOAT64: return load_swapped<double>(p, swap);
  }
  return std::numeric_limits<double>::quiet_NaN();
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
    for (std::size_t c = 0; c < cloud.width; ++c) {
      const double t = read_value(cloud.data + r * cloud.row_step + c * cloud.point_step + ft.offset,
                                  ft.datatype, swap);
      if (!std::isfinite(t)) continue;
      lo = std::min(lo, t);
      hi = std::max(hi, t);
    }
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
  const bool swap = cloud.is_bigendian == host_is_little_endian();

  const TimeRule time_rule = ft ? pointcloud2_time_rule(cloud, *ft, swap) : TimeRule{};
  scan.has_time = time_rule.valid;
  if (time_rule.sets_stamp) scan.timestamp_s = time_rule.subtract_s;  // stamp 0: the earliest point

  for (std::size_t r = 0; r < height && width > 0; ++r) {  // width 0: no rows to walk
    const std::uint8_t* row = cloud.data + r * row_step;
    for (std::size_t c = 0; c < width; ++c) {
      const std::uint8_t* p = row + c * point_step;
      const double x = read_value(p + fx->offset, fx->datatype, swap);
      const double y = read_value(p + fy->offset, fy->datatype, swap);
      const double z = read_value(p + fz->offset, fz->datatype, swap);
      // Finite as floats too: a FLOAT64 coordinate beyond 3.4e38 would become inf.
      if (!fits_float(x) || !fits_float(y) || !fits_float(z)) continue;
      LidarPoint pt;
      pt.x = static_cast<float>(x);
      pt.y = static_cast<float>(y);
      pt.z = static_cast<float>(z);
      if (fi) {
        const double v = read_value(p + fi->offset, fi->datatype, swap);
        pt.intensity = fits_float(v) ? static_cast<float>(v) : 0.f;  // as the PCD/PLY readers do
      }
      if (fr) pt.ring = ring_from_value(read_value(p + fr->offset, fr->datatype, swap));
      if (time_rule.valid) {
        const double t = read_value(p + ft->offset, ft->datatype, swap);
        pt.time_s = static_cast<float>(t * time_rule.scale - time_rule.subtract_s);
        if (!std::isfinite(pt.time_s)) pt.time_s = 0;
      }
      scan.points.push_back(pt);
    }
  }
  return scan;
}

}  // namespace scfloam
