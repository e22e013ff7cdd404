// Where tests find the team's shared data, and how they skip when a user's clone lacks it.
#pragma once

#include <gtest/gtest.h>

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

// A fresh scratch folder for one test, removed first if it exists.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::path(SCFLOAM_BINARY_DIR) / "test-scratch" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace scfloam::test
