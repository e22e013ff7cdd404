#include "mcap_reader.hpp"

#include <fcntl.h>
#include <lz4frame.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>

#include "scfloam/error.hpp"

namespace scfloam {
namespace {

constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr std::uint64_t kRecordHeader = 9;          // opcode + uint64 length
constexpr std::uint64_t kMaxChunkBytes = 1ull << 30;  // refuse absurd sizes from corrupt files

// Little-endian fields of one record body, bounds-checked.
class Cursor {
 public:
  Cursor(const std::uint8_t* p, std::uint64_t n, const McapFile& file, std::string record)
      : p_(p), n_(n), file_(file), record_(std::move(record)) {}
  template <typename T>
  T num() {
    need(sizeof(T));
    T v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) v |= static_cast<T>(p_[pos_ + i]) << (8 * i);
    pos_ += sizeof(T);
    return v;
  }
  std::string str() {
    const std::uint32_t len = num<std::uint32_t>();
    need(len);
    std::string s(reinterpret_cast<const char*>(p_ + pos_), len);
    pos_ += len;
    return s;
  }
  void skip(std::uint64_t len) { need(len); pos_ += len; }
  const std::uint8_t* here() const { return p_ + pos_; }
  std::uint64_t left() const { return n_ - pos_; }

 private:
  void need(std::uint64_t len) const {
    if (len > n_ - pos_)
      throw file_error(file_.path(), std::string("corrupt MCAP ") + record_ + " record (field runs past its end)");
  }
  const std::uint8_t* p_;
  std::uint64_t n_, pos_ = 0;
  const McapFile& file_;
  std::string record_;
};

std::vector<std::uint8_t> decompress(const std::string& compression, const std::uint8_t* src,
                                     std::uint64_t size, std::uint64_t uncompressed_size,
                                     const std::filesystem::path& path) {
  if (uncompressed_size > kMaxChunkBytes)
    throw file_error(path, "MCAP chunk claims " + std::to_string(uncompressed_size) + " bytes");
  if (compression == "zstd") {
    // A corrupt size field must not make us allocate before zstd has looked at the frame.
    const unsigned long long framed = ZSTD_getFrameContentSize(src, size);
    if (framed == ZSTD_CONTENTSIZE_ERROR ||
        (framed != ZSTD_CONTENTSIZE_UNKNOWN && framed != uncompressed_size))
      throw file_error(path, "bad zstd chunk (frame header disagrees with the chunk record)");
  }
  // Refuse a size the compressed bytes cannot produce before allocating it (found by
  // fuzz/mcap_fuzz: a stored chunk claiming 2 GB): stored chunks are exactly their size, and
  // LZ4 expands at most 255:1.
  if (compression.empty() && size != uncompressed_size)
    throw file_error(path, "MCAP chunk size mismatch");
  if (compression == "lz4" && uncompressed_size / 255 > size + 64)
    throw file_error(path, "bad lz4 chunk: claims more bytes than its data can hold");
  std::vector<std::uint8_t> out(uncompressed_size);
  if (compression.empty()) {
    if (size != uncompressed_size) throw file_error(path, "MCAP chunk size mismatch");
    std::copy(src, src + size, out.begin());
  } else if (compression == "zstd") {
    const std::size_t got = ZSTD_decompress(out.data(), out.size(), src, size);
    if (ZSTD_isError(got) || got != uncompressed_size)
      throw file_error(path, std::string("bad zstd chunk: ") +
                                 (ZSTD_isError(got) ? ZSTD_getErrorName(got) : "size mismatch"));
  } else if (compression == "lz4") {
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION)))
      throw file_error(path, "cannot create an lz4 context");
    std::size_t in_pos = 0, out_pos = 0, status = 1;
    while (status != 0 && in_pos < size) {
      std::size_t in_n = size - in_pos, out_n = out.size() - out_pos;
      status = LZ4F_decompress(ctx, out.data() + out_pos, &out_n, src + in_pos, &in_n, nullptr);
      if (LZ4F_isError(status)) {
        LZ4F_freeDecompressionContext(ctx);
        throw file_error(path, std::string("bad lz4 chunk: ") + LZ4F_getErrorName(status));
      }
      in_pos += in_n;
      out_pos += out_n;
      if (in_n == 0 && out_n == 0) break;
    }
    LZ4F_freeDecompressionContext(ctx);
    if (out_pos != uncompressed_size) throw file_error(path, "bad lz4 chunk: size mismatch");
  } else {
    throw file_error(path, "unsupported MCAP chunk compression '" + compression + "'");
  }
  return out;
}

McapMessageRef parse_message_header(Cursor& c, McapMessageRef ref) {
  ref.channel_id = c.num<std::uint16_t>();
  c.num<std::uint32_t>();  // sequence
  ref.log_time_ns = c.num<std::uint64_t>();
  c.num<std::uint64_t>();  // publish_time
  return ref;
}

}  // namespace

std::string mcap_op_name(std::uint8_t op) {
  static const char* names[] = {"",           "Header",          "Footer",        "Schema",
                                "Channel",    "Message",         "Chunk",         "MessageIndex",
                                "ChunkIndex", "Attachment",      "AttachmentIndex", "Statistics",
                                "Metadata",   "MetadataIndex",   "SummaryOffset", "DataEnd"};
  if (op >= 1 && op <= 0x0F) return names[op];
  static const char* hex = "0123456789abcdef";
  return std::string("Unknown(0x") + hex[op >> 4] + hex[op & 15] + ")";
}

McapFile::~McapFile() {
  if (fd_ >= 0) ::close(fd_);
}

void McapFile::fail(const std::string& problem) const { throw file_error(path_, problem); }

void McapFile::read_at(std::uint64_t offset, void* out, std::uint64_t size) const {
  if (offset > size_ || size > size_ - offset)
    fail("MCAP truncated: needs bytes " + std::to_string(offset) + ".." +
         std::to_string(offset + size) + " of a " + std::to_string(size_) + "-byte file");
  auto* dst = static_cast<std::uint8_t*>(out);
  while (size > 0) {
    const ssize_t got = ::pread(fd_, dst, size, static_cast<off_t>(offset));
    if (got <= 0) fail("read error at offset " + std::to_string(offset));
    dst += got;
    offset += static_cast<std::uint64_t>(got);
    size -= static_cast<std::uint64_t>(got);
  }
}

std::vector<std::uint8_t> McapFile::read_record(std::uint64_t offset, std::uint8_t& op) const {
  std::uint8_t head[kRecordHeader];
  read_at(offset, head, kRecordHeader);
  op = head[0];
  std::uint64_t len = 0;
  for (int i = 0; i < 8; ++i) len |= std::uint64_t{head[1 + i]} << (8 * i);
  if (len > size_ - offset - kRecordHeader)
    fail("MCAP truncated: " + mcap_op_name(op) + " record at offset " + std::to_string(offset) +
         " claims " + std::to_string(len) + " bytes past the end of the file");
  std::vector<std::uint8_t> body(len);
  read_at(offset + kRecordHeader, body.data(), len);
  return body;
}

std::unique_ptr<McapFile> McapFile::open(const std::filesystem::path& path) {
  std::unique_ptr<McapFile> f(new McapFile());
  f->path_ = path;
  f->fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (f->fd_ < 0) f->fail("cannot open");
  const off_t end = ::lseek(f->fd_, 0, SEEK_END);
  if (end < 0) f->fail("cannot seek");
  f->size_ = static_cast<std::uint64_t>(end);
  std::uint8_t magic[8];
  if (f->size_ < 8) f->fail("not an MCAP file (" + std::to_string(f->size_) + " bytes)");
  f->read_at(0, magic, 8);
  if (std::memcmp(magic, kMagic, 8) != 0) f->fail("not an MCAP file (bad magic)");
  if (!f->index_from_summary()) f->index_sequentially();
  std::stable_sort(f->messages_.begin(), f->messages_.end(),
                   [](const McapMessageRef& a, const McapMessageRef& b) {
                     return a.log_time_ns < b.log_time_ns;
                   });
  return f;
}

bool McapFile::index_from_summary() {
  const std::uint64_t footer_size = kRecordHeader + 20;
  if (size_ < 8 + footer_size + 8) return false;
  const std::uint64_t footer_at = size_ - 8 - footer_size;
  std::uint8_t tail[footer_size + 8];
  read_at(footer_at, tail, sizeof tail);
  if (std::memcmp(tail + footer_size, kMagic, 8) != 0 || tail[0] != 0x02) return false;
  Cursor footer(tail + kRecordHeader, 20, *this, "Footer");
  const std::uint64_t summary_start = footer.num<std::uint64_t>();
  if (summary_start == 0 || summary_start >= footer_at) return false;

  std::vector<std::uint8_t> summary(footer_at - summary_start);
  read_at(summary_start, summary.data(), summary.size());
  struct ChunkIndexEntry { std::uint64_t chunk_offset; std::vector<std::uint64_t> index_offsets; };
  std::vector<ChunkIndexEntry> chunk_indexes;
  bool have_statistics = false;
  std::uint64_t message_count = 0;
  Cursor records(summary.data(), summary.size(), *this, "summary");
  while (records.left() > 0) {
    const std::uint8_t op = records.num<std::uint8_t>();
    const std::uint64_t len = records.num<std::uint64_t>();
    Cursor c(records.here(), std::min(len, records.left()), *this, mcap_op_name(op));
    records.skip(len);
    if (op == 0x03) {
      McapSchema s;
      s.id = c.num<std::uint16_t>();
      s.name = c.str();
      s.encoding = c.str();
      schemas_[s.id] = s;
    } else if (op == 0x04) {
      McapChannel ch;
      ch.id = c.num<std::uint16_t>();
      ch.schema_id = c.num<std::uint16_t>();
      ch.topic = c.str();
      ch.message_encoding = c.str();
      channels_[ch.id] = ch;
    } else if (op == 0x08) {
      c.num<std::uint64_t>();  // message_start_time
      c.num<std::uint64_t>();  // message_end_time
      ChunkIndexEntry e;
      e.chunk_offset = c.num<std::uint64_t>();
      c.num<std::uint64_t>();  // chunk_length
      const std::uint32_t map_bytes = c.num<std::uint32_t>();
      Cursor m(c.here(), std::min<std::uint64_t>(map_bytes, c.left()), *this, "ChunkIndex");
      c.skip(map_bytes);
      while (m.left() > 0) {
        m.num<std::uint16_t>();
        e.index_offsets.push_back(m.num<std::uint64_t>());
      }
      chunk_indexes.push_back(std::move(e));
    } else if (op == 0x0B) {
      have_statistics = true;
      message_count = c.num<std::uint64_t>();
    }
  }
  if (!have_statistics) return false;

  std::vector<McapMessageRef> refs;
  for (const ChunkIndexEntry& e : chunk_indexes) {
    for (std::uint64_t offset : e.index_offsets) {
      std::uint8_t op = 0;
      const std::vector<std::uint8_t> body = read_record(offset, op);
      if (op != 0x07) return false;
      Cursor c(body.data(), body.size(), *this, "MessageIndex");
      McapMessageRef ref;
      ref.chunk_offset = e.chunk_offset;
      ref.channel_id = c.num<std::uint16_t>();
      const std::uint32_t bytes = c.num<std::uint32_t>();
      if (bytes > c.left() || bytes % 16 != 0) fail("corrupt MCAP MessageIndex record");
      for (std::uint32_t i = 0; i < bytes / 16; ++i) {
        ref.log_time_ns = c.num<std::uint64_t>();
        ref.record_offset = c.num<std::uint64_t>();
        refs.push_back(ref);
      }
    }
  }
  // Messages outside chunks, or chunks without indexes, leave the count short: read it all.
  if (refs.size() != message_count) {
    schemas_.clear();
    channels_.clear();
    return false;
  }
  for (const McapMessageRef& r : refs)
    if (!channels_.count(r.channel_id)) {
      schemas_.clear();
      channels_.clear();
      return false;
    }
  messages_ = std::move(refs);
  from_summary_ = true;
  return true;
}

void McapFile::walk(const std::function<void(std::uint8_t, const std::uint8_t*, std::uint64_t,
                                             bool)>& visit) const {
  std::uint64_t pos = 8;
  while (pos < size_) {
    if (size_ - pos < kRecordHeader)
      fail("MCAP truncated: partial record header at offset " + std::to_string(pos));
    std::uint8_t op = 0;
    const std::vector<std::uint8_t> body = read_record(pos, op);
    visit(op, body.data(), body.size(), false);
    if (op == 0x06) {
      Cursor c(body.data(), body.size(), *this, "Chunk");
      c.num<std::uint64_t>();
      c.num<std::uint64_t>();
      const std::uint64_t uncompressed = c.num<std::uint64_t>();
      c.num<std::uint32_t>();  // crc
      const std::string compression = c.str();
      const std::uint64_t len = c.num<std::uint64_t>();
      const std::uint8_t* src = c.here();
      c.skip(len);
      const std::vector<std::uint8_t> inner = decompress(compression, src, len, uncompressed, path_);
      Cursor r(inner.data(), inner.size(), *this, "Chunk");
      while (r.left() > 0) {
        const std::uint8_t iop = r.num<std::uint8_t>();
        const std::uint64_t ilen = r.num<std::uint64_t>();
        const std::uint8_t* ibody = r.here();
        r.skip(ilen);
        visit(iop, ibody, ilen, true);
      }
    }
    pos += kRecordHeader + body.size();
    if (op == 0x02) {
      std::uint8_t magic[8];
      read_at(pos, magic, 8);
      if (std::memcmp(magic, kMagic, 8) != 0) fail("MCAP footer not followed by the magic");
      return;
    }
  }
  fail("MCAP truncated: no footer (the recording was probably interrupted)");
}

void McapFile::index_sequentially() {
  // Offsets are needed, so this walks by hand rather than through walk().
  std::uint64_t pos = 8;
  bool footer = false;
  while (pos < size_ && !footer) {
    if (size_ - pos < kRecordHeader)
      fail("MCAP truncated: partial record header at offset " + std::to_string(pos));
    std::uint8_t op = 0;
    const std::vector<std::uint8_t> body = read_record(pos, op);
    auto take = [&](std::uint8_t rop, const std::uint8_t* p, std::uint64_t n, std::uint64_t chunk,
                    std::uint64_t offset) {
      Cursor c(p, n, *this, mcap_op_name(rop));
      if (rop == 0x03) {
        McapSchema s;
        s.id = c.num<std::uint16_t>();
        s.name = c.str();
        s.encoding = c.str();
        schemas_[s.id] = s;
      } else if (rop == 0x04) {
        McapChannel ch;
        ch.id = c.num<std::uint16_t>();
        ch.schema_id = c.num<std::uint16_t>();
        ch.topic = c.str();
        ch.message_encoding = c.str();
        channels_[ch.id] = ch;
      } else if (rop == 0x05) {
        McapMessageRef ref;
        ref.chunk_offset = chunk;
        ref.record_offset = offset;
        messages_.push_back(parse_message_header(c, ref));
      }
    };
    take(op, body.data(), body.size(), McapMessageRef::kNoChunk, pos);
    if (op == 0x06) {
      const auto inner = chunk_records(pos);
      Cursor r(inner->data(), inner->size(), *this, "Chunk");
      while (r.left() > 0) {
        const std::uint64_t offset = inner->size() - r.left();
        const std::uint8_t iop = r.num<std::uint8_t>();
        const std::uint64_t ilen = r.num<std::uint64_t>();
        const std::uint8_t* ibody = r.here();
        r.skip(ilen);
        take(iop, ibody, ilen, pos, offset);
      }
    }
    footer = op == 0x02;
    pos += kRecordHeader + body.size();
  }
  if (!footer) fail("MCAP truncated: no footer (the recording was probably interrupted)");
  for (const McapMessageRef& r : messages_)
    if (!channels_.count(r.channel_id))
      fail("MCAP message refers to unknown channel " + std::to_string(r.channel_id));
}

std::shared_ptr<const std::vector<std::uint8_t>> McapFile::chunk_records(
    std::uint64_t chunk_offset) const {
  {
    std::lock_guard<std::mutex> lock(cache_mutex_);
    if (cached_chunk_ && cached_chunk_offset_ == chunk_offset) return cached_chunk_;
  }
  std::uint8_t op = 0;
  const std::vector<std::uint8_t> body = read_record(chunk_offset, op);
  if (op != 0x06) fail("no MCAP Chunk record at offset " + std::to_string(chunk_offset));
  Cursor c(body.data(), body.size(), *this, "Chunk");
  c.num<std::uint64_t>();
  c.num<std::uint64_t>();
  const std::uint64_t uncompressed = c.num<std::uint64_t>();
  c.num<std::uint32_t>();
  const std::string compression = c.str();
  const std::uint64_t len = c.num<std::uint64_t>();
  const std::uint8_t* src = c.here();
  c.skip(len);
  auto records = std::make_shared<const std::vector<std::uint8_t>>(
      decompress(compression, src, len, uncompressed, path_));
  std::lock_guard<std::mutex> lock(cache_mutex_);
  cached_chunk_offset_ = chunk_offset;
  cached_chunk_ = records;
  return records;
}

void McapFile::read(const McapMessageRef& ref, std::vector<std::uint8_t>& payload) const {
  if (ref.chunk_offset == McapMessageRef::kNoChunk) {
    std::uint8_t op = 0;
    const std::vector<std::uint8_t> body = read_record(ref.record_offset, op);
    if (op != 0x05) fail("no MCAP Message record at offset " + std::to_string(ref.record_offset));
    Cursor c(body.data(), body.size(), *this, "Message");
    parse_message_header(c, ref);
    payload.assign(c.here(), c.here() + c.left());
    return;
  }
  const auto records = chunk_records(ref.chunk_offset);
  if (ref.record_offset > records->size()) fail("MCAP message index points past its chunk");
  Cursor r(records->data() + ref.record_offset, records->size() - ref.record_offset, *this, "Chunk");
  const std::uint8_t op = r.num<std::uint8_t>();
  const std::uint64_t len = r.num<std::uint64_t>();
  if (op != 0x05 || len > r.left()) fail("MCAP message index points at no Message record");
  Cursor c(r.here(), len, *this, "Message");
  parse_message_header(c, ref);
  payload.assign(c.here(), c.here() + c.left());
}

}  // namespace scfloam
