// Bags as scan sources: detects the bag kind, picks the PointCloud2 topic, and decodes one
// message per load() through the shared PointCloud2 -> Scan conversion.
#include "scfloam/io/bag_source.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstring>
#include <fstream>

#include "bag_source_internal.hpp"
#include "scfloam/error.hpp"
#include "scfloam/io/pointcloud2.hpp"

namespace scfloam {
namespace fs = std::filesystem;
namespace {

enum class BagKind { None, Ros1, Sqlite, Mcap };

BagKind file_kind(const fs::path& path) {
  char head[16] = {};
  std::ifstream in(path, std::ios::binary);
  in.read(head, sizeof head);
  if (std::memcmp(head, "#ROSBAG V2.0\n", 13) == 0) return BagKind::Ros1;
  if (std::memcmp(head, "\x89MCAP0\r\n", 8) == 0) return BagKind::Mcap;
  if (std::memcmp(head, "SQLite format 3", 16) == 0) return BagKind::Sqlite;
  const std::string ext = path.extension().string();
  if (ext == ".bag") return BagKind::Ros1;
  if (ext == ".mcap") return BagKind::Mcap;
  if (ext == ".db3") return BagKind::Sqlite;
  return BagKind::None;
}

bool is_pointcloud2(const std::string& type) {
  return type == "sensor_msgs/PointCloud2" || type == "sensor_msgs/msg/PointCloud2";
}

// A rosbag2 directory: its metadata.yaml names the storage and the (split) files.
std::unique_ptr<BagFile> open_ros2_directory(const fs::path& dir) {
  const fs::path meta_path = dir / "metadata.yaml";
  YAML::Node info;
  try {
    info = YAML::LoadFile(meta_path.string())["rosbag2_bagfile_information"];
  } catch (const YAML::Exception& e) {
    throw file_error(meta_path, std::string("cannot parse: ") + e.what());
  }
  if (!info) throw file_error(meta_path, "no rosbag2_bagfile_information");
  const std::string storage = info["storage_identifier"].as<std::string>("");
  const std::string compression = info["compression_format"].as<std::string>("");
  if (!compression.empty())
    throw file_error(meta_path, "compressed rosbag2 bags (compression_format: " + compression +
                                    ") are not read; decompress with `ros2 bag convert` first");
  std::vector<fs::path> files;
  for (const auto& rel : info["relative_file_paths"]) {
    fs::path file = dir / rel.as<std::string>();
    // Early rosbag2 versions listed sqlite3 files without their extension.
    if (!fs::exists(file) && storage == "sqlite3" && fs::exists(fs::path(file.string() + ".db3")))
      file += ".db3";
    if (!fs::exists(file)) throw file_error(meta_path, "lists " + file.string() + ", which is missing");
    files.push_back(file);
  }
  if (files.empty()) throw file_error(meta_path, "lists no bag files");
  if (storage == "sqlite3") return open_ros2_sqlite_bag(files, dir);
  if (storage == "mcap") return open_ros2_mcap_bag(files, dir);
  throw file_error(meta_path, "unknown storage_identifier '" + storage + "' (sqlite3 and mcap are read)");
}

std::unique_ptr<BagFile> open_bag_file(const fs::path& path) {
  if (!fs::exists(path)) throw file_error(path, "no such file or directory");
  if (fs::is_directory(path)) {
    if (!fs::exists(path / "metadata.yaml"))
      throw file_error(path, "directory without a rosbag2 metadata.yaml");
    return open_ros2_directory(path);
  }
  switch (file_kind(path)) {
    case BagKind::Ros1: return open_ros1_bag(path);
    case BagKind::Sqlite: return open_ros2_sqlite_bag({path}, path);
    case BagKind::Mcap: return open_ros2_mcap_bag({path}, path);
    case BagKind::None: break;
  }
  throw file_error(path, "not a ROS 1 bag, rosbag2 sqlite3 database or MCAP file");
}

std::vector<std::string> cloud_topics(const BagFile& bag) {
  std::vector<std::string> names;
  for (const TopicInfo& t : bag.topics())
    if (is_pointcloud2(t.type)) names.push_back(t.name);
  return names;
}

std::string join(const std::vector<std::string>& items) {
  std::string s;
  for (const auto& i : items) s += (s.empty() ? "" : ", ") + i;
  return s.empty() ? "none" : s;
}

// The topic `run` reads: options.topic, else the only PointCloud2 topic.
std::string choose_topic(const BagFile& bag, const fs::path& path, const std::string& wanted) {
  const std::vector<std::string> clouds = cloud_topics(bag);
  if (!wanted.empty()) {
    if (std::find(clouds.begin(), clouds.end(), wanted) != clouds.end()) return wanted;
    throw file_error(path, "no sensor_msgs/PointCloud2 topic '" + wanted +
                               "' (PointCloud2 topics: " + join(clouds) + ")");
  }
  if (clouds.size() == 1) return clouds.front();
  if (clouds.empty()) {
    std::vector<std::string> all;
    for (const TopicInfo& t : bag.topics()) all.push_back(t.name + " [" + t.type + "]");
    throw file_error(path, "no sensor_msgs/PointCloud2 topic (topics: " + join(all) + ")");
  }
  throw file_error(path, "several PointCloud2 topics, choose one with --topic: " + join(clouds));
}

void check_serialization(const BagFile& bag, const fs::path& path, const std::string& topic) {
  const std::string format = bag.serialization_format(topic);
  if (bag.wire_format() == WireFormat::Cdr && format != "cdr")
    throw file_error(path, "topic " + topic + " has serialization format '" + format +
                               "' (only 'cdr' is read)");
}

class BagScanSource final : public ScanSource {
 public:
  BagScanSource(std::unique_ptr<BagFile> bag, fs::path path, std::string topic)
      : bag_(std::move(bag)), path_(std::move(path)), topic_(std::move(topic)) {
    bag_->select_topic(topic_);
  }
  std::size_t size() const override { return bag_->size(); }
  Scan load(std::size_t index) const override {
    if (index >= bag_->size())
      throw file_error(path_, "scan " + std::to_string(index) + " out of range");
    std::vector<std::uint8_t> bytes;
    bag_->read(index, bytes);
    const std::string where = path_.string() + ": topic " + topic_ + " message " + std::to_string(index);
    const PointCloud2View cloud = bag_->wire_format() == WireFormat::Ros1
                                      ? decode_ros1_pointcloud2(bytes.data(), bytes.size(), where)
                                      : decode_cdr_pointcloud2(bytes.data(), bytes.size(), where);
    return pointcloud2_to_scan(cloud, where);
  }
  std::string describe() const override {
    return bag_->kind() + " " + path_.string() + " (topic " + topic_ + ", " +
           std::to_string(bag_->size()) + " scans)";
  }

  // The decoded first/last cloud for `info`.
  PointCloud2View cloud(std::size_t index, std::vector<std::uint8_t>& bytes) const {
    bag_->read(index, bytes);
    const std::string where = path_.string() + ": topic " + topic_ + " message " + std::to_string(index);
    return bag_->wire_format() == WireFormat::Ros1
               ? decode_ros1_pointcloud2(bytes.data(), bytes.size(), where)
               : decode_cdr_pointcloud2(bytes.data(), bytes.size(), where);
  }

 private:
  std::unique_ptr<BagFile> bag_;
  fs::path path_;
  std::string topic_;
};

}  // namespace

bool is_bag_input(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return fs::is_regular_file(path / "metadata.yaml", ec);
  return fs::is_regular_file(path, ec) && file_kind(path) != BagKind::None;
}

std::unique_ptr<ScanSource> open_bag_source(const fs::path& path, const ScanSourceOptions& options) {
  std::unique_ptr<BagFile> bag = open_bag_file(path);
  const std::string topic = choose_topic(*bag, path, options.topic);
  check_serialization(*bag, path, topic);
  return std::make_unique<BagScanSource>(std::move(bag), path, topic);
}

InputInfo inspect_bag(const fs::path& path, const ScanSourceOptions& options) {
  std::unique_ptr<BagFile> bag = open_bag_file(path);
  InputInfo info;
  info.kind = bag->kind();
  info.topics = bag->topics();
  std::string topic;
  try {
    topic = choose_topic(*bag, path, options.topic);
    check_serialization(*bag, path, topic);
  } catch (const Error& e) {
    info.notes.push_back(e.what());
    return info;
  }
  info.scan_topic = topic;
  BagScanSource source(std::move(bag), path, topic);
  info.scans = source.size();
  if (info.scans == 0) {
    info.notes.push_back("topic " + topic + " has no messages");
    return info;
  }
  try {
    std::vector<std::uint8_t> bytes;
    const PointCloud2View first = source.cloud(0, bytes);
    info.point_fields = describe_point_fields(first.fields);
    info.start_time_s = first.stamp_s();
    const Scan scan = pointcloud2_to_scan(first, path.string() + ": topic " + topic + " message 0");
    info.points_in_first_scan = scan.points.size();
    if (!scan.has_ring) info.notes.push_back("no ring field (rings are computed from elevation)");
    const std::string time_field = point_time_field(first.fields);
    if (!scan.has_time)
      info.notes.push_back(time_field.empty()
                               ? "no per-point time field"
                               : "per-point time field '" + time_field +
                                     "' ignored: its values are not times within 1.5 s of the stamp");
    if (scan.points.size() < first.width * std::size_t{first.height})
      info.notes.push_back("first scan: " + std::to_string(first.width * std::size_t{first.height} - scan.points.size()) +
                           " points with NaN coordinates dropped");
    info.end_time_s = source.cloud(info.scans - 1, bytes).stamp_s();
  } catch (const Error& e) {
    info.notes.push_back(e.what());
  }
  return info;
}

}  // namespace scfloam
