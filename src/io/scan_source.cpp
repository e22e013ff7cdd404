#include "scfloam/io/scan_source.hpp"

#include "scfloam/error.hpp"
#include "scfloam/io/kitti.hpp"

namespace scfloam {
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

}  // namespace

std::unique_ptr<ScanSource> open_scan_source(const std::filesystem::path& path,
                                             const ScanSourceOptions& /*options*/) {
  namespace fs = std::filesystem;
  if (!fs::exists(path)) throw file_error(path, "no such file or directory");
  if (fs::is_directory(path) && fs::is_directory(path / "velodyne"))
    return std::make_unique<KittiScanSource>(KittiSequence::open(path));
  throw file_error(path,
                   "not a recognised input (expected a KITTI odometry sequence directory with "
                   "velodyne/, calib.txt and times.txt)");
}

}  // namespace scfloam
