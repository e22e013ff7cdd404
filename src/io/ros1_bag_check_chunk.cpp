// One chunk of a ROS 1 bag, decompressed by us before librosbag: librosbag sizes its buffer from
// the chunk header's `size`, decompresses into it without checking how much came out, and then
// reads records at the offsets the index gives (Bag::readHeaderFromBuffer) with no bounds check.
// Here the chunk is streamed through bz2 / lz4 in 64 KB pieces (nothing sized from the file),
// must come out exactly `size` bytes, and the records inside must tile it.
#include <bzlib.h>
#include <lz4frame.h>

#include <algorithm>
#include <array>
#include <memory>

#include "ros1_bag_check_detail.hpp"
#include "scfloam/error.hpp"

namespace scfloam::ros1_check {
namespace {

constexpr std::size_t kBlock = 64 * 1024;

// Consumes a chunk's uncompressed bytes in any pieces and follows its record lengths.
class RecordTiler {
 public:
  RecordTiler(const std::filesystem::path& path, std::uint64_t chunk_pos, std::uint64_t size)
      : path_(path), chunk_pos_(chunk_pos), size_(size) {}

  void feed(const std::uint8_t* p, std::size_t n) {
    while (n > 0) {
      if (state_ == State::Data) {
        const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(need_, n));
        p += take, n -= take, pos_ += take, need_ -= take;
        if (need_ == 0) state_ = State::HeaderLen;
        continue;
      }
      if (state_ == State::Header) {
        const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(need_, n));
        header_.insert(header_.end(), p, p + take);
        p += take, n -= take, pos_ += take, need_ -= take;
        if (need_ == 0) end_header();
        continue;
      }
      len_[len_have_++] = *p++, --n, ++pos_;  // HeaderLen or DataLen, one byte at a time
      if (len_have_ == 4) end_length();
    }
  }

  // The data ended exactly after a whole record.
  std::vector<std::uint32_t> finish() {
    if (state_ != State::HeaderLen || len_have_ != 0)
      fail("its last record is cut off by the end of the chunk");
    return std::move(message_starts_);
  }

 private:
  enum class State { HeaderLen, Header, DataLen, Data };

  [[noreturn]] void fail(const std::string& problem) const {
    throw file_error(path_, "ROS 1 bag: the chunk at byte " + std::to_string(chunk_pos_) + ": " +
                                problem + " (at uncompressed byte " + std::to_string(pos_) + ")");
  }

  void end_length() {
    const std::uint64_t len = le32(len_);
    len_have_ = 0;
    if (len > size_ - pos_)
      fail("a record's length (" + std::to_string(len) + " bytes) runs past the end of the chunk");
    if (state_ == State::HeaderLen) {
      record_start_ = pos_ - 4;
      if (len > kMaxHeaderSize) fail("a record header of " + std::to_string(len) + " bytes");
      header_.clear();
      need_ = len;
      state_ = State::Header;
      if (len == 0) end_header();
    } else {
      need_ = len;
      state_ = len == 0 ? State::HeaderLen : State::Data;
    }
  }

  void end_header() {
    const std::string problem = parse_header(header_.data(), header_.size(), fields_);
    if (!problem.empty()) fail(problem);
    if (u8_field(fields_, "op") == std::uint8_t{0x02})
      message_starts_.push_back(static_cast<std::uint32_t>(record_start_));
    state_ = State::DataLen;
  }

  const std::filesystem::path& path_;
  std::uint64_t chunk_pos_, size_;
  State state_ = State::HeaderLen;
  std::uint8_t len_[4] = {};
  std::size_t len_have_ = 0;
  std::uint64_t need_ = 0, pos_ = 0, record_start_ = 0;
  std::vector<std::uint8_t> header_;
  Fields fields_;
  std::vector<std::uint32_t> message_starts_;
};

// The chunk's stored bytes, read from the file in blocks as the decompressor takes them.
class StoredBytes {
 public:
  StoredBytes(std::ifstream& in, std::uint64_t pos, std::uint64_t len) : in_(in), left_(len) {
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(pos));
  }
  // Reads the next block once the previous one is used up; false if that read fails.
  bool refill() {
    if (have_ > 0 || left_ == 0) return true;
    have_ = static_cast<std::size_t>(std::min<std::uint64_t>(left_, kBlock));
    in_.read(reinterpret_cast<char*>(block_.data()), static_cast<std::streamsize>(have_));
    left_ -= have_;
    next_ = block_.data();
    return static_cast<bool>(in_);
  }
  std::uint8_t* next_ = nullptr;
  std::size_t have_ = 0;

 private:
  std::ifstream& in_;
  std::uint64_t left_;
  std::array<std::uint8_t, kBlock> block_{};
};

}  // namespace

std::vector<std::uint32_t> walk_chunk(std::ifstream& in, const std::filesystem::path& path,
                                      std::uint64_t chunk_pos, std::uint64_t data_pos,
                                      std::uint64_t data_len, const std::string& compression,
                                      std::uint32_t declared_size) {
  const std::string where = "ROS 1 bag: the chunk at byte " + std::to_string(chunk_pos) + " ";
  if (declared_size > kMaxChunkSize)
    throw file_error(path, where + "claims " + std::to_string(declared_size) +
                               " uncompressed bytes (over 1 GiB)");
  RecordTiler tiler(path, chunk_pos, declared_size);
  auto stored = std::make_unique<StoredBytes>(in, data_pos, data_len);
  std::uint64_t out_total = 0;
  std::array<std::uint8_t, kBlock> out{};
  // At most one byte past the declared size is asked for: enough to tell "too long".
  auto room = [&] { return static_cast<std::size_t>(std::min<std::uint64_t>(kBlock, declared_size - out_total + 1)); };
  auto too_long = [&] {
    if (out_total > declared_size)
      throw file_error(path, where + "decompresses to more than its declared " +
                                 std::to_string(declared_size) + " bytes");
  };
  auto wrong_length = [&] {
    throw file_error(path, where + "decompresses to " + std::to_string(out_total) +
                               " bytes, but its header declares " + std::to_string(declared_size));
  };

  auto refill = [&] {
    if (!stored->refill()) throw file_error(path, where + "cannot be read");
  };
  // A decompressor call that neither took input nor gave output: the stream is cut off.
  auto stalled = [&](std::size_t took, std::size_t gave, const char* what) {
    if (took == 0 && gave == 0)
      throw file_error(path, where + "ends inside its " + what);
  };

  if (compression == "none") {
    if (data_len != declared_size)
      throw file_error(path, where + "(uncompressed) holds " + std::to_string(data_len) +
                                 " bytes, but its header declares " + std::to_string(declared_size));
    for (refill(); stored->have_ > 0; refill()) {
      tiler.feed(stored->next_, stored->have_);
      stored->have_ = 0;
    }
    return tiler.finish();
  }
  if (compression == "bz2") {
    bz_stream bz{};
    if (BZ2_bzDecompressInit(&bz, 0, 0) != BZ_OK) throw file_error(path, where + "cannot start bzip2");
    std::unique_ptr<bz_stream, int (*)(bz_stream*)> guard(&bz, BZ2_bzDecompressEnd);
    for (int rc = BZ_OK; rc != BZ_STREAM_END;) {
      refill();
      bz.next_in = reinterpret_cast<char*>(stored->next_);
      bz.avail_in = static_cast<unsigned>(stored->have_);
      bz.next_out = reinterpret_cast<char*>(out.data());
      bz.avail_out = static_cast<unsigned>(room());
      const std::size_t offered = bz.avail_in, asked = bz.avail_out;
      rc = BZ2_bzDecompress(&bz);
      if (rc != BZ_OK && rc != BZ_STREAM_END)
        throw file_error(path, where + "holds a corrupt bz2 stream (bzip2 error " + std::to_string(rc) + ")");
      const std::size_t took = offered - bz.avail_in, gave = asked - bz.avail_out;
      stored->next_ += took, stored->have_ -= took;
      out_total += gave;
      too_long();
      tiler.feed(out.data(), gave);
      if (rc != BZ_STREAM_END) stalled(took, gave, "bz2 stream");
    }
  } else if (compression == "lz4") {
    LZ4F_dctx* dctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&dctx, LZ4F_VERSION)))
      throw file_error(path, where + "cannot start lz4");
    std::unique_ptr<LZ4F_dctx, LZ4F_errorCode_t (*)(LZ4F_dctx*)> guard(dctx, LZ4F_freeDecompressionContext);
    for (std::size_t hint = 1; hint != 0;) {
      refill();
      std::size_t took = stored->have_, gave = room();
      hint = LZ4F_decompress(dctx, out.data(), &gave, stored->next_, &took, nullptr);
      if (LZ4F_isError(hint))
        throw file_error(path, where + "holds a corrupt lz4 frame (" + LZ4F_getErrorName(hint) + ")");
      stored->next_ += took, stored->have_ -= took;
      out_total += gave;
      too_long();
      tiler.feed(out.data(), gave);
      if (hint != 0) stalled(took, gave, "lz4 frame");
    }
  } else {
    throw file_error(path, where + "has unknown compression '" + compression + "'");
  }
  if (out_total != declared_size) wrong_length();
  return tiler.finish();
}

}  // namespace scfloam::ros1_check
