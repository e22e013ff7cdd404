// The whole pipeline on a source, without a progress bar; deterministic unless asked otherwise
// (the tests in this folder compare runs exactly).
#pragma once

#include "scfloam/pipeline/pipeline.hpp"

namespace scfloam::test {

inline RunResult run_quietly(const ScanSource& source, SlamMode mode, const SlamConfig& config = {},
                             bool deterministic = true) {
  RunOptions options;
  options.mode = mode;
  options.progress = false;
  options.deterministic = deterministic;
  return run_slam(source, config, options);
}

}  // namespace scfloam::test
