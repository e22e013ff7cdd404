// The record-length walk that runs before librosbag: a corrupt length is refused by us, with
// the file named, before librosbag sizes a buffer from it; real bags pass it untouched.
#include <gtest/gtest.h>

#include "io/ros1_bag_check.hpp"
#include "scfloam/error.hpp"
#include "test_paths.hpp"

namespace fs = std::filesystem;

TEST(Ros1BagCheck, FuzzedTwoGigabyteHeaderLengthIsRefusedBeforeLibrosbag) {
  const fs::path bag = fs::path(__FILE__).parent_path() / "fuzz_regressions" / "ros1_bag" /
                       "oom-connection-header-2gb.bag";
  try {
    scfloam::check_ros1_bag_records(bag);
    FAIL() << "accepted a record that runs past the end of the file";
  } catch (const scfloam::Error& e) {
    EXPECT_NE(std::string(e.what()).find("runs past the end"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(bag.filename().string()), std::string::npos) << e.what();
  }
}

TEST(Ros1BagCheck, RealBagsPass) {
  SCFLOAM_SHARED_DATA_OR_SKIP(bags, "bags");
  int checked = 0;
  for (const auto& entry : fs::recursive_directory_iterator(bags)) {
    if (entry.path().extension() != ".bag") continue;
    EXPECT_NO_THROW(scfloam::check_ros1_bag_records(entry.path())) << entry.path();
    ++checked;
  }
  EXPECT_GE(checked, 5);
}
