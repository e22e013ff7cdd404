// Where tests find the team's shared data, and how they skip when a user's clone lacks it.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>

#include <filesystem>
#include <string>
#include <vector>

namespace scfloam::test {

inline std::filesystem::path shared_dir() { return SCFLOAM_SHARED_DIR; }

// Path below ../shared/data; the calling test is skipped (saying why) when it is absent.
// CI treats a missing shared/ as an error before any test runs (.ci/run).
#define SCFLOAM_SHARED_DATA_OR_SKIP(var, relative)                                          \
  const std::filesystem::path var = ::scfloam::test::shared_dir() / "data" / (relative);    \
  if (!std::filesystem::exists(var))                                                        \
  GTEST_SKIP() << "shared data not found at " << var                                        \
               << " (clone lacks ../shared; configure with -DSCFLOAM_SHARED_DIR=...)"

// Every scratch folder a test process made is removed when the process ends (static
// destruction after main), so the suite leaves nothing behind: simulated sequences are 0.3-1.1 GB
// each and CI's disk is shared (a full disk failed CI once). SCFLOAM_KEEP_TEST_SCRATCH=1 keeps
// them to look at. A crashed process leaves its folders; the next run of the test removes them.
class ScratchFolders {
 public:
  static ScratchFolders& instance() {
    static ScratchFolders folders;
    return folders;
  }
  void add(const std::filesystem::path& dir) { dirs_.push_back(dir); }
  // Removes one folder now (a test done with a large input) and forgets it.
  void remove(const std::filesystem::path& dir) {
    std::error_code ec;
    if (!keep()) std::filesystem::remove_all(dir, ec);
    dirs_.erase(std::remove(dirs_.begin(), dirs_.end(), dir), dirs_.end());
  }
  ~ScratchFolders() {
    if (keep()) return;
    std::error_code ec;
    for (const auto& dir : dirs_) std::filesystem::remove_all(dir, ec);
  }

 private:
  static bool keep() {
    const char* v = std::getenv("SCFLOAM_KEEP_TEST_SCRATCH");
    return v && std::string(v) == "1";
  }
  std::vector<std::filesystem::path> dirs_;
};

// A fresh scratch folder for one test, removed first if it exists. One per process: ctest runs
// every test as its own process, two at a time, and a suite's shared setup (SetUpTestSuite)
// runs in each of them: a shared folder let one process rewrite the other's input mid-run.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto root = std::filesystem::path(SCFLOAM_BINARY_DIR) / "test-scratch";
  const auto dir = root / (name + "-" + std::to_string(::getpid()));
  // Folders of this name left by earlier processes that have ended are removed.
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(root, ec)) {
    const std::string other = entry.path().filename().string();
    if (other.rfind(name + "-", 0) != 0) continue;
    const std::string pid = other.substr(name.size() + 1);
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    if (::kill(static_cast<pid_t>(std::stol(pid)), 0) != 0 && errno == ESRCH)
      std::filesystem::remove_all(entry.path(), ec);
  }
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ScratchFolders::instance().add(dir);
  return dir;
}

}  // namespace scfloam::test
