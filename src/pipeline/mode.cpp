#include "scfloam/pipeline/pipeline.hpp"

namespace scfloam {

std::optional<SlamMode> parse_mode(const std::string& name) {
  if (name == "odometry") return SlamMode::kOdometry;
  if (name == "simple-sc") return SlamMode::kSimpleSc;
  if (name == "optimized") return SlamMode::kOptimized;
  return std::nullopt;
}

std::string mode_name(SlamMode mode) {
  switch (mode) {
    case SlamMode::kOdometry: return "odometry";
    case SlamMode::kSimpleSc: return "simple-sc";
    case SlamMode::kOptimized: return "optimized";
  }
  return "unknown";
}

}  // namespace scfloam
