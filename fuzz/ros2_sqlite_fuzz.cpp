// A ROS 2 sqlite3 bag: inspection and PointCloud2 scans.
#include "fuzz_input.hpp"
#include "fuzz_readers.hpp"

SCFLOAM_FUZZ_TARGET("ros2_sqlite", ".db3")
