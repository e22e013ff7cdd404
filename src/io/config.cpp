// YAML <-> SlamConfig through one table of (section, key, field) bindings, so reading,
// writing and the unknown-key check can never disagree about which keys exist.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>
#include <sstream>
#include <variant>
#include <vector>

#include "scfloam/atomic_file.hpp"
#include "scfloam/config.hpp"
#include "scfloam/error.hpp"
#include "scfloam/features/rings.hpp"

namespace scfloam {
namespace {

using FieldPtr = std::variant<double*, int*, bool*, std::string*>;

struct Binding {
  std::string section;  // dotted path of the YAML map holding the key, e.g. "odometry.features"
  std::string key;
  FieldPtr field;
};

std::vector<Binding> bindings(SlamConfig& c) {
  auto& o = c.odometry;
  const std::string pre = "odometry.preprocess", ring = "odometry.rings",
                    feat = "odometry.features", reg = "odometry.registration",
                    map = "odometry.map";
  std::vector<Binding> table{
      {pre, "min_range_m", &o.preprocess.min_range_m},
      {pre, "max_range_m", &o.preprocess.max_range_m},
      {pre, "deskew", &o.preprocess.deskew},
      {pre, "deskew_check", &o.preprocess.deskew_check},
      {pre, "deskew_times_from_azimuth", &o.preprocess.deskew_times_from_azimuth},
      {pre, "sweep_period_s", &o.preprocess.sweep_period_s},
      {pre, "sweep_stamp", &o.preprocess.sweep_stamp},
      {pre, "redeskew", &o.preprocess.redeskew},
      {pre, "redeskew_min_rotation_deg", &o.preprocess.redeskew_min_rotation_deg},
      {pre, "redeskew_min_translation_m", &o.preprocess.redeskew_min_translation_m},
      {pre, "elevation_check", &o.preprocess.elevation_check},
      {pre, "elevation_correction_deg", &o.preprocess.elevation_correction_deg},
      {pre, "online_elevation_calibration", &o.preprocess.online_elevation_calibration},
      {pre, "elevation_calibration_gain", &o.preprocess.elevation_calibration_gain},
      {pre, "ground_elevation_calibration", &o.preprocess.ground_elevation_calibration},
      {ring, "lidar", &o.rings.lidar},
      {ring, "use_ring_field", &o.rings.use_ring_field},
      {ring, "adopt_learned_layout", &o.rings.adopt_learned_layout},
      {ring, "min_points_per_ring", &o.rings.min_points_per_ring},
      {feat, "curvature_half_window", &o.features.curvature_half_window},
      {feat, "sectors_per_ring", &o.features.sectors_per_ring},
      {feat, "max_edges_per_sector", &o.features.max_edges_per_sector},
      {feat, "edge_min_curvature", &o.features.edge_min_curvature},
      {feat, "edge_noise_factor", &o.features.edge_noise_factor},
      {feat, "suppression_gap_m", &o.features.suppression_gap_m},
      {feat, "reject_occluded", &o.features.reject_occluded},
      {feat, "occlusion_gap_ratio", &o.features.occlusion_gap_ratio},
      {feat, "edge_leaf_m", &o.features.edge_leaf_m},
      {feat, "plane_leaf_m", &o.features.plane_leaf_m},
      {reg, "knn", &o.registration.knn},
      {reg, "max_neighbor_dist_m", &o.registration.max_neighbor_dist_m},
      {reg, "edge_line_ratio", &o.registration.edge_line_ratio},
      {reg, "plane_max_dist_m", &o.registration.plane_max_dist_m},
      {reg, "edge_max_residual_m", &o.registration.edge_max_residual_m},
      {reg, "edge_view_tolerance_deg", &o.registration.edge_view_tolerance_deg},
      {reg, "plane_min_spread_ratio", &o.registration.plane_min_spread_ratio},
      {reg, "huber_delta_m", &o.registration.huber_delta_m},
      {reg, "inner_iterations", &o.registration.inner_iterations},
      {reg, "outer_iterations", &o.registration.outer_iterations},
      {reg, "outer_iterations_initial", &o.registration.outer_iterations_initial},
      {reg, "match_refresh_m", &o.registration.match_refresh_m},
      {reg, "converged_translation_m", &o.registration.converged_translation_m},
      {reg, "converged_rotation_deg", &o.registration.converged_rotation_deg},
      {reg, "outer_iterations_max", &o.registration.outer_iterations_max},
      {reg, "unconverged_translation_m", &o.registration.unconverged_translation_m},
      {reg, "unconverged_rotation_deg", &o.registration.unconverged_rotation_deg},
      {reg, "solver_step_tolerance", &o.registration.solver_step_tolerance},
      {reg, "degeneracy_min_eigenvalue", &o.registration.degeneracy_min_eigenvalue},
      {reg, "degeneracy_min_rotation_eigenvalue",
       &o.registration.degeneracy_min_rotation_eigenvalue},
      {reg, "degeneracy_fallback", &o.registration.degeneracy_fallback},
      {reg, "degeneracy_prior_translation_weight", &o.registration.degeneracy_prior_translation_weight},
      {reg, "degeneracy_prior_rotation_weight", &o.registration.degeneracy_prior_rotation_weight},
      {reg, "degeneracy_min_translation_ratio", &o.registration.degeneracy_min_translation_ratio},
      {reg, "degeneracy_min_rotation_ratio", &o.registration.degeneracy_min_rotation_ratio},
      {reg, "coarse_neighbor_dist_m", &o.registration.coarse_neighbor_dist_m},
      {reg, "num_threads", &o.registration.num_threads},
      {map, "edge_spacing_m", &o.map.edge_spacing_m},
      {map, "plane_spacing_m", &o.map.plane_spacing_m},
      {map, "max_points_per_cell", &o.map.max_points_per_cell},
      {map, "radius_m", &o.map.radius_m},
  };
  auto& d = c.loop_detection;
  const std::string det = "loop_detection", sc = "loop_detection.descriptor";
  table.insert(table.end(), {
      {sc, "num_rings", &d.descriptor.num_rings},
      {sc, "num_sectors", &d.descriptor.num_sectors},
      {sc, "max_radius_m", &d.descriptor.max_radius_m},
      {sc, "sensor_height_m", &d.descriptor.sensor_height_m},
      {det, "keyframe_distance_m", &d.keyframe_distance_m},
      {det, "keyframe_angle_deg", &d.keyframe_angle_deg},
      {det, "descriptor_from_features", &d.descriptor_from_features},
      {det, "lateral_augmentation_m", &d.lateral_augmentation_m},
      {det, "exclude_recent_keyframes", &d.exclude_recent_keyframes},
      {det, "num_candidates", &d.num_candidates},
      {det, "tree_rebuild_every", &d.tree_rebuild_every},
      {det, "tree_rebuild_async", &d.tree_rebuild_async},
      {det, "fine_search_ratio", &d.fine_search_ratio},
      {det, "score_threshold", &d.score_threshold},
      {det, "adaptive_gate", &d.adaptive_gate},
      {det, "gate_base_m", &d.gate_base_m},
      {det, "gate_keyframes_per_m", &d.gate_keyframes_per_m},
      {det, "fixed_gate_m", &d.fixed_gate_m},
      {det, "gate_drift_fraction", &d.gate_drift_fraction},
  });
  auto& l = c.loop_registration;
  const std::string lr = "loop_registration";
  table.insert(table.end(), {
      {lr, "submap_neighbors", &l.submap_neighbors},
      {lr, "submap_reuse_keyframes", &l.submap_reuse_keyframes},
      {lr, "coarse_radius_m", &l.coarse_radius_m},
      {lr, "coarse_rounds", &l.coarse_rounds},
      {lr, "knn", &l.knn},
      {lr, "fine_first", &l.fine_first},
      {lr, "rounds", &l.rounds},
      {lr, "min_inlier_fraction", &l.min_inlier_fraction},
      {lr, "max_mean_residual_m", &l.max_mean_residual_m},
      {lr, "check_plane_max_dist_m", &l.check_plane_max_dist_m},
      {lr, "information_inflation", &l.information_inflation},
      {lr, "icp_leaf_m", &l.icp_leaf_m},
      {lr, "icp_max_correspondence_m", &l.icp_max_correspondence_m},
      {lr, "icp_max_iterations", &l.icp_max_iterations},
      {lr, "icp_max_fitness_m2", &l.icp_max_fitness_m2},
  });
  auto& g = c.pose_graph;
  const std::string pg = "pose_graph";
  table.insert(table.end(), {
      {pg, "odometry_rotation_sigma_rad", &g.odometry_rotation_sigma_rad},
      {pg, "odometry_translation_sigma_m", &g.odometry_translation_sigma_m},
      {pg, "loop_rotation_sigma_rad", &g.loop_rotation_sigma_rad},
      {pg, "loop_translation_sigma_m", &g.loop_translation_sigma_m},
      {pg, "loop_cauchy_scale", &g.loop_cauchy_scale},
      {pg, "loop_outlier_chi2", &g.loop_outlier_chi2},
      {pg, "max_outlier_rounds", &g.max_outlier_rounds},
      {pg, "loop_support_min", &g.loop_support_min},
      {pg, "loop_support_span_keyframes", &g.loop_support_span_keyframes},
      {pg, "loop_support_translation_m", &g.loop_support_translation_m},
      {pg, "loop_support_rotation_deg", &g.loop_support_rotation_deg},
      {pg, "loop_support_max_chi2", &g.loop_support_max_chi2},
      {pg, "skip_solve_loop_chi2", &g.skip_solve_loop_chi2},
      {pg, "solve_window_margin_keyframes", &g.solve_window_margin_keyframes},
      {pg, "solve_window_max_keyframes", &g.solve_window_max_keyframes},
      {pg, "max_iterations", &g.max_iterations},
  });
  auto& p = c.pipeline;
  const std::string pl = "pipeline";
  table.insert(table.end(), {
      {pl, "deterministic", &p.deterministic},
      {pl, "queue_capacity", &p.queue_capacity},
      {pl, "max_loop_lag_frames", &p.max_loop_lag_frames},
      {pl, "max_deferred_loops", &p.max_deferred_loops},
      {pl, "loop_thread_nice", &p.loop_thread_nice},
      {pl, "rebuild_map_after_loop", &p.rebuild_map_after_loop},
      {pl, "map_rebuild_min_shift_m", &p.map_rebuild_min_shift_m},
      {pl, "raw_leaf_m", &p.raw_leaf_m},
      {pl, "resident_keyframes", &p.resident_keyframes},
      {pl, "spill_dir", &p.spill_dir},
      {pl, "map_rebuild_cell_m", &p.map_rebuild_cell_m},
  });
  return table;
}

std::vector<std::string> split_dots(const std::string& s) {
  std::vector<std::string> parts;
  std::stringstream ss(s);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  return parts;
}

// Every map in the file must be a known section and every scalar a known key.
void check_known(const YAML::Node& node, const std::string& prefix,
                 const std::vector<Binding>& table, const std::filesystem::path& path) {
  for (const auto& kv : node) {
    if (!kv.first.IsScalar())
      throw file_error(path, "a key " + (prefix.empty() ? std::string("at the top level")
                                                          : "under `" + prefix + "`") +
                                 " is not a plain name");
    const std::string name = kv.first.Scalar();
    const std::string full = prefix.empty() ? name : prefix + "." + name;
    bool is_section = false, is_key = false;
    for (const auto& b : table) {
      if (b.section == full || b.section.rfind(full + ".", 0) == 0) is_section = true;
      if (b.section == prefix && b.key == name) is_key = true;
    }
    if (is_key) continue;
    if (!is_section) throw file_error(path, "unknown key `" + full + "`");
    if (!kv.second.IsMap()) throw file_error(path, "`" + full + "` must be a map of settings");
    check_known(kv.second, full, table, path);
  }
}

template <typename T>
void read_scalar(const YAML::Node& n, T* out, const std::string& full,
                 const std::filesystem::path& path, const char* type_name) {
  if (!n.IsScalar()) throw file_error(path, "`" + full + "` must be " + type_name);
  try {
    *out = n.as<T>();
  } catch (const YAML::Exception&) {
    throw file_error(path, "`" + full + "` must be " + type_name + ", got `" + n.Scalar() + "`");
  }
  if constexpr (std::is_same_v<T, double>)
    if (!std::isfinite(*out)) throw file_error(path, "`" + full + "` must be a finite number");
}

// Values the stages divide by, size buffers with or loop over: a zero or negative one would
// hang or crash a run far from the config file, so it is refused here, naming the key.
void check_ranges(const SlamConfig& c, const std::filesystem::path& path) {
  auto require = [&](bool ok, const char* key, const std::string& rule) {
    if (!ok) throw file_error(path, std::string("`") + key + "` must be " + rule);
  };
  const auto& o = c.odometry;
  require(o.preprocess.min_range_m >= 0, "odometry.preprocess.min_range_m", ">= 0");
  require(o.preprocess.max_range_m > o.preprocess.min_range_m, "odometry.preprocess.max_range_m",
          "> min_range_m");
  if (o.rings.lidar != "auto") {
    try {
      parse_lidar_model(o.rings.lidar);
    } catch (const Error&) {
      require(false, "odometry.rings.lidar", "auto, hdl64, hdl32, vlp16, os1-64 or os1-128 (got `" + o.rings.lidar + "`)");
    }
  }
  require(o.preprocess.sweep_period_s == 0 || (o.preprocess.sweep_period_s >= 0.005 && o.preprocess.sweep_period_s <= 1),
          "odometry.preprocess.sweep_period_s", "0 (from the stamps) or in [0.005, 1] s");
  require(o.preprocess.sweep_stamp == "start" || o.preprocess.sweep_stamp == "middle" || o.preprocess.sweep_stamp == "end",
          "odometry.preprocess.sweep_stamp", "start, middle or end (got `" + o.preprocess.sweep_stamp + "`)");
  require(o.preprocess.redeskew_min_rotation_deg >= 0, "odometry.preprocess.redeskew_min_rotation_deg", ">= 0");
  require(o.preprocess.redeskew_min_translation_m >= 0, "odometry.preprocess.redeskew_min_translation_m", ">= 0");
  require(o.rings.min_points_per_ring >= 0, "odometry.rings.min_points_per_ring", ">= 0");
  require(o.features.curvature_half_window >= 1, "odometry.features.curvature_half_window", ">= 1");
  require(o.features.sectors_per_ring >= 1, "odometry.features.sectors_per_ring", ">= 1");
  require(o.features.max_edges_per_sector >= 0, "odometry.features.max_edges_per_sector", ">= 0");
  require(o.features.edge_leaf_m > 0, "odometry.features.edge_leaf_m", "> 0");
  require(o.features.plane_leaf_m > 0, "odometry.features.plane_leaf_m", "> 0");
  const std::string knn_range = "in [3, " + std::to_string(kMaxRegistrationKnn) + "]";
  require(o.registration.knn >= 3 && o.registration.knn <= kMaxRegistrationKnn,
          "odometry.registration.knn", knn_range);
  require(c.loop_registration.knn >= 3 && c.loop_registration.knn <= kMaxRegistrationKnn,
          "loop_registration.knn", knn_range);
  require(o.registration.plane_min_spread_ratio >= 0 && o.registration.plane_min_spread_ratio < 1,
          "odometry.registration.plane_min_spread_ratio", "in [0, 1)");
  require(o.registration.max_neighbor_dist_m > 0, "odometry.registration.max_neighbor_dist_m", "> 0");
  require(o.registration.plane_max_dist_m > 0, "odometry.registration.plane_max_dist_m", "> 0");
  require(o.registration.edge_max_residual_m >= 0, "odometry.registration.edge_max_residual_m", ">= 0 (0 = off)");
  require(o.registration.edge_view_tolerance_deg >= 0 && o.registration.edge_view_tolerance_deg < 180,
          "odometry.registration.edge_view_tolerance_deg", "in [0, 180) (0 = off)");
  require(c.loop_registration.check_plane_max_dist_m > 0, "loop_registration.check_plane_max_dist_m",
          "> 0");
  require(o.registration.inner_iterations >= 1, "odometry.registration.inner_iterations", ">= 1");
  require(o.registration.outer_iterations >= 1, "odometry.registration.outer_iterations", ">= 1");
  require(o.registration.outer_iterations_max >= 0, "odometry.registration.outer_iterations_max", ">= 0");
  require(o.registration.unconverged_translation_m >= 0,
          "odometry.registration.unconverged_translation_m", ">= 0");
  require(o.registration.unconverged_rotation_deg >= 0,
          "odometry.registration.unconverged_rotation_deg", ">= 0");
  require(o.registration.num_threads >= 1, "odometry.registration.num_threads", ">= 1");
  require(o.registration.degeneracy_prior_translation_weight >= 0,
          "odometry.registration.degeneracy_prior_translation_weight", ">= 0");
  require(o.registration.degeneracy_prior_rotation_weight >= 0,
          "odometry.registration.degeneracy_prior_rotation_weight", ">= 0");
  require(o.map.edge_spacing_m >= 0, "odometry.map.edge_spacing_m", ">= 0");
  require(c.loop_registration.information_inflation >= 0,
          "loop_registration.information_inflation", ">= 0");
  require(o.map.plane_spacing_m >= 0, "odometry.map.plane_spacing_m", ">= 0");
  require(o.map.max_points_per_cell >= 1, "odometry.map.max_points_per_cell", ">= 1");
  require(o.map.radius_m > 0, "odometry.map.radius_m", "> 0");
  const auto& d = c.loop_detection;
  require(d.descriptor.num_rings >= 1, "loop_detection.descriptor.num_rings", ">= 1");
  require(d.descriptor.num_sectors >= 1, "loop_detection.descriptor.num_sectors", ">= 1");
  require(d.descriptor.max_radius_m > 0, "loop_detection.descriptor.max_radius_m", "> 0");
  require(d.num_candidates >= 1, "loop_detection.num_candidates", ">= 1");
  require(d.tree_rebuild_every >= 1, "loop_detection.tree_rebuild_every", ">= 1");
  require(d.gate_drift_fraction >= 0, "loop_detection.gate_drift_fraction", ">= 0");
  require(c.loop_registration.icp_leaf_m > 0, "loop_registration.icp_leaf_m", "> 0");
  require(c.pipeline.queue_capacity >= 1, "pipeline.queue_capacity", ">= 1");
  require(c.pipeline.max_loop_lag_frames >= -1, "pipeline.max_loop_lag_frames", ">= -1");
  require(c.pipeline.max_deferred_loops >= 0, "pipeline.max_deferred_loops", ">= 0");
  require(c.pipeline.loop_thread_nice >= 0 && c.pipeline.loop_thread_nice <= 19,
          "pipeline.loop_thread_nice", "in 0..19");
  require(c.pipeline.raw_leaf_m > 0, "pipeline.raw_leaf_m", "> 0");
  require(c.pipeline.resident_keyframes >= 0, "pipeline.resident_keyframes", ">= 0");
  require(c.pipeline.map_rebuild_cell_m >= 0, "pipeline.map_rebuild_cell_m", ">= 0");
}

}  // namespace

SlamConfig load_config(const std::filesystem::path& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::BadFile&) {
    throw file_error(path, "cannot open the config file");
  } catch (const YAML::Exception& e) {
    throw file_error(path, std::string("not valid YAML: ") + e.what());
  }
  SlamConfig config;
  if (root.IsNull()) return config;  // empty file: all defaults
  if (!root.IsMap()) throw file_error(path, "the top level must be a map of sections");
  auto table = bindings(config);
  check_known(root, "", table, path);
  for (auto& b : table) {
    // reset(), not operator=: assigning a yaml-cpp node overwrites the node it refers to.
    YAML::Node n;
    n.reset(root);
    bool present = true;
    for (const auto& part : split_dots(b.section)) {
      const YAML::Node& cn = n;
      if (!cn[part]) { present = false; break; }
      n.reset(cn[part]);
    }
    const YAML::Node& cn = n;
    if (!present || !cn[b.key]) continue;
    const YAML::Node v = cn[b.key];
    const std::string full = b.section + "." + b.key;
    std::visit(
        [&](auto* field) {
          using T = std::remove_pointer_t<decltype(field)>;
          if constexpr (std::is_same_v<T, double>) read_scalar(v, field, full, path, "a number");
          if constexpr (std::is_same_v<T, int>) read_scalar(v, field, full, path, "an integer");
          if constexpr (std::is_same_v<T, bool>) read_scalar(v, field, full, path, "true or false");
          if constexpr (std::is_same_v<T, std::string>) read_scalar(v, field, full, path, "a string");
        },
        b.field);
  }
  check_ranges(config, path);
  return config;
}

namespace {

// Sections as a tree, in binding order, for emitting nested maps.
struct SectionTree {
  std::vector<std::pair<std::string, SectionTree>> children;
  std::vector<const Binding*> keys;

  SectionTree& child(const std::string& name) {
    for (auto& c : children)
      if (c.first == name) return c.second;
    children.emplace_back(name, SectionTree{});
    return children.back().second;
  }
};

void emit(YAML::Emitter& out, const SectionTree& tree) {
  out << YAML::BeginMap;
  for (const Binding* b : tree.keys) {
    out << YAML::Key << b->key << YAML::Value;
    std::visit([&](auto* field) { out << *field; }, b->field);
  }
  for (const auto& [name, sub] : tree.children) {
    out << YAML::Key << name << YAML::Value;
    emit(out, sub);
  }
  out << YAML::EndMap;
}

}  // namespace

std::string config_to_yaml(const SlamConfig& config) {
  SlamConfig copy = config;
  const auto table = bindings(copy);
  SectionTree root;
  for (const auto& b : table) {
    SectionTree* node = &root;
    for (const auto& part : split_dots(b.section)) node = &node->child(part);
    node->keys.push_back(&b);
  }
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  emit(out, root);
  return std::string(out.c_str()) + "\n";
}

void save_config(const std::filesystem::path& path, const SlamConfig& config) {
  const std::string text = config_to_yaml(config);
  write_file_atomic(path, [&](std::ostream& os) { os << text; });
}

}  // namespace scfloam
