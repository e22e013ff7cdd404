#include "scfloam/io/point_fields.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>

#include "scfloam/error.hpp"
#include "scfloam/io/field_names.hpp"

namespace scfloam {
namespace {

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

template <typename T>
T load_as(const unsigned char* p, bool swap) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, p, sizeof(T));
  if (swap) std::reverse(bytes, bytes + sizeof(T));
  T v;
  std::memcpy(&v, bytes, sizeof(T));
  return v;
}

double read_value(const unsigned char* p, FieldType type, bool swap) {
  switch (type) {
    case FieldType::kInt8: return load_as<std::int8_t>(p, false);
    case FieldType::kUint8: return load_as<std::uint8_t>(p, false);
    case FieldType::kInt16: return load_as<std::int16_t>(p, swap);
    case FieldType::kUint16: return load_as<std::uint16_t>(p, swap);
    case FieldType::kInt32: return load_as<std::int32_t>(p, swap);
    case FieldType::kUint32: return load_as<std::uint32_t>(p, swap);
    case FieldType::kFloat32: return load_as<float>(p, swap);
    case FieldType::kFloat64: return load_as<double>(p, swap);
  }
  return 0;
}

bool host_is_big_endian() {
  const std::uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 0;
}

}  // namespace

std::size_t field_type_size(FieldType type) {
  switch (type) {
    case FieldType::kInt8:
    case FieldType::kUint8: return 1;
    case FieldType::kInt16:
    case FieldType::kUint16: return 2;
    case FieldType::kInt32:
    case FieldType::kUint32:
    case FieldType::kFloat32: return 4;
    case FieldType::kFloat64: return 8;
  }
  return 0;
}

const char* field_type_name(FieldType type) {
  switch (type) {
    case FieldType::kInt8: return "int8";
    case FieldType::kUint8: return "uint8";
    case FieldType::kInt16: return "int16";
    case FieldType::kUint16: return "uint16";
    case FieldType::kInt32: return "int32";
    case FieldType::kUint32: return "uint32";
    case FieldType::kFloat32: return "float32";
    case FieldType::kFloat64: return "float64";
  }
  return "?";
}

std::optional<FieldType> field_type_from_pcd(char type, std::size_t size) {
  switch (std::toupper(static_cast<unsigned char>(type))) {
    case 'F':
      if (size == 4) return FieldType::kFloat32;
      if (size == 8) return FieldType::kFloat64;
      break;
    case 'I':
      if (size == 1) return FieldType::kInt8;
      if (size == 2) return FieldType::kInt16;
      if (size == 4) return FieldType::kInt32;
      break;
    case 'U':
      if (size == 1) return FieldType::kUint8;
      if (size == 2) return FieldType::kUint16;
      if (size == 4) return FieldType::kUint32;
      break;
  }
  return std::nullopt;
}

std::optional<FieldType> field_type_from_ply(const std::string& name) {
  const std::string n = lower(name);
  if (n == "char" || n == "int8") return FieldType::kInt8;
  if (n == "uchar" || n == "uint8") return FieldType::kUint8;
  if (n == "short" || n == "int16") return FieldType::kInt16;
  if (n == "ushort" || n == "uint16") return FieldType::kUint16;
  if (n == "int" || n == "int32") return FieldType::kInt32;
  if (n == "uint" || n == "uint32") return FieldType::kUint32;
  if (n == "float" || n == "float32") return FieldType::kFloat32;
  if (n == "double" || n == "float64") return FieldType::kFloat64;
  return std::nullopt;
}

PointLayout map_point_fields(const std::vector<CloudField>& fields) {
  // The first name of each list that is present wins (intensity before reflectivity, ...):
  // the same lists as the PointCloud2 conversion of the bag readers (field_names.hpp).
  auto find = [&](const auto& names) {
    for (const char* name : names)
      for (int i = 0; i < static_cast<int>(fields.size()); ++i)
        if (lower(fields[i].name) == name) return i;
    return -1;
  };
  PointLayout layout;
  layout.x = find(std::array{"x"});
  layout.y = find(std::array{"y"});
  layout.z = find(std::array{"z"});
  layout.intensity = find(field_names::kIntensity);
  layout.ring = find(field_names::kRing);
  layout.time = find(field_names::kTime);
  if (layout.x < 0 || layout.y < 0 || layout.z < 0) {
    std::string names;
    for (const auto& f : fields) names += (names.empty() ? "" : " ") + f.name;
    throw Error("points have no x, y and z fields (fields: " + (names.empty() ? "none" : names) + ")");
  }
  return layout;
}

bool is_integer(FieldType type) { return type != FieldType::kFloat32 && type != FieldType::kFloat64; }

TimeRule choose_time_rule(const unsigned char* data, std::size_t count, std::size_t stride, const CloudField& field,
                          bool big_endian, double stamp_s) {
  const bool swap = big_endian != host_is_big_endian();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t i = 0; i < count; ++i) {
    const double t = read_value(data + i * stride + field.offset, field.type, swap);
    if (!std::isfinite(t)) continue;
    lo = std::min(lo, t);
    hi = std::max(hi, t);
  }
  return time_rule_for_range(lo, hi, is_integer(field.type), stamp_s);
}

TimeRule time_rule_for_range(double lo, double hi, bool integer_field, double stamp_s) {
  constexpr double kMaxScanSpanS = 1.5;  // slower than any spinning LiDAR's sweep
  if (!(lo <= hi)) return {};
  const bool floating = !integer_field;
  // Without a stamp (PCD, PLY) the earliest point stands for it in the absolute readings.
  const double stamp_abs_s = stamp_s != 0 ? stamp_s : lo;
  const double stamp_abs_ns_s = stamp_s != 0 ? stamp_s : lo * 1e-9;
  const TimeRule candidates[] = {{floating, 1, 0, false},
                                 {floating, 1, stamp_abs_s, stamp_s == 0},
                                 {floating, 1e-9, stamp_abs_ns_s, stamp_s == 0},
                                 {true, 1e-9, 0, false}};
  for (const TimeRule& rule : candidates) {
    if (!rule.valid) continue;
    const double a = lo * rule.scale - rule.subtract_s, b = hi * rule.scale - rule.subtract_s;
    if (std::fabs(a) <= kMaxScanSpanS && std::fabs(b) <= kMaxScanSpanS) return rule;
  }
  return {};
}

void append_points(const unsigned char* data, std::size_t count, std::size_t stride,
                   const std::vector<CloudField>& fields, const PointLayout& layout,
                   bool big_endian, Scan& scan) {
  const bool swap = big_endian != host_is_big_endian();
  const CloudField& fx = fields.at(layout.x);
  const CloudField& fy = fields.at(layout.y);
  const CloudField& fz = fields.at(layout.z);
  const CloudField* fi = layout.intensity >= 0 ? &fields[layout.intensity] : nullptr;
  const CloudField* fr = layout.ring >= 0 ? &fields[layout.ring] : nullptr;
  const CloudField* ft = layout.time >= 0 ? &fields[layout.time] : nullptr;
  const TimeRule time_rule = ft ? choose_time_rule(data, count, stride, *ft, big_endian, scan.timestamp_s) : TimeRule{};
  if (time_rule.sets_stamp) scan.timestamp_s = time_rule.subtract_s;
  scan.points.reserve(scan.points.size() + count);
  for (std::size_t i = 0; i < count; ++i) {
    const unsigned char* p = data + i * stride;
    LidarPoint q;
    const double x = read_value(p + fx.offset, fx.type, swap);
    const double y = read_value(p + fy.offset, fy.type, swap);
    const double z = read_value(p + fz.offset, fz.type, swap);
    // A float64 field can hold finite values beyond float's range, which would become inf here.
    if (!fits_float(x) || !fits_float(y) || !fits_float(z)) continue;
    q.x = static_cast<float>(x);
    q.y = static_cast<float>(y);
    q.z = static_cast<float>(z);
    if (fi) {
      const double v = read_value(p + fi->offset, fi->type, swap);
      q.intensity = fits_float(v) ? static_cast<float>(v) : 0.f;
    }
    if (fr) q.ring = ring_from_value(read_value(p + fr->offset, fr->type, swap));
    if (time_rule.valid) {
      const double t = read_value(p + ft->offset, ft->type, swap);
      q.time_s = static_cast<float>(t * time_rule.scale - time_rule.subtract_s);
      if (!std::isfinite(q.time_s)) q.time_s = 0;
    }
    scan.points.push_back(q);
  }
  scan.has_ring = fr != nullptr;
  scan.has_time = time_rule.valid;
}

std::vector<std::string> describe_fields(const std::vector<CloudField>& fields) {
  std::vector<std::string> out;
  for (const auto& f : fields) {
    std::string s = f.name + ":" + field_type_name(f.type);
    if (f.count > 1) s += "[" + std::to_string(f.count) + "]";
    out.push_back(s);
  }
  return out;
}

}  // namespace scfloam

namespace scfloam {
namespace {
template <typename T>
void store_as(unsigned char* dst, double v) {
  const T t = static_cast<T>(v);
  std::memcpy(dst, &t, sizeof(T));
}
}  // namespace

void store_field_value(unsigned char* dst, FieldType type, double value) {
  // Integers: NaN and out-of-range values would be undefined behaviour in the cast.
  auto clamp_int = [&](double lo, double hi) { return std::isfinite(value) ? std::clamp(value, lo, hi) : 0.0; };
  switch (type) {
    case FieldType::kInt8: store_as<std::int8_t>(dst, clamp_int(-128, 127)); break;
    case FieldType::kUint8: store_as<std::uint8_t>(dst, clamp_int(0, 255)); break;
    case FieldType::kInt16: store_as<std::int16_t>(dst, clamp_int(-32768, 32767)); break;
    case FieldType::kUint16: store_as<std::uint16_t>(dst, clamp_int(0, 65535)); break;
    case FieldType::kInt32: store_as<std::int32_t>(dst, clamp_int(-2147483648.0, 2147483647.0)); break;
    case FieldType::kUint32: store_as<std::uint32_t>(dst, clamp_int(0, 4294967295.0)); break;
    case FieldType::kFloat32: store_as<float>(dst, value); break;
    case FieldType::kFloat64: store_as<double>(dst, value); break;
  }
}

}  // namespace scfloam
