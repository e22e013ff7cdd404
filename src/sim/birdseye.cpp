// Accumulating scans into a bird's-eye raster.
#include "scfloam/sim/birdseye.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "scfloam/error.hpp"
#include "scfloam/progress.hpp"

namespace scfloam::sim {

BirdseyeImage render_birdseye(const KittiSequence& seq, const PoseList& poses,
                              const BirdseyeOptions& opt, bool progress) {
  if (poses.size() < seq.size())
    throw file_error(seq.dir(), "has " + std::to_string(seq.size()) + " scans but only " +
                                    std::to_string(poses.size()) + " poses to render them with");
  if (opt.every == 0 || !(opt.resolution_m > 0)) throw Error("render: --every must be >= 1 and --resolution > 0");
  double xmin = 1e18, ymin = 1e18, xmax = -1e18, ymax = -1e18;
  for (std::size_t k = 0; k < seq.size(); k += opt.every) {
    const Eigen::Vector3d p = poses[k].translation();
    xmin = std::min(xmin, p.x() - opt.max_range_m);
    xmax = std::max(xmax, p.x() + opt.max_range_m);
    ymin = std::min(ymin, p.y() - opt.max_range_m);
    ymax = std::max(ymax, p.y() + opt.max_range_m);
  }
  BirdseyeImage img;
  img.resolution_m = opt.resolution_m;
  while ((xmax - xmin) * (ymax - ymin) / (img.resolution_m * img.resolution_m) > static_cast<double>(opt.max_pixels))
    img.resolution_m *= 1.25;
  if (img.resolution_m != opt.resolution_m && progress)
    std::fprintf(stderr, "render: resolution coarsened to %.3f m/pixel to stay under %zu pixels\n",
                 img.resolution_m, opt.max_pixels);
  img.width = static_cast<int>(std::ceil((xmax - xmin) / img.resolution_m));
  img.height = static_cast<int>(std::ceil((ymax - ymin) / img.resolution_m));
  img.x0 = xmin;
  img.y_top = ymax;
  const std::size_t cells = static_cast<std::size_t>(img.width) * img.height;
  std::vector<float> zmin(cells, std::numeric_limits<float>::infinity()), zmax(cells, -std::numeric_limits<float>::infinity());
  auto cell_of = [&](double x, double y, std::size_t* idx) {
    const int px = static_cast<int>((x - img.x0) / img.resolution_m);
    const int py = static_cast<int>((img.y_top - y) / img.resolution_m);
    if (px < 0 || py < 0 || px >= img.width || py >= img.height) return false;
    *idx = static_cast<std::size_t>(py) * img.width + px;
    return true;
  };
  const std::size_t used = (seq.size() + opt.every - 1) / opt.every;
  ProgressBar bar("render", used, progress);
  const double r2 = opt.max_range_m * opt.max_range_m;
  std::size_t done = 0;
  for (std::size_t k = 0; k < seq.size(); k += opt.every) {
    const Scan scan = seq.load(k);
    const Eigen::Matrix3d R = poses[k].linear();
    const Eigen::Vector3d t = poses[k].translation();
    for (const auto& pt : scan.points) {
      const Eigen::Vector3d p(pt.x, pt.y, pt.z);
      if (p.squaredNorm() > r2) continue;
      const Eigen::Vector3d w = R * p + t;
      std::size_t idx;
      if (!cell_of(w.x(), w.y(), &idx)) continue;
      zmin[idx] = std::min(zmin[idx], static_cast<float>(w.z()));
      zmax[idx] = std::max(zmax[idx], static_cast<float>(w.z()));
    }
    bar.update(++done);
  }
  bar.finish();
  img.rgb.assign(cells * 3, 0);
  for (std::size_t i = 0; i < cells; ++i) {
    if (!(zmax[i] >= zmin[i])) continue;
    const double extent = std::min(1.0, (zmax[i] - zmin[i]) / 3.0);
    const auto v = static_cast<std::uint8_t>(45 + 210 * std::pow(extent, 0.6));
    img.rgb[3 * i] = img.rgb[3 * i + 1] = img.rgb[3 * i + 2] = v;
  }
  for (std::size_t k = 0; k < seq.size(); ++k) {
    const Eigen::Vector3d p = poses[k].translation();
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        std::size_t idx;
        if (!cell_of(p.x() + dx * img.resolution_m, p.y() + dy * img.resolution_m, &idx)) continue;
        img.rgb[3 * idx] = 255;
        img.rgb[3 * idx + 1] = 40;
        img.rgb[3 * idx + 2] = 40;
      }
  }
  return img;
}

}  // namespace scfloam::sim
