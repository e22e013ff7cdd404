// What `scfloam info` reports about an input before anything runs: the kind of input, its
// topics and message types (bags), how many scans, the fields of a point, and the time span.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace scfloam {

struct TopicInfo {
  std::string name;          // "/velodyne_points"
  std::string type;          // "sensor_msgs/PointCloud2" or "sensor_msgs/msg/PointCloud2"
  std::size_t messages = 0;
};

struct InputInfo {
  std::string kind;                        // "KITTI sequence", "PCD folder", "ROS 1 bag", ...
  std::vector<TopicInfo> topics;           // bags only
  std::string scan_topic;                  // the topic `run` would read (bags), empty if none
  std::size_t scans = 0;                   // scans `run` would read
  std::vector<std::string> point_fields;   // of the first scan, e.g. "x:float32", "ring:uint16"
  std::size_t points_in_first_scan = 0;
  double start_time_s = 0, end_time_s = 0; // first and last scan stamps (0, 0 if unknown)
  std::vector<std::string> notes;          // anything the user should know (e.g. "no ring field")
};

}  // namespace scfloam
