#include "scfloam/io/folder_source.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>

#include "scfloam/error.hpp"
#include "scfloam/io/point_cloud_file.hpp"
#include "scfloam/io/trajectory.hpp"

namespace scfloam {
namespace fs = std::filesystem;
namespace {

constexpr double kDefaultPeriodS = 0.1;

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

std::string kind_of(const std::string& ext) {
  if (ext == ".pcd") return "PCD";
  if (ext == ".ply") return "PLY";
  return "KITTI .bin";
}

enum class StampOrigin { kTimestampsFile, kFileNames, kScans, kEvenlySpaced };

struct Stamps {
  StampOrigin origin = StampOrigin::kEvenlySpaced;
  std::vector<double> values_s;  // empty for kScans (read with each scan)
  std::string note;
};

// A file name that is a time: "1583836591.182590976" (seconds) or "1583836591182590976" (ns).
bool stamp_from_name(const fs::path& file, double* stamp_s) {
  const std::string stem = file.stem().string();
  if (stem.empty() || !std::isdigit(static_cast<unsigned char>(stem[0]))) return false;
  char* end = nullptr;
  const double v = std::strtod(stem.c_str(), &end);
  if (*end != '\0') return false;
  if (v >= 1e17) *stamp_s = v * 1e-9;
  else if (v >= 1e8) *stamp_s = v;
  else return false;
  return true;
}

Stamps decide_stamps(const ScanFileList& list, const ScanSourceOptions& options, const Scan& first_scan) {
  Stamps s;
  const std::size_t n = list.files.size();
  if (!options.timestamps_file.empty()) {
    s.values_s = read_times(options.timestamps_file);
    if (s.values_s.size() != n)
      throw file_error(options.timestamps_file, std::to_string(s.values_s.size()) + " timestamps for " +
                                                    std::to_string(n) + " scans (one per scan expected)");
    s.origin = StampOrigin::kTimestampsFile;
    s.note = "stamps from " + options.timestamps_file.string();
    return s;
  }
  std::vector<double> from_names(n);
  bool all_named = true;
  for (std::size_t i = 0; i < n && all_named; ++i) all_named = stamp_from_name(list.files[i], &from_names[i]);
  if (all_named && std::is_sorted(from_names.begin(), from_names.end())) {
    s.origin = StampOrigin::kFileNames;
    s.values_s = std::move(from_names);
    s.note = "stamps from the file names";
    return s;
  }
  if (first_scan.timestamp_s != 0) {
    s.origin = StampOrigin::kScans;
    s.note = "stamps from each scan's absolute per-point times (first point)";
    return s;
  }
  s.values_s.resize(n);
  for (std::size_t i = 0; i < n; ++i) s.values_s[i] = kDefaultPeriodS * static_cast<double>(i);
  s.note = "no timestamps (no --timestamps file, no stamps in names or points): scans assumed 0.1 s apart";
  return s;
}

class FileListSource final : public ScanSource {
 public:
  FileListSource(ScanFileList list, Stamps stamps) : list_(std::move(list)), stamps_(std::move(stamps)) {}
  std::size_t size() const override { return list_.files.size(); }
  Scan load(std::size_t index) const override {
    Scan scan = read_point_cloud_file(list_.files.at(index)).scan;
    if (stamps_.origin != StampOrigin::kScans) scan.timestamp_s = stamps_.values_s[index];
    return scan;
  }
  std::string describe() const override {
    const fs::path where = list_.files.size() == 1 ? list_.files.front() : list_.files.front().parent_path();
    return list_.kind + " " + where.string() + " (" + std::to_string(list_.files.size()) + " scans, " +
           stamps_.note + ")";
  }

 private:
  ScanFileList list_;
  Stamps stamps_;
};

}  // namespace

bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const bool da = std::isdigit(static_cast<unsigned char>(a[i]));
    const bool db = std::isdigit(static_cast<unsigned char>(b[j]));
    if (da && db) {
      std::size_t ei = i, ej = j;
      while (ei < a.size() && std::isdigit(static_cast<unsigned char>(a[ei]))) ++ei;
      while (ej < b.size() && std::isdigit(static_cast<unsigned char>(b[ej]))) ++ej;
      std::size_t zi = i, zj = j;  // skip leading zeros, then the longer number is larger
      while (zi + 1 < ei && a[zi] == '0') ++zi;
      while (zj + 1 < ej && b[zj] == '0') ++zj;
      if (ei - zi != ej - zj) return ei - zi < ej - zj;
      const int c = a.compare(zi, ei - zi, b, zj, ej - zj);
      if (c != 0) return c < 0;
      i = ei;
      j = ej;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  if (a.size() - i != b.size() - j) return a.size() - i < b.size() - j;
  return a < b;  // equal under natural order ("01" vs "1"): any fixed order
}

bool is_scan_file_extension(const fs::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".pcd" || ext == ".ply" || ext == ".bin";
}

ScanFileList list_scan_folder(const fs::path& dir) {
  ScanFileList list;
  std::string ext_seen;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (!entry.is_regular_file() || !is_scan_file_extension(entry.path())) continue;
    const std::string ext = lower_extension(entry.path());
    if (!ext_seen.empty() && ext != ext_seen)
      throw file_error(dir, "the folder mixes " + ext_seen + " and " + ext +
                                " scans (one kind per folder: move the others out)");
    ext_seen = ext;
    list.files.push_back(entry.path());
  }
  if (ec) throw file_error(dir, "cannot list the folder: " + ec.message());
  if (list.files.empty())
    throw file_error(dir, "no scans in the folder (looked for .pcd, .ply and .bin files, and for a KITTI "
                          "velodyne/ subfolder or a ROS 2 bag's metadata.yaml)");
  std::sort(list.files.begin(), list.files.end(), [](const fs::path& a, const fs::path& b) {
    return natural_less(a.filename().string(), b.filename().string());
  });
  list.kind = kind_of(ext_seen) + " folder";
  return list;
}

ScanFileList single_scan_file(const fs::path& file) {
  if (!is_scan_file_extension(file)) throw file_error(file, "not a scan file (expected .pcd, .ply or .bin)");
  return ScanFileList{{file}, kind_of(lower_extension(file)) + " file"};
}

std::unique_ptr<ScanSource> open_file_list_source(ScanFileList list, const ScanSourceOptions& options) {
  // The first scan is read now: a bad file fails at open, and it tells whether scans carry stamps.
  const Scan first = read_point_cloud_file(list.files.front()).scan;
  Stamps stamps = decide_stamps(list, options, first);
  return std::make_unique<FileListSource>(std::move(list), std::move(stamps));
}

InputInfo inspect_file_list(const ScanFileList& list, const ScanSourceOptions& options) {
  const PointCloudFile first = read_point_cloud_file(list.files.front());
  const Stamps stamps = decide_stamps(list, options, first.scan);
  InputInfo info;
  info.kind = list.kind + " (" + first.format + ")";
  info.scans = list.files.size();
  info.point_fields = describe_fields(first.fields);
  info.points_in_first_scan = first.scan.points.size();
  if (stamps.origin == StampOrigin::kScans) {
    info.start_time_s = first.scan.timestamp_s;
    info.end_time_s = read_point_cloud_file(list.files.back()).scan.timestamp_s;
  } else {
    info.start_time_s = stamps.values_s.front();
    info.end_time_s = stamps.values_s.back();
  }
  info.notes.push_back(stamps.note);
  if (first.declared_points != first.scan.points.size())
    info.notes.push_back(std::to_string(first.declared_points - first.scan.points.size()) +
                         " points of the first scan have NaN coordinates (organized cloud) and are dropped");
  if (!first.scan.has_ring)
    info.notes.push_back("no ring field: rings come from each point's elevation (pick the sensor preset)");
  if (!first.scan.has_time) info.notes.push_back("no per-point time field");
  return info;
}

}  // namespace scfloam
