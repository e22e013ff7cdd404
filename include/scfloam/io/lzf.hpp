// LZF, the compression of PCD's `DATA binary_compressed`, done by Debian's liblzf
// (src/io/pcd_lzf.cpp adapts its 32-bit C interface).
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace scfloam {

// Throws std::length_error over 4 GiB (PCD stores the sizes in 32 bits).
std::vector<unsigned char> lzf_compress(const unsigned char* data, std::size_t size);
// nullopt when the stream is corrupt or does not decode to exactly `expected_size` bytes.
std::optional<std::vector<unsigned char>> lzf_decompress(const unsigned char* data, std::size_t size,
                                                         std::size_t expected_size);

}  // namespace scfloam
