// A walk over a ROS 1 bag's record lengths before librosbag opens it: librosbag trusts each
// record's header and data lengths and grows its buffers to whatever they claim (a fuzzed
// 400-byte bag made it allocate 2.3 GB before failing). Every length must fit in the file.
#include "ros1_bag_check.hpp"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "scfloam/error.hpp"

namespace scfloam {
namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::uint64_t kMagicSize = sizeof(kMagic) - 1;

std::uint32_t le32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
         std::uint32_t(p[3]) << 24;
}

// The value of `name` in a record header (fields: uint32 length, then "name=value").
std::string header_field(const std::vector<std::uint8_t>& header, const std::string& name) {
  std::size_t pos = 0;
  while (pos + 4 <= header.size()) {
    const std::uint32_t len = le32(&header[pos]);
    pos += 4;
    if (len > header.size() - pos) break;
    const char* field = reinterpret_cast<const char*>(&header[pos]);
    const void* eq = std::memchr(field, '=', len);
    if (eq) {
      const std::size_t key_len = static_cast<const char*>(eq) - field;
      if (std::string(field, key_len) == name) return std::string(field + key_len + 1, len - key_len - 1);
    }
    pos += len;
  }
  return {};
}

std::uint64_t le64_field(const std::string& value) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < 8 && i < value.size(); ++i)
    v |= std::uint64_t(static_cast<std::uint8_t>(value[i])) << (8 * i);
  return v;
}

// Where records start at top level, and the offsets other records point at (the bag header's
// index_pos, chunk infos' chunk_pos): librosbag seeks to those and trusts what it reads there.
struct RecordOffsets {
  std::set<std::uint64_t> starts;
  std::vector<std::uint64_t> pointed_at;
};

// Checks the records between byte offsets begin and end of the file.
void check_records(std::ifstream& in, const std::filesystem::path& path, std::uint64_t begin,
                   std::uint64_t end, int depth, RecordOffsets& offsets) {
  std::uint64_t pos = begin;
  std::vector<std::uint8_t> header;
  while (pos < end) {
    if (depth == 0) offsets.starts.insert(pos);
    std::uint8_t len[4];
    auto read_len = [&](const char* what) {
      if (end - pos < 4) throw file_error(path, std::string("ROS 1 bag: truncated ") + what + " length at byte " + std::to_string(pos));
      in.seekg(static_cast<std::streamoff>(pos));
      in.read(reinterpret_cast<char*>(len), 4);
      if (!in) throw file_error(path, "ROS 1 bag: cannot read at byte " + std::to_string(pos));
      pos += 4;
      const std::uint64_t n = le32(len);
      if (n > end - pos)
        throw file_error(path, std::string("ROS 1 bag: a record's ") + what + " length (" +
                                   std::to_string(n) + " bytes) runs past the end of its " +
                                   (depth == 0 ? "file" : "chunk") + " at byte " + std::to_string(pos - 4));
      return n;
    };
    const std::uint64_t header_len = read_len("header");
    header.resize(header_len);
    in.read(reinterpret_cast<char*>(header.data()), static_cast<std::streamsize>(header_len));
    pos += header_len;
    const std::uint64_t data_len = read_len("data");
    // An uncompressed chunk holds records of its own (message and connection records).
    const std::string op = header_field(header, "op");
    if (depth == 0 && op.size() == 1 && op[0] == 0x03) {
      const std::uint64_t index_pos = le64_field(header_field(header, "index_pos"));
      if (index_pos != 0) offsets.pointed_at.push_back(index_pos);
    }
    if (depth == 0 && op.size() == 1 && op[0] == 0x06)
      offsets.pointed_at.push_back(le64_field(header_field(header, "chunk_pos")));
    if (depth == 0 && op.size() == 1 && op[0] == 0x05 && header_field(header, "compression") == "none")
      check_records(in, path, pos, pos + data_len, 1, offsets);
    pos += data_len;
  }
}

}  // namespace

void check_ros1_bag_records(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw file_error(path, "cannot open");
  in.seekg(0, std::ios::end);
  const std::uint64_t size = static_cast<std::uint64_t>(in.tellg());
  char magic[kMagicSize];
  in.seekg(0);
  in.read(magic, kMagicSize);
  if (!in || std::memcmp(magic, kMagic, kMagicSize) != 0)
    throw file_error(path, "not a ROS 1 bag 2.0 (no '#ROSBAG V2.0' line)");
  RecordOffsets offsets;
  check_records(in, path, kMagicSize, size, 0, offsets);
  offsets.starts.insert(size);  // an empty bag's index_pos is its end: nothing follows
  for (const std::uint64_t pointed : offsets.pointed_at)
    if (!offsets.starts.count(pointed))
      throw file_error(path, "ROS 1 bag: an index points at byte " + std::to_string(pointed) +
                                 ", where no record starts");
}

}  // namespace scfloam
