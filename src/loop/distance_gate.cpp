#include "scfloam/loop/distance_gate.hpp"

#include <limits>
#include <string>

#include "scfloam/error.hpp"

namespace scfloam {

DistanceGate::DistanceGate(bool adaptive, double base_m, double keyframes_per_m)
    : adaptive_(adaptive), base_m_(base_m), keyframes_per_m_(keyframes_per_m) {
  if (!(base_m >= 0.0))
    throw Error("distance gate: threshold must be >= 0 m (got " + std::to_string(base_m) + ")");
  if (adaptive && !(keyframes_per_m > 0.0))
    throw Error("distance gate: keyframes per metre n must be > 0 (got " +
                std::to_string(keyframes_per_m) + ")");
}

DistanceGate DistanceGate::adaptive(double base_m, double keyframes_per_m) {
  return DistanceGate(true, base_m, keyframes_per_m);
}

DistanceGate DistanceGate::fixed(double threshold_m) { return DistanceGate(false, threshold_m, 0.0); }

DistanceGate DistanceGate::from_config(const LoopDetectionConfig& config) {
  // The path gate needs the pose graph: the closure stage applies it (path_gate.hpp).
  if (config.adaptive_gate && config.gate_drift_fraction > 0.0)
    return fixed(std::numeric_limits<double>::infinity());
  return config.adaptive_gate ? adaptive(config.gate_base_m, config.gate_keyframes_per_m)
                              : fixed(config.fixed_gate_m);
}

double DistanceGate::threshold_m(std::size_t keyframes) const {
  if (!adaptive_) return base_m_;
  return base_m_ + static_cast<double>(keyframes) / keyframes_per_m_;
}

double DistanceGate::distance_m(const Eigen::Isometry3d& T_world_loop,
                                const Eigen::Isometry3d& T_world_current) {
  return (T_world_loop.inverse() * T_world_current).translation().norm();
}

}  // namespace scfloam
