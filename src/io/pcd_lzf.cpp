// Thin wrapper over Debian's liblzf (the codec PCL uses for PCD binary_compressed): sizes as
// std::size_t, a refusal instead of liblzf's 32-bit truncation, and a bound on the claimed size
// so that a corrupt header cannot make us allocate gigabytes before the stream is read.
#include <lzf.h>

#include <limits>
#include <stdexcept>
#include <string>

#include "scfloam/io/lzf.hpp"

namespace scfloam {
namespace {

constexpr std::size_t kMaxLength = std::numeric_limits<unsigned int>::max();
// The densest LZF token is a 3-byte back reference that writes 264 bytes.
constexpr std::size_t kMaxExpansion = 88;

}  // namespace

std::vector<unsigned char> lzf_compress(const unsigned char* data, std::size_t size) {
  // Incompressible data grows by one control byte per 32 literals; liblzf also wants a few
  // bytes of slack at the end of its output buffer.
  const std::size_t capacity = size + size / 32 + 64;
  if (capacity > kMaxLength) throw std::length_error("LZF input of " + std::to_string(size) + " bytes is over 4 GiB");
  if (size == 0) return {};
  std::vector<unsigned char> out(capacity);
  const unsigned int n = ::lzf_compress(data, static_cast<unsigned int>(size), out.data(),
                                        static_cast<unsigned int>(capacity));
  if (n == 0) throw std::runtime_error("liblzf could not compress " + std::to_string(size) + " bytes");
  out.resize(n);
  return out;
}

std::optional<std::vector<unsigned char>> lzf_decompress(const unsigned char* data, std::size_t size,
                                                         std::size_t expected_size) {
  if (expected_size == 0) return size == 0 ? std::optional<std::vector<unsigned char>>(std::vector<unsigned char>{})
                                           : std::nullopt;
  if (size == 0 || size > kMaxLength || expected_size > kMaxLength || expected_size / kMaxExpansion > size)
    return std::nullopt;
  std::vector<unsigned char> out(expected_size);
  const unsigned int n = ::lzf_decompress(data, static_cast<unsigned int>(size), out.data(),
                                          static_cast<unsigned int>(expected_size));
  if (n != expected_size) return std::nullopt;  // corrupt (EINVAL), too long (E2BIG) or too short
  return out;
}

}  // namespace scfloam
