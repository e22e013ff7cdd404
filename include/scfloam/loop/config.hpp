// Loop detection parameters (keyframes, Scan Context, candidate search, distance gate) with
// the defaults of ../shared/SPEC.md; docs/loop.md explains each and how they were chosen.
#pragma once

namespace scfloam {

struct ScanContextConfig {
  int num_rings = 20;             // radial bins up to max_radius_m
  int num_sectors = 60;           // azimuth bins over 360 degrees (6 degrees each)
  double max_radius_m = 80.0;     // points farther than this (horizontally) are ignored
  double sensor_height_m = 2.0;   // added to z so that heights above the ground are positive
};

struct LoopDetectionConfig {
  ScanContextConfig descriptor;

  // A new keyframe after this much accumulated travel or rotation since the last one.
  double keyframe_distance_m = 2.0;
  double keyframe_angle_deg = 10.0;

  // The paper's change: descriptor from the edge + plane feature clouds; false builds it
  // from the raw scan (SC-A-LOAM / Simple-SC-F-LOAM baseline). The caller passes the points.
  bool descriptor_from_features = true;

  // The query is also described from virtual sensors this far to the left and the right
  // (0 = off): a revisit in the opposite lane, ~3 m aside, otherwise scores 0.4-0.5.
  double lateral_augmentation_m = 3.0;

  int exclude_recent_keyframes = 50;  // the newest keyframes are never loop candidates
  int num_candidates = 10;            // ring-key nearest neighbours aligned per query
  int tree_rebuild_every = 50;        // k-d tree rebuilt once this many keyframes are unindexed
  bool tree_rebuild_async = true;     // rebuild on a background thread (results are the same)
  double fine_search_ratio = 0.1;     // fine column-shift search: +- this fraction of sectors
  double score_threshold = 0.3;       // accept a candidate whose column cosine distance is <= this

  // Distance gate on current poses: d <= gate_base_m + k / gate_keyframes_per_m (paper eq. 1-3),
  // or d <= fixed_gate_m when adaptive_gate is false (baseline).
  bool adaptive_gate = true;
  double gate_base_m = 20.0;
  double gate_keyframes_per_m = 40.0;  // the paper's n
  // > 0 replaces the paper's k/n term (adaptive gate only) by drift_fraction * L, L being the
  // shortest path linking the two keyframes in the pose graph (through accepted loops), with
  // the distance under the optimized poses (scfloam/loop/path_gate.hpp). 0 = the paper's gate.
  double gate_drift_fraction = 0.0;
  // The baseline's fixed gate: 60 m, as the paper's public code uses for its 16-beam variant
  // (SC-A-LOAM itself has none: set 1e9 for that).
  double fixed_gate_m = 60.0;
};

}  // namespace scfloam
