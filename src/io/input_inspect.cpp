#include "scfloam/io/input_inspect.hpp"

#include <cmath>
#include <cstdio>
#include <utility>
#include <nlohmann/json.hpp>

#include "scfloam/features/beam_layout.hpp"
#include "scfloam/features/sweep_times.hpp"
#include "scfloam/io/bag_source.hpp"
#include "scfloam/io/folder_source.hpp"
#include "scfloam/io/kitti.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/scan_source.hpp"
#include "scfloam/io/sensor_detection.hpp"

namespace scfloam {
namespace fs = std::filesystem;
namespace {

InputInfo inspect_kitti(const fs::path& dir) {
  const KittiSequence seq = KittiSequence::open(dir);
  InputInfo info;
  info.kind = "KITTI sequence";
  info.scans = seq.size();
  Scan first;
  if (seq.scan_path(0).extension() == ".pcd") {
    // Read once: the file gives both its declared fields and the scan.
    PointCloudFile file = read_pcd(seq.scan_path(0));
    info.kind = "KITTI sequence (PCD scans)";
    for (const CloudField& f : file.fields) info.point_fields.push_back(f.name + ":" + field_type_name(f.type));
    first = std::move(file.scan);
  } else {
    info.point_fields = {"x:float32", "y:float32", "z:float32", "reflectance:float32"};
    first = seq.load(0);
  }
  info.points_in_first_scan = first.points.size();
  if (!seq.times().empty()) {
    info.start_time_s = seq.times().front();
    info.end_time_s = seq.times().back();
  }
  info.notes.push_back(seq.ground_truth_camera() ? "ground truth poses.txt: accuracy is reported"
                                                 : "no poses.txt: no accuracy report");
  info.notes.push_back(seq.calib().has_Tr ? "calib.txt has Tr: poses_kitti.txt in camera-0 convention by default"
                                          : "no Tr in calib.txt: poses in the lidar frame (--frame camera refused)");
  if (!first.has_ring && !first.has_time)
    info.notes.push_back("no ring or time fields: rings from elevation");
  else if (!first.has_time)
    info.notes.push_back("ring field, no time field");
  else
    info.notes.push_back(std::string(first.has_ring ? "ring and time fields" : "time field, no ring field") +
                         ": deskewed when the config says so (preprocess.deskew)");
  return info;
}


// What deskew would do with scans that carry no point times: times from the azimuth when the
// point order shows the sweep (features/sweep_times.hpp), else none.
std::string azimuth_times_note(const Scan& first) {
  const SweepLayout sweep = sweep_layout(first.points);
  if (!sweep.usable)
    return "no per-point times, and the point order shows no sweep (" + sweep.why + "): not deskewed";
  char line[256];
  std::snprintf(line, sizeof line,
                "no per-point times: where deskewed (the raw sensors' presets), from the azimuth: %s, turning "
                "%s, seam at %.1f deg",
                sweep.ring_major ? "beam by beam" : "column by column",
                sweep.clockwise ? "clockwise" : "counterclockwise", sweep.seam_rad * 180 / M_PI);
  return line;
}

// The beams of the first scan (src/features/beam_layout.cpp) and the ring tables that fit
// them, so that a user with an unfamiliar sensor knows which --sensor to pass.
void describe_beams(const Scan& first, InputInfo& info) {
  if (first.has_ring) return;  // the scan's own rings are used
  const BeamLayout layout = learn_beam_layout(first.points, 1.0, 200.0);
  char line[320];
  if (layout.points_used < kMinLayoutPoints) {
    std::snprintf(line, sizeof line, "beams: the first scan has only %d usable returns, too few to tell its beams",
                  layout.points_used);
  } else if (!layout.confident) {
    std::snprintf(line, sizeof line,
                  "beams: elevations blurred (%.0f %% of returns on %zu peaks): rings come from the --sensor "
                  "table (KITTI's HDL-64E looks like this: --sensor kitti)",
                  100.0 * layout.clustered_fraction, layout.elevations_deg.size());
  } else {
    // A preset fits when its table keeps every beam in a ring of its own (KITTI's HDL-64E
    // table may crop the lowest beams or the top one at its edge: up to 3 of 64).
    // (io/sensor_detection.hpp)
    std::string fitting;
    for (LidarModel m : matching_ring_tables(layout))
      fitting += std::string(fitting.empty() ? "" : ", ") + lidar_model_name(m);
    std::snprintf(line, sizeof line,
                  "beams: %zu distinct elevations, %+.2f .. %+.2f deg (%.1f %% of returns on them); %s",
                  layout.elevations_deg.size(), layout.elevations_deg.front(), layout.elevations_deg.back(),
                  100.0 * layout.clustered_fraction,
                  fitting.empty() ? "no preset's ring table matches them: rings.lidar: auto uses them (a --sensor table "
                                    "that puts two of them in one ring is replaced by them anyway)"
                                  : ("ring table of --sensor " + fitting + " fits").c_str());
  }
  info.notes.push_back(line);
}

}  // namespace

InputInfo inspect_input(const fs::path& path, const ScanSourceOptions& options) {
  InputInfo info;
  switch (detect_input_kind(path)) {
    case InputKind::kBag: info = inspect_bag(path, options); break;
    case InputKind::kKitti: info = inspect_kitti(path); break;
    case InputKind::kScanFolder: info = inspect_file_list(list_scan_folder(path), options); break;
    case InputKind::kScanFile: info = inspect_file_list(single_scan_file(path), options); break;
  }
  if (info.scans > 0) {
    const auto source = open_scan_source(path, options);
    if (source->size() > 0) {
      const Scan first = source->load(0);
      describe_beams(first, info);
      if (!first.has_time) info.notes.push_back(azimuth_times_note(first));
      const SensorGuess guess = guess_sensor(*source);
      info.notes.push_back("sensor: `scfloam run` without --sensor uses " + guess.preset + " (" + guess.reason + ")");
    }
  }
  return info;
}

std::string input_info_text(const InputInfo& info) {
  std::string out = "kind:      " + info.kind + "\n";
  char line[256];
  if (!info.topics.empty()) {
    out += "topics:\n";
    for (const auto& t : info.topics) {
      std::snprintf(line, sizeof line, "  %-32s %-32s %zu messages\n", t.name.c_str(), t.type.c_str(), t.messages);
      out += line;
    }
    out += "scan topic: " + (info.scan_topic.empty() ? std::string("(none)") : info.scan_topic) + "\n";
  }
  out += "scans:     " + std::to_string(info.scans) + "\n";
  out += "fields:   ";
  for (const auto& f : info.point_fields) out += " " + f;
  out += "\npoints in the first scan: " + std::to_string(info.points_in_first_scan) + "\n";
  std::snprintf(line, sizeof line, "time span: %.6f .. %.6f s (%.3f s)\n", info.start_time_s, info.end_time_s,
                info.end_time_s - info.start_time_s);
  out += line;
  for (const auto& n : info.notes) out += "note:      " + n + "\n";
  return out;
}

std::string input_info_json(const InputInfo& info) {
  nlohmann::json j;
  j["kind"] = info.kind;
  j["topics"] = nlohmann::json::array();
  for (const auto& t : info.topics) j["topics"].push_back({{"name", t.name}, {"type", t.type}, {"messages", t.messages}});
  j["scan_topic"] = info.scan_topic;
  j["scans"] = info.scans;
  j["point_fields"] = info.point_fields;
  j["points_in_first_scan"] = info.points_in_first_scan;
  j["start_time_s"] = info.start_time_s;
  j["end_time_s"] = info.end_time_s;
  j["notes"] = info.notes;
  return j.dump(2) + "\n";
}

}  // namespace scfloam
