// Where tests find the team's shared data, and how they skip when a user's clone lacks it.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>

#include <filesystem>
#include <string>

namespace scfloam::test {

inline std::filesystem::path shared_dir() { return SCFLOAM_SHARED_DIR; }

// Path below ../shared/data; the calling test is skipped (saying why) when it is absent.
// CI treats a missing shared/ as an error before any test runs (.ci/run).
#define SCFLOAM_SHARED_DATA_OR_SKIP(var, relative)                                          \
  const std::filesystem::path var = ::scfloam::test::shared_dir() / "data" / (relative);    \
  if (!std::filesystem::exists(var))                                                        \
  GTEST_SKIP() << "shared data not found at " << var                                        \
               << " (clone lacks ../shared; configure with -DSCFLOAM_SHARED_DIR=...)"

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
  return dir;
}

}  // namespace scfloam::test
