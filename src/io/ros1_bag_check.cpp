// A walk over a whole ROS 1 bag before librosbag opens it. librosbag trusts the file: it grows
// buffers to whatever record lengths claim (a fuzzed 400-byte bag made it allocate 2.3 GB),
// reads as many connection / chunk-info / index records as counts say, parses headers without
// bounds checks, and reads messages at the offsets index entries give inside decompressed
// chunks (a fuzzed bag made it read far outside the buffer). So everything librosbag reads on
// opening and iterating a bag is checked here first:
// - every top-level record's header and data lengths fit in the file, headers parse strictly;
// - the bag header's index_pos starts `connection_count` connection records followed by
//   `chunk_count` chunk-info records, whose data lengths match their counts;
// - each chunk info points at a chunk, decompressed here to exactly its declared size, whose
//   records tile it; after the chunk follow one index record per connection the chunk info
//   lists, each entry pointing at a message-data record start of that chunk, for a connection
//   that exists.
#include "ros1_bag_check.hpp"

#include <algorithm>
#include <cstring>
#include <set>
#include <string>
#include <vector>

#include "ros1_bag_check_detail.hpp"
#include "scfloam/error.hpp"

namespace scfloam {
namespace {

using namespace ros1_check;

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::uint64_t kMagicSize = sizeof(kMagic) - 1;
constexpr std::uint8_t kOpIndexData = 0x04, kOpChunk = 0x05, kOpChunkInfo = 0x06,
                       kOpConnection = 0x07, kOpFileHeader = 0x03;

struct Record {
  std::uint64_t pos = 0, data_pos = 0, data_len = 0;
  Fields fields;
  std::optional<std::uint8_t> op;
};

class BagWalk {
 public:
  explicit BagWalk(const std::filesystem::path& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw file_error(path, "cannot open");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<std::uint64_t>(in_.tellg());
    char magic[kMagicSize];
    in_.seekg(0);
    in_.read(magic, kMagicSize);
    if (!in_ || std::memcmp(magic, kMagic, kMagicSize) != 0)
      throw file_error(path, "not a ROS 1 bag 2.0 (no '#ROSBAG V2.0' line)");
  }

  void run() {
    read_top_level();
    const Record& header = records_.front();
    if (header.op != kOpFileHeader) fail("the first record is not the bag header (op 0x03)");
    const auto index_pos = u64_field(header.fields, "index_pos");
    const auto connection_count = u32_field(header.fields, "conn_count");
    const auto chunk_count = u32_field(header.fields, "chunk_count");
    if (!index_pos || !connection_count || !chunk_count)
      fail("the bag header lacks index_pos, conn_count or chunk_count (or has a wrong size)");
    if (*index_pos == 0) fail("the bag is not indexed (index_pos 0): run `rosbag reindex` on it");
    const auto encryptor = header.fields.find("encryptor");
    if (encryptor != header.fields.end() && !encryptor->second.empty() &&
        encryptor->second != "rosbag/NoEncryptor")
      fail("encrypted bags (" + encryptor->second + ") are not supported");

    // The index section: connections, then chunk infos, read in sequence by librosbag.
    // An empty bag's index_pos is the end of the file: nothing is read there.
    std::size_t i = *index_pos == size_ ? records_.size() : record_at(*index_pos, "the bag header's index_pos");
    for (std::uint32_t c = 0; c < *connection_count; ++c, ++i) check_connection(i);
    std::vector<std::size_t> chunk_infos;
    for (std::uint32_t c = 0; c < *chunk_count; ++c, ++i) chunk_infos.push_back(check_chunk_info(i));
    for (const std::size_t info : chunk_infos) check_chunk(info);
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const {
    throw file_error(path_, "ROS 1 bag: " + problem);
  }

  std::vector<std::uint8_t> read_bytes(std::uint64_t pos, std::uint64_t len) {
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(len));
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(pos));
    in_.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(len));
    if (!in_) fail("cannot read " + std::to_string(len) + " bytes at byte " + std::to_string(pos));
    return bytes;
  }

  // Length field at `pos`, which must leave room for itself in the file.
  std::uint64_t length_at(std::uint64_t pos, const char* what) {
    if (size_ - pos < 4) fail(std::string("truncated ") + what + " length at byte " + std::to_string(pos));
    const std::uint64_t n = le32(read_bytes(pos, 4).data());
    if (n > size_ - pos - 4)
      fail(std::string("a record's ") + what + " length (" + std::to_string(n) +
           " bytes) runs past the end of the file at byte " + std::to_string(pos));
    return n;
  }

  void read_top_level() {
    for (std::uint64_t pos = kMagicSize; pos < size_;) {
      Record r;
      r.pos = pos;
      const std::uint64_t header_len = length_at(pos, "header");
      if (header_len > kMaxHeaderSize)
        fail("a record header of " + std::to_string(header_len) + " bytes at byte " + std::to_string(pos));
      const std::vector<std::uint8_t> header = read_bytes(pos + 4, header_len);
      const std::string problem = parse_header(header.data(), header.size(), r.fields);
      if (!problem.empty()) fail("the record at byte " + std::to_string(pos) + ": " + problem);
      r.op = u8_field(r.fields, "op");
      r.data_len = length_at(pos + 4 + header_len, "data");
      r.data_pos = pos + 8 + header_len;
      pos = r.data_pos + r.data_len;
      index_of_.emplace(r.pos, records_.size());
      records_.push_back(std::move(r));
    }
    if (records_.empty()) fail("no bag header record after the version line");
  }

  // The index of the top-level record starting exactly at `pos`.
  std::size_t record_at(std::uint64_t pos, const std::string& what) {
    const auto it = index_of_.find(pos);
    if (it == index_of_.end())
      fail(what + " points at byte " + std::to_string(pos) + ", where no record starts");
    return it->second;
  }

  const Record& record(std::size_t i, const std::string& what) {
    if (i >= records_.size()) fail("the file ends before " + what);
    return records_[i];
  }

  void check_connection(std::size_t i) {
    const Record& r = record(i, "all connection records the bag header counts");
    const std::string where = "the connection record at byte " + std::to_string(r.pos);
    const auto id = u32_field(r.fields, "conn");
    const auto topic = r.fields.find("topic");
    if (r.op != kOpConnection || !id || topic == r.fields.end() || topic->second.empty())
      fail(where + " is not a connection record with a conn id and a topic");
    // Its data is a second header (type, md5sum, message_definition), parsed by librosbag.
    if (r.data_len > kMaxHeaderSize) fail(where + " has a connection header over 1 MiB");
    const std::vector<std::uint8_t> data = read_bytes(r.data_pos, r.data_len);
    Fields connection_header;
    const std::string problem = parse_header(data.data(), data.size(), connection_header);
    if (!problem.empty()) fail(where + ": " + problem);
    connections_.insert(*id);
  }

  std::size_t check_chunk_info(std::size_t i) {
    const Record& r = record(i, "all chunk-info records the bag header counts");
    const std::string where = "the chunk-info record at byte " + std::to_string(r.pos);
    const auto count = u32_field(r.fields, "count");
    if (r.op != kOpChunkInfo || u32_field(r.fields, "ver") != 1u || !u64_field(r.fields, "chunk_pos") ||
        !u64_field(r.fields, "start_time") || !u64_field(r.fields, "end_time") || !count)
      fail(where + " is not a version-1 chunk info with chunk_pos, start/end time and count");
    if (r.data_len != std::uint64_t(*count) * 8)
      fail(where + " counts " + std::to_string(*count) + " connections but holds " +
           std::to_string(r.data_len) + " bytes");
    return i;
  }

  // The chunk a chunk info points at, and the index records librosbag reads after it.
  void check_chunk(std::size_t info_index) {
    const Record& info = records_[info_index];
    std::set<std::uint32_t> listed;  // librosbag keys the counts by connection: repeats collapse
    const std::vector<std::uint8_t> counts = read_bytes(info.data_pos, info.data_len);
    for (std::size_t k = 0; k + 8 <= counts.size(); k += 8) listed.insert(le32(&counts[k]));

    const std::size_t c = record_at(*u64_field(info.fields, "chunk_pos"),
                                    "the chunk info at byte " + std::to_string(info.pos));
    const Record& chunk = records_[c];
    const std::string where = "the chunk at byte " + std::to_string(chunk.pos);
    const auto compression = chunk.fields.find("compression");
    const auto size = u32_field(chunk.fields, "size");
    if (chunk.op != kOpChunk || compression == chunk.fields.end() || !size)
      fail(where + " is not a chunk record with compression and size");
    auto cached = message_starts_.find(chunk.pos);
    if (cached == message_starts_.end())
      cached = message_starts_
                   .emplace(chunk.pos, walk_chunk(in_, path_, chunk.pos, chunk.data_pos, chunk.data_len,
                                                  compression->second, *size))
                   .first;
    for (std::size_t k = 1; k <= listed.size(); ++k)
      check_index(c + k, where, cached->second);
  }

  void check_index(std::size_t i, const std::string& chunk_where,
                   const std::vector<std::uint32_t>& message_starts) {
    const Record& r = record(i, "the index records of " + chunk_where);
    const std::string where = "the index record at byte " + std::to_string(r.pos);
    const auto connection = u32_field(r.fields, "conn");
    const auto count = u32_field(r.fields, "count");
    if (r.op != kOpIndexData || u32_field(r.fields, "ver") != 1u || !connection || !count)
      fail(where + " (after " + chunk_where + ") is not a version-1 index record with conn and count");
    if (!connections_.count(*connection))
      fail(where + " indexes connection " + std::to_string(*connection) + ", which has no connection record");
    if (r.data_len != std::uint64_t(*count) * 12)
      fail(where + " counts " + std::to_string(*count) + " entries but holds " +
           std::to_string(r.data_len) + " bytes");
    const std::vector<std::uint8_t> entries = read_bytes(r.data_pos, r.data_len);
    for (std::size_t k = 0; k < entries.size(); k += 12) {
      const std::uint32_t offset = le32(&entries[k + 8]);
      if (!std::binary_search(message_starts.begin(), message_starts.end(), offset))
        fail(where + ": an entry points at byte " + std::to_string(offset) + " of " + chunk_where +
             ", where no message-data record starts");
    }
  }

  const std::filesystem::path& path_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
  std::vector<Record> records_;
  std::map<std::uint64_t, std::size_t> index_of_;
  std::set<std::uint32_t> connections_;
  std::map<std::uint64_t, std::vector<std::uint32_t>> message_starts_;
};

}  // namespace

void check_ros1_bag_records(const std::filesystem::path& path) { BagWalk(path).run(); }

}  // namespace scfloam
