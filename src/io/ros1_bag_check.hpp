// Record-length sanity of a ROS 1 bag 2.0 file, run before librosbag sees it.
#pragma once

#include <filesystem>

namespace scfloam {

// Error naming the file and the problem unless everything librosbag reads when opening the bag
// and reading its messages is in bounds and consistent: record lengths within the file, headers
// that parse, the index section's counts, chunks (decompressed here, streaming) of exactly their
// declared size, index entries at message records of existing connections. Reads the headers
// and index data and decompresses each chunk once; holds no chunk in memory.
void check_ros1_bag_records(const std::filesystem::path& path);

}  // namespace scfloam
