// Every number that changes behaviour, one struct per stage, with the paper's defaults
// (../shared/SPEC.md). Loaded from YAML by load_config(); docs/parameters.md explains each.
#pragma once

#include <filesystem>
#include <string>

namespace scfloam {

// Filled in by the odometry work (issue 3): preprocessing, rings, features, registration,
// local map. Sections for loop detection, loop registration and the pose graph follow.
struct OdometryConfig {
  // placeholder fields are not allowed: each section lists real parameters with defaults
};

struct SlamConfig {
  OdometryConfig odometry;
};

// Reads a YAML file; unknown keys and wrong types are errors naming the file and the key.
SlamConfig load_config(const std::filesystem::path& path);

}  // namespace scfloam
