#include "scfloam/eval/trajectory_input.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "scfloam/error.hpp"
#include "scfloam/io/trajectory.hpp"

namespace scfloam {
namespace {

std::string describe(const LoadedTrajectory& t) {
  return t.path.string() + " (" + trajectory_format_name(t.format) + ", " +
         std::to_string(t.poses.size()) + " poses)";
}

std::string span(const std::vector<double>& stamps) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.3f..%.3f s", stamps.front(), stamps.back());
  return buf;
}

}  // namespace

TrajectoryFormat parse_trajectory_format(const std::string& name) {
  if (name == "auto") return TrajectoryFormat::kAuto;
  if (name == "kitti") return TrajectoryFormat::kKitti;
  if (name == "tum") return TrajectoryFormat::kTum;
  throw Error("unknown trajectory format '" + name + "' (use auto, kitti or tum)");
}

const char* trajectory_format_name(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kAuto: return "auto";
    case TrajectoryFormat::kKitti: return "KITTI";
    case TrajectoryFormat::kTum: return "TUM";
  }
  return "?";
}

TrajectoryFormat detect_trajectory_format(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw file_error(path, "cannot open the trajectory file");
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto n = parse_numbers(line, path, line_no).size();
    if (n == 12) return TrajectoryFormat::kKitti;
    if (n == 8) return TrajectoryFormat::kTum;
    throw file_error(path, "line " + std::to_string(line_no) + ": " + std::to_string(n) +
                               " numbers: neither KITTI (12) nor TUM (8)");
  }
  throw file_error(path, "no poses in the file");
}

LoadedTrajectory load_trajectory(const std::filesystem::path& path, TrajectoryFormat format,
                                 const std::optional<std::filesystem::path>& times_path) {
  LoadedTrajectory t;
  t.path = path;
  t.format = format == TrajectoryFormat::kAuto ? detect_trajectory_format(path) : format;
  if (t.format == TrajectoryFormat::kTum) {
    if (times_path)
      throw file_error(*times_path, "a times file is only for KITTI pose files, but " +
                                        path.string() + " is TUM (it carries its own timestamps)");
    StampedTrajectory s = read_tum(path);
    t.poses = std::move(s.poses);
    t.stamps_s = std::move(s.stamps_s);
    return t;
  }
  t.poses = read_kitti_poses(path);
  if (times_path) {
    t.stamps_s = read_times(*times_path);
    if (t.stamps_s.size() != t.poses.size())
      throw file_error(*times_path, std::to_string(t.stamps_s.size()) + " timestamps but " +
                                        path.string() + " has " + std::to_string(t.poses.size()) +
                                        " poses");
  }
  return t;
}

AssociatedTrajectories associate_trajectories(const LoadedTrajectory& gt,
                                              const LoadedTrajectory& est, double max_dt_s) {
  AssociatedTrajectories a;
  a.gt_total = gt.poses.size();
  a.est_total = est.poses.size();
  if (gt.has_stamps() != est.has_stamps()) {
    const LoadedTrajectory& bare = gt.has_stamps() ? est : gt;
    throw Error("cannot pair " + describe(gt) + " with " + describe(est) + ": " +
                bare.path.string() + " has no timestamps (pass " +
                (gt.has_stamps() ? "--est-times" : "--gt-times") +
                " times.txt, or give both files in KITTI format to pair by index)");
  }
  if (!gt.has_stamps()) {
    if (gt.poses.size() != est.poses.size())
      throw Error("pose counts differ: ground truth " + describe(gt) + " vs estimate " +
                  describe(est) + "; KITTI files pair by index and need a pose for every frame");
    a.gt = gt.poses;
    a.est = est.poses;
    a.gt_index.resize(gt.poses.size());
    for (std::size_t i = 0; i < a.gt_index.size(); ++i) a.gt_index[i] = i;
    a.est_index = a.gt_index;
    a.method = "by index";
    return a;
  }

  // Nearest gt stamp for each estimate stamp; both lists are sorted, so a collision (two
  // estimates on one gt pose) can only involve the previous match: keep the closer one.
  struct Match { std::size_t gt_i, est_i; double dt_s; };
  std::vector<Match> matches;
  const auto& gs = gt.stamps_s;
  for (std::size_t i = 0; i < est.stamps_s.size(); ++i) {
    const double t = est.stamps_s[i];
    const auto it = std::lower_bound(gs.begin(), gs.end(), t);
    std::size_t j = static_cast<std::size_t>(it - gs.begin());
    if (j == gs.size() || (j > 0 && t - gs[j - 1] <= gs[j] - t)) j = j == 0 ? 0 : j - 1;
    const double dt = std::abs(gs[j] - t);
    if (dt > max_dt_s) continue;
    if (!matches.empty() && matches.back().gt_i == j) {
      if (dt < matches.back().dt_s) matches.back() = {j, i, dt};
      continue;
    }
    matches.push_back({j, i, dt});
  }
  if (matches.empty()) {
    char tol[32];
    std::snprintf(tol, sizeof tol, "%g", max_dt_s);
    throw Error("no estimate timestamp of " + describe(est) + " (" + span(est.stamps_s) +
                ") lies within " + tol + " s of a ground-truth timestamp of " + describe(gt) +
                " (" + span(gt.stamps_s) + ")");
  }
  for (const Match& m : matches) {
    a.gt.push_back(gt.poses[m.gt_i]);
    a.est.push_back(est.poses[m.est_i]);
    a.gt_index.push_back(m.gt_i);
    a.est_index.push_back(m.est_i);
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "by timestamp (<= %g s)", max_dt_s);
  a.method = buf;
  return a;
}

}  // namespace scfloam
