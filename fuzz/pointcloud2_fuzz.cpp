// One serialized PointCloud2 message, ROS 1 or CDR, and its conversion to a scan.
#include "fuzz_input.hpp"
#include "fuzz_readers.hpp"

SCFLOAM_FUZZ_TARGET("pointcloud2", ".msg")
