// What every bag backend (ROS 1, ROS 2 sqlite3, ROS 2 MCAP) provides to the shared scan source:
// its topics, and random access to the serialized messages of one topic in time order.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "scfloam/io/input_info.hpp"

namespace scfloam {

enum class WireFormat { Ros1, Cdr };

class BagFile {
 public:
  virtual ~BagFile() = default;
  virtual std::string kind() const = 0;                 // "ROS 1 bag", "ROS 2 bag (MCAP)", ...
  virtual const std::vector<TopicInfo>& topics() const = 0;
  virtual WireFormat wire_format() const = 0;
  // Serialization format of a topic as the bag states it ("cdr" for ROS 2; "ros1" for ROS 1).
  virtual std::string serialization_format(const std::string& topic) const = 0;
  // Indexes the messages of `topic` (ordered by receive time); later calls replace it.
  virtual void select_topic(const std::string& topic) = 0;
  virtual std::size_t size() const = 0;
  // The serialized message `index` of the selected topic. Thread-safe.
  virtual void read(std::size_t index, std::vector<std::uint8_t>& bytes) const = 0;
};

std::unique_ptr<BagFile> open_ros1_bag(const std::filesystem::path& path);
std::unique_ptr<BagFile> open_ros2_sqlite_bag(const std::vector<std::filesystem::path>& files,
                                              const std::filesystem::path& name);
std::unique_ptr<BagFile> open_ros2_mcap_bag(const std::vector<std::filesystem::path>& files,
                                            const std::filesystem::path& name);

}  // namespace scfloam
