// Bounds-checked readers of the two message serializations: ROS 1 (little-endian, packed,
// uint32 length before strings and arrays) and CDR / XCDR1 as ROS 2 writes it (a 4-byte
// encapsulation header giving the byte order, then every primitive aligned to its size
// counted from the end of that header; strings carry their terminating NUL).
#pragma once

#include <cstdint>
#include <cstring>
#include <string>

#include "scfloam/error.hpp"

namespace scfloam {

class WireReader {
 public:
  // `origin` is where alignment counts from (CDR: just after the encapsulation header).
  WireReader(const std::uint8_t* bytes, std::size_t size, std::size_t pos, bool big_endian,
             bool aligned, const std::string& where)
      : bytes_(bytes), size_(size), pos_(pos), origin_(pos), swap_(big_endian == host_little()),
        aligned_(aligned), where_(where) {}

  template <typename T>
  T read(const char* what) {
    align(sizeof(T), what);
    need(sizeof(T), what);
    std::uint8_t b[sizeof(T)];
    std::memcpy(b, bytes_ + pos_, sizeof(T));
    if (swap_)
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    T v;
    std::memcpy(&v, b, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }

  // A string: uint32 length then bytes; CDR counts (and requires) the trailing NUL.
  std::string read_string(const char* what) {
    const std::uint32_t n = read<std::uint32_t>(what);
    need(n, what);
    std::size_t len = n;
    if (aligned_ && len > 0 && bytes_[pos_ + len - 1] == 0) --len;
    std::string s(reinterpret_cast<const char*>(bytes_ + pos_), len);
    pos_ += n;
    return s;
  }

  // `n` raw bytes at the current position (returned in place, not copied).
  const std::uint8_t* take(std::size_t n, const char* what) {
    need(n, what);
    const std::uint8_t* p = bytes_ + pos_;
    pos_ += n;
    return p;
  }

  std::size_t remaining() const { return size_ - pos_; }

  [[noreturn]] void fail(const std::string& problem) const {
    throw Error(where_ + ": " + problem);
  }

 private:
  static bool host_little() {
    const std::uint16_t one = 1;
    std::uint8_t first;
    std::memcpy(&first, &one, 1);
    return first == 1;
  }
  void align(std::size_t n, const char* what) {
    if (!aligned_) return;
    const std::size_t rel = pos_ - origin_;
    const std::size_t pad = (n - rel % n) % n;
    need(pad, what);
    pos_ += pad;
  }
  void need(std::size_t n, const char* what) const {
    if (n > size_ - pos_)
      fail(std::string("message truncated while reading ") + what + " (needs " +
           std::to_string(n) + " bytes at offset " + std::to_string(pos_) + ", message has " +
           std::to_string(size_) + ")");
  }

  const std::uint8_t* bytes_;
  std::size_t size_, pos_, origin_;
  bool swap_;
  bool aligned_;
  const std::string& where_;
};

}  // namespace scfloam
