// Strict parsing of ROS 1 record headers: librosbag's parser checks each field length only
// against 1 MB, not against the header it is reading, so a header it sees must already be
// known to hold whole fields.
#include <cstring>

#include "ros1_bag_check_detail.hpp"

namespace scfloam::ros1_check {

std::uint32_t le32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
         std::uint32_t(p[3]) << 24;
}

std::string parse_header(const std::uint8_t* data, std::size_t size, Fields& fields) {
  fields.clear();
  std::size_t pos = 0;
  while (pos < size) {
    if (size - pos < 4) return "a header field length is cut off by the end of the header";
    const std::uint32_t len = le32(data + pos);
    pos += 4;
    if (len > size - pos)
      return "a header field of " + std::to_string(len) + " bytes runs past the end of its header";
    const char* field = reinterpret_cast<const char*>(data + pos);
    const void* eq = std::memchr(field, '=', len);
    if (!eq) return "a header field has no '='";
    const std::size_t key_len = static_cast<const char*>(eq) - field;
    std::string key(field, key_len);
    if (fields.count(key)) return "the header field '" + key + "' appears twice";
    fields.emplace(std::move(key), std::string(field + key_len + 1, len - key_len - 1));
    pos += len;
  }
  return {};
}

namespace {

template <typename T>
std::optional<T> fixed_field(const Fields& fields, const std::string& name) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.size() != sizeof(T)) return std::nullopt;
  T value = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i)  // little-endian on disk
    value |= T(static_cast<std::uint8_t>(it->second[i])) << (8 * i);
  return value;
}

}  // namespace

std::optional<std::uint8_t> u8_field(const Fields& fields, const std::string& name) {
  return fixed_field<std::uint8_t>(fields, name);
}
std::optional<std::uint32_t> u32_field(const Fields& fields, const std::string& name) {
  return fixed_field<std::uint32_t>(fields, name);
}
std::optional<std::uint64_t> u64_field(const Fields& fields, const std::string& name) {
  return fixed_field<std::uint64_t>(fields, name);
}

}  // namespace scfloam::ros1_check
