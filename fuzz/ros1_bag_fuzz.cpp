// A ROS 1 bag (Debian's librosbag behind our reader): inspection and PointCloud2 scans.
#include "fuzz_input.hpp"
#include "fuzz_readers.hpp"

SCFLOAM_FUZZ_TARGET("ros1_bag", ".bag")
