#include "scfloam/io/point_cloud_file.hpp"

#include <string>

#include "scfloam/atomic_file.hpp"

namespace scfloam {

void write_pcd_binary(const std::filesystem::path& path, const std::vector<LidarPoint>& points) {
  write_file_atomic(path, [&](std::ostream& out) {
    out << "# .PCD v0.7 - Point Cloud Data file format (written by scfloam)\n"
        << "VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
        << "WIDTH " << points.size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
        << "POINTS " << points.size() << "\nDATA binary\n";
    std::vector<float> row(4 * points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      row[4 * i + 0] = points[i].x;
      row[4 * i + 1] = points[i].y;
      row[4 * i + 2] = points[i].z;
      row[4 * i + 3] = points[i].intensity;
    }
    out.write(reinterpret_cast<const char*>(row.data()), row.size() * sizeof(float));
  });
}

}  // namespace scfloam
