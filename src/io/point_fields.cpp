#include "scfloam/io/point_fields.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <type_traits>

#include "scfloam/error.hpp"
#include "scfloam/io/field_names.hpp"

namespace scfloam {
namespace {

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

template <typename T, bool Swap>
T load(const unsigned char* p) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, p, sizeof(T));
  if constexpr (Swap) std::reverse(bytes, bytes + sizeof(T));
  T v;
  std::memcpy(&v, bytes, sizeof(T));
  return v;
}

// Calls sink(i, value) for the field of points first .. first + count - 1 (i from 0), the type
// and byte order resolved once per call so that the loop itself is a plain typed load.
template <typename Sink>
void for_each_value(const unsigned char* data, std::size_t first, std::size_t count, std::size_t stride,
                    FieldSlot slot, bool swap, Sink&& sink) {
  if (count == 0) return;  // `data` may be null then (an empty cloud's buffer)
  if (slot.stride != 0) stride = slot.stride;
  auto run = [&](auto value_type, auto swapped) {
    using T = decltype(value_type);
    const unsigned char* p = data + slot.offset + first * stride;
    for (std::size_t i = 0; i < count; ++i, p += stride)
      sink(i, static_cast<double>(load<T, decltype(swapped)::value>(p)));
  };
  auto typed = [&](auto value_type) {
    if (swap && sizeof(value_type) > 1)
      run(value_type, std::true_type{});
    else
      run(value_type, std::false_type{});
  };
  switch (slot.type) {
    case FieldType::kInt8: return typed(std::int8_t{});
    case FieldType::kUint8: return typed(std::uint8_t{});
    case FieldType::kInt16: return typed(std::int16_t{});
    case FieldType::kUint16: return typed(std::uint16_t{});
    case FieldType::kInt32: return typed(std::int32_t{});
    case FieldType::kUint32: return typed(std::uint32_t{});
    case FieldType::kFloat32: return typed(float{});
    case FieldType::kFloat64: return typed(double{});
  }
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

namespace {

// append_points and append_columns once each field has its slot.
void append_slots(const unsigned char* data, std::size_t count, std::size_t stride, const PointSlots& slots,
                  bool big_endian, Scan& scan) {
  const bool swap = big_endian != host_is_big_endian();
  TimeRule time_rule;
  if (slots.time) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    widen_field_range(data, count, stride, *slots.time, swap, lo, hi);
    time_rule = time_rule_for_range(lo, hi, is_integer(slots.time->type), scan.timestamp_s);
  }
  if (time_rule.sets_stamp) scan.timestamp_s = time_rule.subtract_s;
  scan.points.reserve(scan.points.size() + count);
  append_point_run(data, count, stride, slots, swap, time_rule, scan.points);
  scan.has_ring = slots.ring.has_value();
  scan.has_time = time_rule.valid;
}

PointSlots slots_of(const PointLayout& layout, const std::vector<FieldSlot>& slot_of_field) {
  auto slot = [&](int index) -> std::optional<FieldSlot> {
    if (index < 0) return std::nullopt;
    return slot_of_field.at(static_cast<std::size_t>(index));
  };
  return {*slot(layout.x), *slot(layout.y), *slot(layout.z), slot(layout.intensity), slot(layout.ring),
          slot(layout.time)};
}

}  // namespace

void append_points(const unsigned char* data, std::size_t count, std::size_t stride,
                   const std::vector<CloudField>& fields, const PointLayout& layout,
                   bool big_endian, Scan& scan) {
  std::vector<FieldSlot> slot_of_field;
  for (const CloudField& f : fields) slot_of_field.push_back({f.offset, f.type});
  append_slots(data, count, stride, slots_of(layout, slot_of_field), big_endian, scan);
}

void append_columns(const unsigned char* columns, std::size_t count, const std::vector<CloudField>& fields,
                    const PointLayout& layout, Scan& scan) {
  std::vector<FieldSlot> slot_of_field;
  std::size_t column_begin = 0;
  for (const CloudField& f : fields) {
    const std::size_t width = field_type_size(f.type) * f.count;
    slot_of_field.push_back({column_begin, f.type, width});
    column_begin += width * count;
  }
  append_slots(columns, count, 0, slots_of(layout, slot_of_field), false, scan);
}

void append_point_run(const unsigned char* data, std::size_t count, std::size_t stride,
                      const PointSlots& slots, bool swap, const TimeRule& rule,
                      std::vector<LidarPoint>& out) {
  // Blocks small enough to stay in the L1 cache between the field passes and the assembly.
  constexpr std::size_t kBlock = 256;
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  float xs[kBlock], ys[kBlock], zs[kBlock], intensity[kBlock], time[kBlock];
  std::int16_t ring[kBlock];
  // A coordinate beyond float's range (float64 fields) would become inf: dropped as non-finite.
  auto coordinate = [](float* dst) {
    return [dst](std::size_t i, double v) { dst[i] = fits_float(v) ? static_cast<float>(v) : kNaN; };
  };
  for (std::size_t begin = 0; begin < count; begin += kBlock) {
    const std::size_t n = std::min(kBlock, count - begin);
    for_each_value(data, begin, n, stride, slots.x, swap, coordinate(xs));
    for_each_value(data, begin, n, stride, slots.y, swap, coordinate(ys));
    for_each_value(data, begin, n, stride, slots.z, swap, coordinate(zs));
    if (slots.intensity)
      for_each_value(data, begin, n, stride, *slots.intensity, swap, [&](std::size_t i, double v) {
        intensity[i] = fits_float(v) ? static_cast<float>(v) : 0.f;
      });
    if (slots.ring)
      for_each_value(data, begin, n, stride, *slots.ring, swap,
                     [&](std::size_t i, double v) { ring[i] = ring_from_value(v); });
    if (slots.time && rule.valid)
      for_each_value(data, begin, n, stride, *slots.time, swap, [&](std::size_t i, double v) {
        const double t = v * rule.scale - rule.subtract_s;
        time[i] = fits_float(t) ? static_cast<float>(t) : 0.f;
      });
    // Points written in place: a LidarPoint assembled on the stack and copied in stalls on
    // store forwarding (its 16-byte copy reads five narrower stores), the most of the loop.
    const std::size_t base = out.size();
    out.resize(base + n);
    LidarPoint* dst = out.data() + base;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(xs[i]) || !std::isfinite(ys[i]) || !std::isfinite(zs[i])) continue;
      LidarPoint& q = dst[kept++];
      q.x = xs[i];
      q.y = ys[i];
      q.z = zs[i];
      q.intensity = slots.intensity ? intensity[i] : 0.f;
      q.ring = slots.ring ? ring[i] : std::int16_t{-1};
      q.time_s = slots.time && rule.valid ? time[i] : 0.f;
    }
    out.resize(base + kept);
  }
}

void widen_field_range(const unsigned char* data, std::size_t count, std::size_t stride,
                       FieldSlot slot, bool swap, double& lo, double& hi) {
  // Locals, not the references: the field bytes may alias them, which would make the compiler
  // store and reload both on every value.
  double low = lo, high = hi;
  for_each_value(data, 0, count, stride, slot, swap, [&](std::size_t, double v) {
    if (!std::isfinite(v)) return;
    low = std::min(low, v);
    high = std::max(high, v);
  });
  lo = low;
  hi = high;
}

bool host_is_big_endian() {
  const std::uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 0;
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
