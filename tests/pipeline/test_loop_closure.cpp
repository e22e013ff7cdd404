// The loop stages on a simulated drive whose odometry drifts in heading and scale: detection on
// feature clouds, feature registration and the pose graph must pull the keyframes back onto
// the ground truth (issue 5: optimized error <= 0.6x the odometry's).
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include "pipeline/keyframe_store.hpp"
#include "pipeline/loop_closure.hpp"
#include "scfloam/eval/alignment.hpp"
#include "scfloam/features/feature_extractor.hpp"
#include "scfloam/loop/keyframe_selector.hpp"
#include "scfloam/registration/voxel_filter.hpp"
#include "scfloam/se3.hpp"
#include "scfloam/sim/scan.hpp"
#include "scfloam/sim/scenario.hpp"
#include "scfloam/sim/sensor.hpp"
#include "loop/simulated_keyframes.hpp"  // drifting_odometry

using namespace scfloam;

TEST(LoopClosure, CorrectsADriftingOdometryOnASimulatedDrive) {
  const SlamConfig config;
  const sim::Scenario scenario = sim::make_loops_scenario(3, 1000);
  sim::SensorModel sensor = sim::sensor_preset("hdl64");
  sensor.columns = 1000;  // thinner rings keep the test fast; features still form
  const sim::BeamCalibration calibration = sim::draw_beam_calibration(sensor, 3);

  PoseList gt;
  for (std::size_t k = 0; k < scenario.frames; ++k) gt.push_back(scenario.frame_pose(k));
  const PoseList odometry = test::drifting_odometry(gt, 0.01, 1.0);  // 1 % scale, 1 deg per 100 m

  // Keyframes on the odometry, as the pipeline picks them.
  std::vector<std::size_t> frames;
  KeyframeSelector selector(config.loop_detection.keyframe_distance_m,
                            config.loop_detection.keyframe_angle_deg * M_PI / 180.0);
  for (std::size_t k = 0; k < odometry.size(); ++k)
    if (selector.update(odometry[k])) frames.push_back(k);
  std::vector<std::shared_ptr<Keyframe>> keyframes(frames.size());
  tbb::parallel_for(std::size_t{0}, frames.size(), [&](std::size_t i) {
    sim::SweepPoses poses;
    poses.T_world_lidar = gt[frames[i]];
    const Scan scan = sim::render_scan(scenario.world, sensor, calibration, poses, 3, frames[i]);
    FeatureExtractor extractor(config.odometry.preprocess, config.odometry.rings,
                               config.odometry.features);
    FeatureCloud edges, planes;
    extractor.extract(scan.points, false, edges, planes);
    auto kf = std::make_shared<Keyframe>();
    kf->index = i;
    kf->frame = frames[i];
    kf->edges = voxel_downsample(edges, config.odometry.features.edge_leaf_m);
    kf->planes = voxel_downsample(planes, config.odometry.features.plane_leaf_m);
    if (i > 0) kf->T_prev_current = odometry[frames[i - 1]].inverse() * odometry[frames[i]];
    keyframes[i] = kf;
  });

  KeyframeStore store;
  LoopClosure closure(config, LoopRegistrationMethod::kFeatures, store);
  LoopDetector detector(config.loop_detection);
  std::uint64_t seen = 0;
  for (const auto& kf : keyframes) {
    store.add(kf);
    if (store.version() != seen) {  // the gate works on corrected poses
      seen = store.version();
      PoseList poses = store.current_poses();
      poses.resize(detector.size());
      detector.update_poses(poses);
    }
    closure.add(kf, detector.add_keyframe(static_cast<std::int64_t>(kf->frame),
                                          store.current_pose(kf->index), kf->edges, kf->planes));
  }

  // Loops the graph already agreed with were added without a solve; the end solves once.
  closure.finish();
  EXPECT_GT(closure.solves_skipped(), 0u);
  EXPECT_LT(closure.optimization_ms().size(), closure.accepted_loops());
  // After it every active loop edge, solved or not, fits the final graph.
  const PoseGraph& graph = closure.graph();
  for (std::size_t e = 0; e < graph.edges().size(); ++e)
    if (graph.edges()[e].is_loop && graph.edges()[e].active) {
      EXPECT_LT(graph.edge_chi2(e), config.pose_graph.loop_outlier_chi2) << e;
    }

  PoseList gt_kf, odom_kf;
  for (std::size_t f : frames) {
    gt_kf.push_back(gt[f]);
    odom_kf.push_back(odometry[f]);
  }
  const PoseList corrected = store.current_poses();
  const double ate_odometry = ate_rmse_m(gt_kf, odom_kf);
  const double ate_corrected = ate_rmse_m(gt_kf, corrected);
  std::printf("%zu keyframes, %zu loops accepted (%zu without a solve): ATE odometry %.2f m, corrected %.2f m\n",
              frames.size(), closure.accepted_loops(), closure.solves_skipped(), ate_odometry, ate_corrected);
  ASSERT_GT(ate_odometry, 2.0);  // the drift is real
  EXPECT_GE(closure.accepted_loops(), 5u);
  EXPECT_LE(ate_corrected, 0.6 * ate_odometry);
  // No accepted loop joins places that are truly apart.
  for (const auto& row : closure.log().rows()) {
    if (row.verdict != LoopVerdict::kAccepted) continue;
    EXPECT_LT((gt[row.current_frame].translation() - gt[row.loop_frame].translation()).norm(), 10.0);
  }
}
