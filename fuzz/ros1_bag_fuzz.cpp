// A ROS 1 bag (Debian's librosbag behind our reader): inspection and PointCloud2 scans.
#include <rosbag/bag.h>

#include "fuzz_input.hpp"
#include "fuzz_readers.hpp"

// Every rosbag::Bag loads its encryptor plugin through pluginlib: the first Bag dlopens the
// plugin library and the last one to go dlcloses it. One Bag kept for the whole run keeps the
// library loaded, so an input costs its own work only (not a dlopen, relocation and dlclose),
// and each input's allocations balance, so libFuzzer's leak check does not scan after each.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  static rosbag::Bag* keep_plugin_loaded = new rosbag::Bag();
  (void)keep_plugin_loaded;
  return 0;
}

SCFLOAM_FUZZ_TARGET("ros1_bag", ".bag")
