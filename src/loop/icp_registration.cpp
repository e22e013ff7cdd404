// The ICP baseline of loop registration, on Open3D's point-to-point ICP (Debian's
// libopen3d-dev): the library does the work, as the paper's baseline used PCL's.
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>

#include <dlfcn.h>

#include <cmath>

#include "scfloam/loop/loop_registration.hpp"

namespace scfloam {
namespace {

void append(open3d::geometry::PointCloud& out, const FeatureCloud& points,
            const Eigen::Isometry3d& T) {
  out.points_.reserve(out.points_.size() + points.size());
  for (const auto& p : points) out.points_.push_back(T * p.cast<double>());
}

}  // namespace

// The OpenMP runtime is Open3D's (libgomp, loaded with it); looked up at run time so that
// neither compiler needs OpenMP's headers or flags for this. Without a runtime there is
// nothing to do: ICP then runs on one thread anyway.
IcpOnThisThreadRepeatable::IcpOnThisThreadRepeatable() {
  void* set = ::dlsym(RTLD_DEFAULT, "omp_set_num_threads");
  void* get = ::dlsym(RTLD_DEFAULT, "omp_get_max_threads");
  if (!set || !get) return;
  set_threads_ = reinterpret_cast<void (*)(int)>(set);
  previous_threads_ = reinterpret_cast<int (*)()>(get)();
  set_threads_(1);
}

IcpOnThisThreadRepeatable::~IcpOnThisThreadRepeatable() {
  if (set_threads_ && previous_threads_ > 0) set_threads_(previous_threads_);
}

LoopMatch register_loop_icp(const KeyframeView& current, const std::vector<KeyframeView>& submap,
                            std::size_t loop_index, double sc_yaw_rad,
                            const LoopRegistrationConfig& config) {
  namespace reg = open3d::pipelines::registration;
  LoopMatch best;
  best.reason = "no points";
  if (!current.raw || current.raw->empty() || loop_index >= submap.size()) return best;

  // Everything in the loop keyframe's frame, so the result is T_loop_current directly.
  const Eigen::Isometry3d T_loop_world = submap[loop_index].T_world_lidar.inverse();
  open3d::geometry::PointCloud target, source;
  for (const auto& kf : submap)
    if (kf.raw) append(target, *kf.raw, T_loop_world * kf.T_world_lidar);
  target = *target.VoxelDownSample(config.icp_leaf_m);
  append(source, *current.raw, Eigen::Isometry3d::Identity());
  if (target.points_.empty()) return best;

  for (const Eigen::Isometry3d& guess :
       loop_initial_guesses(submap[loop_index].T_world_lidar, current.T_world_lidar, sc_yaw_rad)) {
    const reg::RegistrationResult r = reg::RegistrationICP(
        source, target, config.icp_max_correspondence_m, guess.matrix(),
        reg::TransformationEstimationPointToPoint(),
        reg::ICPConvergenceCriteria(1e-6, 1e-6, config.icp_max_iterations));
    LoopMatch match;
    match.T_loop_current.matrix() = r.transformation_;
    match.T_loop_current.linear() = Eigen::Quaterniond(match.T_loop_current.linear()).normalized().toRotationMatrix();
    match.residual_m = r.inlier_rmse_;
    match.inlier_fraction = r.fitness_;  // share of points with a correspondence
    const double fitness_m2 = r.inlier_rmse_ * r.inlier_rmse_;
    match.accepted = r.fitness_ > 0 && fitness_m2 < config.icp_max_fitness_m2;
    if (!match.accepted) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "ICP fitness %.3f m^2 (max %.3f)", fitness_m2,
                    config.icp_max_fitness_m2);
      match.reason = buf;
    }
    if (match.accepted) return match;
    if (best.reason == "no points" || fitness_m2 < best.residual_m * best.residual_m) best = match;
  }
  return best;
}

}  // namespace scfloam
