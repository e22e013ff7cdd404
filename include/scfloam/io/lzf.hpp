// LZF, the compression of PCD's `DATA binary_compressed` (liblzf's format: literal runs of up
// to 32 bytes and back references of up to 264 bytes within 8 KiB).
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace scfloam {

std::vector<unsigned char> lzf_compress(const unsigned char* data, std::size_t size);
// nullopt when the stream is corrupt or does not decode to exactly `expected_size` bytes.
std::optional<std::vector<unsigned char>> lzf_decompress(const unsigned char* data, std::size_t size,
                                                         std::size_t expected_size);

}  // namespace scfloam
