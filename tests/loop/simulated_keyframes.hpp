// A simulated drive with loops reduced to what loop detection sees: keyframes chosen on
// drifting "odometry" poses, each with its ground-truth pose and the Scan Contexts of its
// raw sweep and of its F-LOAM feature clouds (edges 0.4 m + planes 0.8 m voxels).
#pragma once

#include <tbb/parallel_for.h>

#include <cstdint>
#include <vector>

#include "scfloam/features/feature_extractor.hpp"
#include "scfloam/loop/keyframe_selector.hpp"
#include "scfloam/loop/loop_detector.hpp"
#include "scfloam/loop/loop_evaluation.hpp"
#include "scfloam/registration/voxel_filter.hpp"
#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/simulate.hpp"

namespace scfloam::test {

struct SimulatedKeyframes {
  std::vector<std::int64_t> frames;
  PoseList T_world_gt, T_world_odometry;
  std::vector<ScanContext> from_features, from_raw;
  // Lateral variants (config.lateral_augmentation_m to the left and right) of both.
  std::vector<std::vector<ScanContext>> features_lateral, raw_lateral;
  double end_drift_m = 0;
};

// Odometry that drifts: a scale error and a steady yaw bias per metre travelled.
inline PoseList drifting_odometry(const PoseList& gt, double scale_error, double yaw_bias_deg_per_100m) {
  PoseList odometry{gt.front()};
  for (std::size_t k = 1; k < gt.size(); ++k) {
    Eigen::Isometry3d step = gt[k - 1].inverse() * gt[k];
    const double travel_m = step.translation().norm();
    step.translation() *= 1.0 + scale_error;
    Eigen::Isometry3d bias = Eigen::Isometry3d::Identity();
    bias.linear() = Eigen::AngleAxisd(yaw_bias_deg_per_100m * M_PI / 180.0 / 100.0 * travel_m,
                                      Eigen::Vector3d::UnitZ()).toRotationMatrix();
    odometry.push_back(odometry.back() * step * bias);
  }
  return odometry;
}

// `columns` < the preset's 2083 thins each ring to save rendering time (0 = keep).
inline SimulatedKeyframes simulate_keyframes(std::uint64_t seed, std::size_t frames, int columns,
                                             const LoopDetectionConfig& config) {
  const sim::Scenario scenario = sim::make_loops_scenario(seed, frames);
  sim::SensorModel sensor = sim::sensor_preset("hdl64");
  if (columns > 0) sensor.columns = columns;
  const sim::BeamCalibration calibration = sim::draw_beam_calibration(sensor, seed);

  PoseList gt;
  for (std::size_t k = 0; k < scenario.frames; ++k) gt.push_back(scenario.frame_pose(k));
  const PoseList odometry = drifting_odometry(gt, 0.005, 0.1);

  SimulatedKeyframes out;
  KeyframeSelector selector(config.keyframe_distance_m, config.keyframe_angle_deg * M_PI / 180.0);
  for (std::size_t k = 0; k < gt.size(); ++k)
    if (selector.update(odometry[k])) {
      out.frames.push_back(static_cast<std::int64_t>(k));
      out.T_world_gt.push_back(gt[k]);
      out.T_world_odometry.push_back(odometry[k]);
    }
  out.end_drift_m = (odometry.back().translation() - gt.back().translation()).norm();

  const std::size_t n = out.frames.size();
  out.from_features.resize(n);
  out.from_raw.resize(n);
  out.features_lateral.resize(n);
  out.raw_lateral.resize(n);
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    sim::SweepPoses poses;
    poses.T_world_lidar = out.T_world_gt[i];
    const Scan scan = sim::render_scan(scenario.world, sensor, calibration, poses, seed,
                                       static_cast<std::uint64_t>(out.frames[i]));
    FeatureExtractor extractor(PreprocessConfig{}, RingConfig{}, FeatureConfig{});
    FeatureCloud edges, planes;
    extractor.extract(scan.points, scan.has_ring, edges, planes);
    FeatureCloud features = voxel_downsample(edges, FeatureConfig{}.edge_leaf_m);
    const FeatureCloud plane_points = voxel_downsample(planes, FeatureConfig{}.plane_leaf_m);
    features.insert(features.end(), plane_points.begin(), plane_points.end());
    out.from_features[i] = make_scan_context(features, config.descriptor);
    out.from_raw[i] = make_scan_context(scan.points, config.descriptor);
    out.features_lateral[i] = lateral_descriptors(features, config);
    for (const double offset_m : {config.lateral_augmentation_m, -config.lateral_augmentation_m}) {
      if (config.lateral_augmentation_m <= 0.0) break;
      ScanContextBuilder shifted(config.descriptor, static_cast<float>(offset_m));
      shifted.add(scan.points);
      out.raw_lateral[i].push_back(shifted.finish());
    }
  });
  return out;
}

// Runs a detector over the keyframes (gate on the odometry poses) and scores its verdicts;
// the lateral variants are used when config.lateral_augmentation_m > 0.
inline LoopEvaluation detect_and_evaluate(const SimulatedKeyframes& kfs, const LoopDetectionConfig& config,
                                          bool from_features, std::vector<LoopCandidate>* accepted = nullptr) {
  LoopDetector detector(config);
  std::vector<LoopCandidate> evaluated;
  const std::vector<ScanContext> none;
  for (std::size_t i = 0; i < kfs.frames.size(); ++i) {
    const auto& lateral = from_features ? kfs.features_lateral[i] : kfs.raw_lateral[i];
    const LoopQuery query = detector.add_keyframe(kfs.frames[i], kfs.T_world_odometry[i],
                                                  from_features ? kfs.from_features[i] : kfs.from_raw[i],
                                                  config.lateral_augmentation_m > 0.0 ? lateral : none);
    evaluated.insert(evaluated.end(), query.evaluated.begin(), query.evaluated.end());
    if (accepted && query.best) accepted->push_back(*query.best);
  }
  return evaluate_loops(kfs.T_world_gt, evaluated, LoopEvaluationConfig{});
}

}  // namespace scfloam::test
