// Pieces of the ROS 1 bag pre-walk (ros1_bag_check.cpp): strict record-header parsing and the
// walk over one chunk's uncompressed records. Internal to src/io.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace scfloam::ros1_check {

// Chunks claiming more than this uncompressed size are refused before anything is allocated.
constexpr std::uint64_t kMaxChunkSize = std::uint64_t(1) << 30;  // 1 GiB
// Record headers are a few "name=value" fields; librosbag parses them whole.
constexpr std::uint64_t kMaxHeaderSize = std::uint64_t(1) << 20;  // 1 MiB

using Fields = std::map<std::string, std::string>;

// Parses "uint32 length, name=value" fields the way librosbag's ros::Header::parse reads them,
// but refuses what that parser would read out of bounds: a field length running past the
// header, a field with no '=', a repeated name. Returns an empty string or the problem.
std::string parse_header(const std::uint8_t* data, std::size_t size, Fields& fields);

// Typed field values with librosbag's exact sizes (uint8 op, uint32, uint64); nullopt when the
// field is missing or has another size.
std::optional<std::uint8_t> u8_field(const Fields& fields, const std::string& name);
std::optional<std::uint32_t> u32_field(const Fields& fields, const std::string& name);
std::optional<std::uint64_t> u64_field(const Fields& fields, const std::string& name);

std::uint32_t le32(const std::uint8_t* p);

// Decompresses one chunk's data (compression "none", "bz2" or "lz4") streaming from `in`,
// checks that it comes out exactly `declared_size` bytes and that the records inside tile it,
// and returns the offsets (within the uncompressed data) where message-data records (op 0x02)
// start: the only places an index entry may point at. Throws Error naming the file.
std::vector<std::uint32_t> walk_chunk(std::ifstream& in, const std::filesystem::path& path,
                                      std::uint64_t chunk_pos, std::uint64_t data_pos,
                                      std::uint64_t data_len, const std::string& compression,
                                      std::uint32_t declared_size);

}  // namespace scfloam::ros1_check
