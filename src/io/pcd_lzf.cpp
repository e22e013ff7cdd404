#include <array>
#include <cstdint>

#include "scfloam/io/lzf.hpp"

namespace scfloam {
namespace {

constexpr std::size_t kMaxLiteral = 32;
constexpr std::size_t kMaxOffset = 8192;
constexpr std::size_t kMaxMatch = 264;

void flush_literals(const unsigned char* data, std::size_t begin, std::size_t end,
                    std::vector<unsigned char>& out) {
  while (begin < end) {
    const std::size_t n = std::min(kMaxLiteral, end - begin);
    out.push_back(static_cast<unsigned char>(n - 1));
    out.insert(out.end(), data + begin, data + begin + n);
    begin += n;
  }
}

}  // namespace

std::vector<unsigned char> lzf_compress(const unsigned char* data, std::size_t size) {
  std::vector<unsigned char> out;
  out.reserve(size / 2 + 16);
  constexpr int kHashBits = 14;
  std::vector<std::int64_t> table(std::size_t{1} << kHashBits, -1);
  std::size_t literal_begin = 0, i = 0;
  while (i + 2 < size) {
    const std::uint32_t key = data[i] << 16 | data[i + 1] << 8 | data[i + 2];
    const std::uint32_t h = (key * 2654435761u) >> (32 - kHashBits);
    const std::int64_t candidate = table[h];
    table[h] = static_cast<std::int64_t>(i);
    if (candidate >= 0 && i - candidate - 1 < kMaxOffset && data[candidate] == data[i] &&
        data[candidate + 1] == data[i + 1] && data[candidate + 2] == data[i + 2]) {
      flush_literals(data, literal_begin, i, out);
      std::size_t len = 3;
      const std::size_t max_len = std::min(kMaxMatch, size - i);
      while (len < max_len && data[candidate + len] == data[i + len]) ++len;
      const std::size_t offset = i - candidate - 1;
      const std::size_t code = len - 2;  // 1..262
      if (code < 7) {
        out.push_back(static_cast<unsigned char>(code << 5 | offset >> 8));
      } else {
        out.push_back(static_cast<unsigned char>(7 << 5 | offset >> 8));
        out.push_back(static_cast<unsigned char>(code - 7));
      }
      out.push_back(static_cast<unsigned char>(offset & 0xff));
      i += len;
      literal_begin = i;
    } else {
      ++i;
    }
  }
  flush_literals(data, literal_begin, size, out);
  return out;
}

std::optional<std::vector<unsigned char>> lzf_decompress(const unsigned char* data, std::size_t size,
                                                         std::size_t expected_size) {
  std::vector<unsigned char> out;
  out.reserve(expected_size);
  std::size_t ip = 0;
  while (ip < size) {
    const unsigned ctrl = data[ip++];
    if (ctrl < 32) {
      const std::size_t n = ctrl + 1;
      if (ip + n > size || out.size() + n > expected_size) return std::nullopt;
      out.insert(out.end(), data + ip, data + ip + n);
      ip += n;
      continue;
    }
    std::size_t len = ctrl >> 5;
    if (len == 7) {
      if (ip >= size) return std::nullopt;
      len += data[ip++];
    }
    len += 2;
    if (ip >= size) return std::nullopt;
    const std::size_t back = ((ctrl & 0x1f) << 8) + data[ip++] + 1;
    if (back > out.size() || out.size() + len > expected_size) return std::nullopt;
    // Byte by byte: a reference may overlap the bytes it produces (runs).
    for (std::size_t k = 0, from = out.size() - back; k < len; ++k) out.push_back(out[from + k]);
  }
  if (out.size() != expected_size) return std::nullopt;
  return out;
}

}  // namespace scfloam
