// Record-length sanity of a ROS 1 bag 2.0 file, run before librosbag sees it.
#pragma once

#include <filesystem>

namespace scfloam {

// Error naming the file when any record's header or data length runs past the end of the
// file (or of its uncompressed chunk). Cheap: reads only the record lengths and headers.
void check_ros1_bag_records(const std::filesystem::path& path);

}  // namespace scfloam
