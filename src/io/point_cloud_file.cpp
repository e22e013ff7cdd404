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
  // One read of the whole file: a character iterator with a growing string took a tenth of
  // a raw HDL-64E run's CPU time (2.7 MB scans, docs/inputs.md). A pipe has no size to ask
  // for and is read as a stream.
  std::error_code error;
  const bool regular = std::filesystem::is_regular_file(path, error);
  const std::uintmax_t size = regular ? std::filesystem::file_size(path, error) : 0;
  if (!regular || error) {
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw file_error(path, "read error");
    return bytes;
  }
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (size > 0 && !in.read(bytes.data(), static_cast<std::streamsize>(size)))
    throw file_error(path, "read error (" + std::to_string(in.gcount()) + " of " + std::to_string(size) +
                               " bytes: did the file change while read?)");
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
