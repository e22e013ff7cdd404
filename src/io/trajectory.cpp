#include "scfloam/io/trajectory.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "scfloam/atomic_file.hpp"
#include "scfloam/error.hpp"

namespace scfloam {
namespace {

std::string at_line(std::size_t line_no) { return "line " + std::to_string(line_no) + ": "; }

void check_rotation(const Eigen::Matrix3d& R, const std::filesystem::path& path,
                    std::size_t line_no) {
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-3 || R.determinant() < 0)
    throw file_error(path, at_line(line_no) + "the 3x3 part is not a rotation matrix");
}

}  // namespace

std::vector<double> parse_numbers(const std::string& line, const std::filesystem::path& path,
                                  std::size_t line_no) {
  std::vector<double> values;
  const char* p = line.c_str();
  while (true) {
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == ',') ++p;
    if (*p == '\0') break;
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    if (end == p) throw file_error(path, at_line(line_no) + "not a number near '" +
                                             std::string(p).substr(0, 20) + "'");
    if (!std::isfinite(v)) throw file_error(path, at_line(line_no) + "non-finite value");
    values.push_back(v);
    p = end;
  }
  return values;
}

std::vector<double> read_times(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw file_error(path, "cannot open the times file");
  std::vector<double> stamps;
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto v = parse_numbers(line, path, line_no);
    if (v.empty()) continue;
    if (v.size() != 1)
      throw file_error(path, "line " + std::to_string(line_no) + ": expected one timestamp, found " +
                                 std::to_string(v.size()) + " numbers");
    if (!stamps.empty() && v[0] < stamps.back())
      throw file_error(path, "line " + std::to_string(line_no) + ": timestamps go backwards");
    stamps.push_back(v[0]);
  }
  if (stamps.empty()) throw file_error(path, "no timestamps in the file");
  return stamps;
}

PoseList read_kitti_poses(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw file_error(path, "cannot open the pose file");
  PoseList poses;
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto v = parse_numbers(line, path, line_no);
    if (v.empty()) continue;
    if (v.size() != 12)
      throw file_error(path, at_line(line_no) + "expected 12 numbers (KITTI 3x4 pose), found " +
                                 std::to_string(v.size()));
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) T.matrix()(r, c) = v[r * 4 + c];
    check_rotation(T.linear(), path, line_no);
    poses.push_back(T);
  }
  if (poses.empty()) throw file_error(path, "no poses in the file");
  return poses;
}

void write_kitti_poses(const std::filesystem::path& path, const PoseList& poses) {
  write_file_atomic(path, [&](std::ostream& out) {
    char buf[64];
    for (const auto& T : poses) {
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) {
          std::snprintf(buf, sizeof buf, "%.9e", T.matrix()(r, c));
          out << buf << (r == 2 && c == 3 ? '\n' : ' ');
        }
    }
  });
}

StampedTrajectory read_tum(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw file_error(path, "cannot open the TUM trajectory");
  StampedTrajectory traj;
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto v = parse_numbers(line, path, line_no);
    if (v.size() != 8)
      throw file_error(path, at_line(line_no) + "expected 8 numbers (t tx ty tz qx qy qz qw), found " +
                                 std::to_string(v.size()));
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-2)
      throw file_error(path, at_line(line_no) + "quaternion is not of unit length");
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = q.normalized().toRotationMatrix();
    T.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    if (!traj.stamps_s.empty() && v[0] < traj.stamps_s.back())
      throw file_error(path, at_line(line_no) + "timestamps go backwards");
    traj.stamps_s.push_back(v[0]);
    traj.poses.push_back(T);
  }
  if (traj.poses.empty()) throw file_error(path, "no poses in the file");
  return traj;
}

void write_tum(const std::filesystem::path& path, const StampedTrajectory& trajectory) {
  if (trajectory.stamps_s.size() != trajectory.poses.size())
    throw file_error(path, "internal: stamps and poses differ in count");
  write_file_atomic(path, [&](std::ostream& out) {
    out << "# timestamp tx ty tz qx qy qz qw\n";
    char buf[256];
    for (std::size_t i = 0; i < trajectory.poses.size(); ++i) {
      const auto& T = trajectory.poses[i];
      const Eigen::Quaterniond q(T.linear());
      const Eigen::Vector3d t = T.translation();
      std::snprintf(buf, sizeof buf, "%.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n",
                    trajectory.stamps_s[i], t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
      out << buf;
    }
  });
}

}  // namespace scfloam
