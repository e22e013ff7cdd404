#include "scfloam/eval/report.hpp"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "scfloam/error.hpp"

namespace scfloam {
namespace {

// nlohmann writes NaN as null already; being explicit keeps the JSON valid whatever the version.
nlohmann::ordered_json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) return "n/a";
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace

EvalReport evaluate_trajectory(const PoseList& gt, const PoseList& est) {
  if (gt.empty()) throw Error("evaluation: the ground truth has no poses");
  EvalReport r;
  r.kitti = kitti_metric(gt, est);  // checks the lengths match
  r.ate = absolute_trajectory_error(gt, est);
  r.rpe = relative_pose_error(gt, est);
  r.frames = gt.size();
  r.gt_total = gt.size();
  r.est_total = est.size();
  return r;
}

std::string format_eval_table(const EvalReport& r) {
  std::string out;
  char line[256];
  if (!r.gt_name.empty()) out += "ground truth: " + r.gt_name + " (" + std::to_string(r.gt_total) + " poses)\n";
  if (!r.est_name.empty()) out += "estimate:     " + r.est_name + " (" + std::to_string(r.est_total) + " poses)\n";
  std::snprintf(line, sizeof line, "frames evaluated: %zu%s%s, ground-truth path %.1f m\n",
                r.frames, r.association.empty() ? "" : ", paired ", r.association.c_str(),
                r.kitti.path_length_m);
  out += line;
  if (r.gt_total > r.frames)
    out += "  note: only " + std::to_string(r.frames) + " of " + std::to_string(r.gt_total) +
           " ground-truth poses have an estimate; the devkit expects every frame, so its\n"
           "        10-frame step and the RPE pairs here count paired poses, not frames\n";
  out += "\nKITTI odometry metric (devkit: every 10th first frame, segments of 100..800 m)\n";
  out += "  length [m]  segments  t_err [%]  r_err [deg/100m]\n";
  for (const auto& pl : r.kitti.per_length) {
    std::snprintf(line, sizeof line, "  %10.0f  %8zu  %9s  %16s\n", pl.length_m, pl.segments,
                  fixed(pl.t_err_pct, 3).c_str(), fixed(pl.r_err_deg_per_100m, 4).c_str());
    out += line;
  }
  std::snprintf(line, sizeof line, "  %10s  %8zu  %9s  %16s\n", "all", r.kitti.segments,
                fixed(r.kitti.t_err_pct, 3).c_str(), fixed(r.kitti.r_err_deg_per_100m, 4).c_str());
  out += line;
  if (!r.kitti.note.empty()) out += "  note: " + r.kitti.note + "\n";
  if (r.kitti.has_segments()) {
    if (std::isfinite(r.kitti.t_err_vertical_pct)) {
      std::snprintf(line, sizeof line, "  t_err split by the ground truth's up: horizontal %s %%, vertical %s %% (means of |part| / length)\n",
                    fixed(r.kitti.t_err_horizontal_pct, 3).c_str(), fixed(r.kitti.t_err_vertical_pct, 3).c_str());
      out += line;
    } else {
      out += "  t_err split: n/a (the ground truth spans no plane, or never turns, to take its up from)\n";
    }
  }
  out += "\nATE after SE(3) Umeyama alignment [m]\n";
  std::snprintf(line, sizeof line, "  rmse %s  mean %s  median %s  max %s\n",
                fixed(r.ate.rmse_m, 3).c_str(), fixed(r.ate.mean_m, 3).c_str(),
                fixed(r.ate.median_m, 3).c_str(), fixed(r.ate.max_m, 3).c_str());
  out += line;
  std::snprintf(line, sizeof line, "RPE between consecutive frames (%zu pairs)\n", r.rpe.pairs());
  out += line;
  std::snprintf(line, sizeof line, "  translation rmse %s m  mean %s m\n  rotation    rmse %s deg  mean %s deg\n",
                fixed(r.rpe.trans_rmse_m, 4).c_str(), fixed(r.rpe.trans_mean_m, 4).c_str(),
                fixed(r.rpe.rot_rmse_deg, 4).c_str(), fixed(r.rpe.rot_mean_deg, 4).c_str());
  out += line;
  std::snprintf(line, sizeof line, "\nt_err %s %%   r_err %s deg/100m   ATE %s m\n",
                fixed(r.kitti.t_err_pct, 3).c_str(), fixed(r.kitti.r_err_deg_per_100m, 4).c_str(),
                fixed(r.ate.rmse_m, 3).c_str());
  out += line;
  return out;
}

std::string eval_json(const EvalReport& r) {
  nlohmann::ordered_json j;
  j["frames"] = r.frames;
  j["t_err_pct"] = number_or_null(r.kitti.t_err_pct);
  j["r_err_deg_per_100m"] = number_or_null(r.kitti.r_err_deg_per_100m);
  j["t_err_horizontal_pct"] = number_or_null(r.kitti.t_err_horizontal_pct);
  j["t_err_vertical_pct"] = number_or_null(r.kitti.t_err_vertical_pct);
  j["kitti_segments"] = r.kitti.segments;
  j["path_length_m"] = r.kitti.path_length_m;
  nlohmann::ordered_json per_length = nlohmann::ordered_json::array();
  for (const auto& pl : r.kitti.per_length)
    per_length.push_back({{"length_m", pl.length_m},
                          {"segments", pl.segments},
                          {"t_err_pct", number_or_null(pl.t_err_pct)},
                          {"r_err_deg_per_100m", number_or_null(pl.r_err_deg_per_100m)}});
  j["per_length"] = per_length;
  j["ate_rmse_m"] = r.ate.rmse_m;
  j["ate_mean_m"] = r.ate.mean_m;
  j["ate_median_m"] = r.ate.median_m;
  j["ate_max_m"] = r.ate.max_m;
  j["rpe_pairs"] = r.rpe.pairs();
  j["rpe_trans_rmse_m"] = r.rpe.trans_rmse_m;
  j["rpe_trans_mean_m"] = r.rpe.trans_mean_m;
  j["rpe_rot_rmse_deg"] = r.rpe.rot_rmse_deg;
  j["rpe_rot_mean_deg"] = r.rpe.rot_mean_deg;
  j["note"] = r.kitti.note;
  j["gt"] = r.gt_name;
  j["est"] = r.est_name;
  j["association"] = r.association;
  j["gt_poses"] = r.gt_total;
  j["est_poses"] = r.est_total;
  return j.dump();
}

}  // namespace scfloam
