// ROS 2 bags in MCAP storage: one or several .mcap files (split bags) read by McapFile.
#include <algorithm>
#include <map>

#include "bag_source_internal.hpp"
#include "mcap_reader.hpp"
#include "scfloam/error.hpp"

namespace scfloam {
namespace {

class Ros2McapBag final : public BagFile {
 public:
  Ros2McapBag(const std::vector<std::filesystem::path>& files, const std::filesystem::path& name)
      : name_(name) {
    std::map<std::string, TopicInfo> by_name;
    for (const auto& path : files) {
      files_.push_back(McapFile::open(path));
      const McapFile& f = *files_.back();
      for (const auto& [id, ch] : f.channels()) {
        TopicInfo& t = by_name[ch.topic];
        t.name = ch.topic;
        const auto schema = f.schemas().find(ch.schema_id);
        if (schema != f.schemas().end()) t.type = schema->second.name;
        encodings_[ch.topic] = ch.message_encoding;
      }
      for (const McapMessageRef& m : f.messages()) ++by_name[f.channels().at(m.channel_id).topic].messages;
    }
    for (auto& [n, info] : by_name) topics_.push_back(info);
  }

  std::string kind() const override { return "ROS 2 bag (MCAP)"; }
  const std::vector<TopicInfo>& topics() const override { return topics_; }
  WireFormat wire_format() const override { return WireFormat::Cdr; }
  std::string serialization_format(const std::string& topic) const override {
    const auto it = encodings_.find(topic);
    return it == encodings_.end() ? std::string() : it->second;
  }

  void select_topic(const std::string& topic) override {
    index_.clear();
    for (std::size_t i = 0; i < files_.size(); ++i) {
      const McapFile& f = *files_[i];
      for (const McapMessageRef& m : f.messages())
        if (f.channels().at(m.channel_id).topic == topic) index_.push_back({i, m});
    }
    // Split files follow each other in time; a stable sort keeps file order among equal stamps.
    std::stable_sort(index_.begin(), index_.end(), [](const Entry& a, const Entry& b) {
      return a.ref.log_time_ns < b.ref.log_time_ns;
    });
  }
  std::size_t size() const override { return index_.size(); }
  void read(std::size_t index, std::vector<std::uint8_t>& bytes) const override {
    const Entry& e = index_.at(index);
    files_[e.file]->read(e.ref, bytes);
  }

 private:
  struct Entry {
    std::size_t file;
    McapMessageRef ref;
  };
  std::filesystem::path name_;
  std::vector<std::unique_ptr<McapFile>> files_;
  std::vector<TopicInfo> topics_;
  std::map<std::string, std::string> encodings_;
  std::vector<Entry> index_;
};

}  // namespace

std::unique_ptr<BagFile> open_ros2_mcap_bag(const std::vector<std::filesystem::path>& files,
                                            const std::filesystem::path& name) {
  return std::make_unique<Ros2McapBag>(files, name);
}

}  // namespace scfloam
