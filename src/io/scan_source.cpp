#include "scfloam/io/scan_source.hpp"

#include "scfloam/error.hpp"
#include "scfloam/io/bag_source.hpp"
#include "scfloam/io/folder_source.hpp"
#include "scfloam/io/kitti.hpp"

namespace scfloam {
namespace fs = std::filesystem;
namespace {

class KittiScanSource final : public ScanSource {
 public:
  explicit KittiScanSource(KittiSequence seq) : seq_(std::move(seq)) {}
  std::size_t size() const override { return seq_.size(); }
  Scan load(std::size_t index) const override { return seq_.load(index); }
  std::string describe() const override {
    std::string s = "KITTI sequence " + seq_.dir().string() + " (" + std::to_string(seq_.size()) +
                    " scans";
    if (seq_.ground_truth_camera()) s += ", ground truth";
    if (seq_.calib().has_Tr) s += ", Tr";
    return s + ")";
  }
  std::optional<Eigen::Isometry3d> T_cam0_lidar() const override {
    if (!seq_.calib().has_Tr) return std::nullopt;
    return seq_.calib().T_cam0_velo;
  }
  PoseList ground_truth_lidar() const override { return seq_.ground_truth_lidar(); }

 private:
  KittiSequence seq_;
};

void refuse_timestamps_file(const fs::path& path, const ScanSourceOptions& options, const char* kind) {
  if (!options.timestamps_file.empty())
    throw file_error(path, std::string("--timestamps applies to folders of scans and single scan files, not to a ") +
                               kind + " (it has its own stamps)");
}

}  // namespace

InputKind detect_input_kind(const fs::path& path) {
  if (!fs::exists(path)) throw file_error(path, "no such file or directory");
  if (is_bag_input(path)) return InputKind::kBag;
  if (fs::is_directory(path)) return fs::is_directory(path / "velodyne") ? InputKind::kKitti : InputKind::kScanFolder;
  if (fs::is_regular_file(path) && is_scan_file_extension(path)) return InputKind::kScanFile;
  throw file_error(path,
                   "not a recognised input (looked for: a KITTI odometry sequence directory with velodyne/, "
                   "a ROS bag (.bag, .db3, .mcap or a folder with metadata.yaml), a folder of .pcd, .ply or "
                   ".bin scans, or a single .pcd, .ply or .bin file)");
}

std::unique_ptr<ScanSource> open_kitti_source(const fs::path& dir) {
  return std::make_unique<KittiScanSource>(KittiSequence::open(dir));
}

std::unique_ptr<ScanSource> open_scan_source(const fs::path& path, const ScanSourceOptions& options) {
  switch (detect_input_kind(path)) {
    case InputKind::kBag:
      refuse_timestamps_file(path, options, "bag");
      return open_bag_source(path, options);
    case InputKind::kKitti:
      refuse_timestamps_file(path, options, "KITTI sequence (times.txt)");
      return open_kitti_source(path);
    case InputKind::kScanFolder: return open_file_list_source(list_scan_folder(path), options);
    case InputKind::kScanFile: return open_file_list_source(single_scan_file(path), options);
  }
  throw file_error(path, "not a recognised input");
}

}  // namespace scfloam
