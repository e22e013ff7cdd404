#include "scfloam/io/point_cloud_file.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>

#include "scfloam/error.hpp"
#include "scfloam/io/kitti.hpp"

namespace scfloam {

std::string read_file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw file_error(path, "cannot open for reading");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw file_error(path, "read error");
  return bytes;
}

PointCloudFile read_point_cloud_file(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".pcd") return read_pcd(path);
  if (ext == ".ply") return read_ply(path);
  if (ext == ".bin") {
    PointCloudFile file;
    file.scan.points = read_kitti_bin(path);
    file.format = "KITTI .bin";
    file.declared_points = file.scan.points.size();
    file.fields = {{"x", 0, FieldType::kFloat32}, {"y", 4, FieldType::kFloat32},
                   {"z", 8, FieldType::kFloat32}, {"reflectance", 12, FieldType::kFloat32}};
    return file;
  }
  throw file_error(path, "not a point-cloud file (expected .pcd, .ply or .bin)");
}

void write_pcd_binary(const std::filesystem::path& path, const std::vector<LidarPoint>& points) {
  write_pcd(path, points, PcdEncoding::kBinary);
}

}  // namespace scfloam
