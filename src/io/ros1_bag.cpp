// ROS 1 bag 2.0 through Debian's librosbag (rosbag_storage): it handles the chunk formats
// (none, bz2, lz4), connection and index records; we take the serialized bytes of each message.
#include <console_bridge/console.h>
#include <rosbag/bag.h>
#include <rosbag/query.h>
#include <rosbag/view.h>

#include <map>
#include <mutex>

#include "bag_source_internal.hpp"
#include "ros1_bag_check.hpp"
#include "scfloam/error.hpp"

namespace scfloam {
namespace {

class Ros1BagFile final : public BagFile {
 public:
  explicit Ros1BagFile(const std::filesystem::path& path) : path_(path) {
    // librosbag also prints its errors through console_bridge; they reach the user as the
    // Error below instead, once.
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
    check_ros1_bag_records(path);  // before librosbag sizes buffers from corrupt lengths
    try {
      bag_.open(path.string(), rosbag::bagmode::Read);
      rosbag::View all(bag_);
      std::map<std::string, TopicInfo> by_name;
      for (const rosbag::ConnectionInfo* c : all.getConnections()) {
        TopicInfo& t = by_name[c->topic];
        t.name = c->topic;
        t.type = c->datatype;
      }
      for (const rosbag::MessageInstance& m : all) ++by_name[m.getTopic()].messages;
      for (auto& [name, info] : by_name) topics_.push_back(info);
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      // rosbag::BagException, ros::Exception from corrupt headers, bad_alloc from corrupt sizes.
      throw file_error(path, std::string("cannot read ROS 1 bag: ") + e.what());
    }
  }

  std::string kind() const override { return "ROS 1 bag"; }
  const std::vector<TopicInfo>& topics() const override { return topics_; }
  WireFormat wire_format() const override { return WireFormat::Ros1; }
  std::string serialization_format(const std::string&) const override { return "ros1"; }

  void select_topic(const std::string& topic) override {
    index_.clear();
    try {
      rosbag::View view(bag_, rosbag::TopicQuery(topic));
      for (const rosbag::MessageInstance& m : view) index_.push_back(m);
    } catch (const std::exception& e) {
      throw file_error(path_, "cannot index topic " + topic + ": " + e.what());
    }
  }

  std::size_t size() const override { return index_.size(); }

  void read(std::size_t index, std::vector<std::uint8_t>& bytes) const override {
    // rosbag::Bag keeps one file handle and chunk buffer: reads are serialized.
    std::lock_guard<std::mutex> lock(mutex_);
    try {
      const rosbag::MessageInstance& m = index_.at(index);
      bytes.resize(m.size());
      ros::serialization::OStream stream(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
      m.write(stream);
    } catch (const std::exception& e) {
      throw file_error(path_, "message " + std::to_string(index) + ": " + e.what());
    }
  }

 private:
  std::filesystem::path path_;
  rosbag::Bag bag_;
  std::vector<TopicInfo> topics_;
  std::vector<rosbag::MessageInstance> index_;
  mutable std::mutex mutex_;
};

}  // namespace

std::unique_ptr<BagFile> open_ros1_bag(const std::filesystem::path& path) {
  return std::make_unique<Ros1BagFile>(path);
}

}  // namespace scfloam
