// Replays every input the fuzzers ever crashed on (tests/io/fuzz_regressions/<target>/) and
// the seed corpora (fuzz/corpus/<target>/) through the same reader calls as the fuzz targets:
// each must end in success or a clean scfloam::Error, never a crash or another exception.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "../fuzz/fuzz_readers.hpp"

namespace fs = std::filesystem;

namespace {

const fs::path kRegressions = fs::path(__FILE__).parent_path() / "fuzz_regressions";
const fs::path kSeeds = fs::path(__FILE__).parent_path().parent_path().parent_path() / "fuzz" / "corpus";

// Replays each file of root/<target>/; returns how many it replayed.
std::size_t replay_all(const fs::path& root) {
  std::size_t replayed = 0;
  for (const auto& target_dir : fs::directory_iterator(root)) {
    if (!target_dir.is_directory()) continue;
    const std::string target = target_dir.path().filename().string();
    const auto reader = scfloam::fuzz::readers().find(target);
    if (reader == scfloam::fuzz::readers().end()) {
      ADD_FAILURE() << target_dir.path() << " names no fuzz target";
      continue;
    }
    for (const auto& input : fs::directory_iterator(target_dir.path())) {
      SCOPED_TRACE(input.path().string());
      EXPECT_NO_THROW(reader->second(input.path()));
      ++replayed;
    }
  }
  return replayed;
}

}  // namespace

TEST(FuzzRegressions, SavedCrashInputsEndInACleanError) {
  ASSERT_TRUE(fs::is_directory(kRegressions)) << kRegressions;
  EXPECT_GT(replay_all(kRegressions), 0u);
}

TEST(FuzzRegressions, SeedCorporaReadCleanly) {
  ASSERT_TRUE(fs::is_directory(kSeeds)) << kSeeds;
  EXPECT_GT(replay_all(kSeeds), 0u);
}
