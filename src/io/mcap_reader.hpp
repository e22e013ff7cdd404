// A reader of MCAP files (https://mcap.dev/spec), written here because Debian packages none.
// It indexes every message at open time (from the summary's chunk and message indexes when
// they are complete, else by one sequential pass that decompresses each chunk once) and then
// reads single messages by position, so memory does not grow with the file size.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace scfloam {

struct McapSchema {
  std::uint16_t id = 0;
  std::string name, encoding;
};

struct McapChannel {
  std::uint16_t id = 0, schema_id = 0;
  std::string topic, message_encoding;
};

// Where one message lives: a top-level Message record, or a record inside a chunk.
struct McapMessageRef {
  std::uint64_t log_time_ns = 0;
  std::uint64_t chunk_offset = 0;   // file offset of the Chunk record; kNoChunk when top-level
  std::uint64_t record_offset = 0;  // of the Message record: in the file, or in the chunk's records
  std::uint16_t channel_id = 0;
  static constexpr std::uint64_t kNoChunk = ~std::uint64_t{0};
};

// MCAP opcodes (spec section "Records").
enum class McapOp : std::uint8_t {
  Header = 0x01, Footer = 0x02, Schema = 0x03, Channel = 0x04, Message = 0x05, Chunk = 0x06,
  MessageIndex = 0x07, ChunkIndex = 0x08, Attachment = 0x09, AttachmentIndex = 0x0A,
  Statistics = 0x0B, Metadata = 0x0C, MetadataIndex = 0x0D, SummaryOffset = 0x0E, DataEnd = 0x0F
};
std::string mcap_op_name(std::uint8_t op);  // "Message", ..., "Unknown(0x42)"

class McapFile {
 public:
  // Error naming the file for anything that is not a readable MCAP file.
  static std::unique_ptr<McapFile> open(const std::filesystem::path& path);
  ~McapFile();

  const std::filesystem::path& path() const { return path_; }
  const std::map<std::uint16_t, McapSchema>& schemas() const { return schemas_; }
  const std::map<std::uint16_t, McapChannel>& channels() const { return channels_; }
  // Every message of the file ordered by log time (file order among equal times).
  const std::vector<McapMessageRef>& messages() const { return messages_; }
  bool indexed_from_summary() const { return from_summary_; }

  // The payload of one message. Thread-safe.
  void read(const McapMessageRef& ref, std::vector<std::uint8_t>& payload) const;

  // Calls `visit(op, body, size)` for every record in file order, entering chunks (whose
  // inner records are visited in place of the Chunk; Chunk and MessageIndex records are
  // visited too, flagged by their opcode). For tests and `info`.
  void walk(const std::function<void(std::uint8_t op, const std::uint8_t* body,
                                     std::uint64_t size, bool in_chunk)>& visit) const;

 private:
  McapFile() = default;
  void read_at(std::uint64_t offset, void* out, std::uint64_t size) const;
  std::vector<std::uint8_t> read_record(std::uint64_t offset, std::uint8_t& op) const;
  std::shared_ptr<const std::vector<std::uint8_t>> chunk_records(std::uint64_t chunk_offset) const;
  bool index_from_summary();
  void index_sequentially();
  [[noreturn]] void fail(const std::string& problem) const;

  std::filesystem::path path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
  std::map<std::uint16_t, McapSchema> schemas_;
  std::map<std::uint16_t, McapChannel> channels_;
  std::vector<McapMessageRef> messages_;
  bool from_summary_ = false;
  // The last decompressed chunk: consecutive messages usually share one.
  mutable std::mutex cache_mutex_;
  mutable std::uint64_t cached_chunk_offset_ = McapMessageRef::kNoChunk;
  mutable std::shared_ptr<const std::vector<std::uint8_t>> cached_chunk_;
};

}  // namespace scfloam
