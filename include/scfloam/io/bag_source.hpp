// ROS bags as scan sources: ROS 1 bag 2.0 (through Debian's librosbag) and ROS 2 bags in
// sqlite3 (.db3 + metadata.yaml) or MCAP storage, both carrying sensor_msgs PointCloud2.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "scfloam/io/input_info.hpp"
#include "scfloam/io/scan_source.hpp"

namespace scfloam {

// True when `path` looks like a bag these readers handle: a `.bag` file, a `.db3` or `.mcap`
// file, or a directory holding a rosbag2 `metadata.yaml`. Cheap: looks at names and magic bytes.
bool is_bag_input(const std::filesystem::path& path);

// Opens the PointCloud2 stream of a bag. `options.topic` picks the topic; when empty, the only
// PointCloud2 topic is used, and an Error lists the candidates when there are none or several.
std::unique_ptr<ScanSource> open_bag_source(const std::filesystem::path& path,
                                            const ScanSourceOptions& options);

// Everything `scfloam info` prints about a bag, including bags with no PointCloud2 topic.
// Error naming the file and the problem when the bag cannot be read at all.
InputInfo inspect_bag(const std::filesystem::path& path, const ScanSourceOptions& options);

}  // namespace scfloam
