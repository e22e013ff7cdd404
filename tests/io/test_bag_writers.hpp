// Small writers of PointCloud2 messages and bags for the bag tests: clouds with chosen layouts,
// CDR encoding (either byte order), an MCAP writer (chunked or not, zstd / lz4, with or without
// summary) and a rosbag2 sqlite3 writer. Independent of the readers under test.
#pragma once

#include <lz4frame.h>
#include <rosbag/bag.h>
#include <sensor_msgs/PointCloud2.h>
#include <sqlite3.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "scfloam/io/pointcloud2.hpp"
#include "scfloam/types.hpp"

namespace scfloam::test {

enum class TimeField { None, RelativeSecondsF32, RelativeNanosU32, AbsoluteSecondsF64, AbsoluteNanosF64 };

struct CloudLayout {
  std::uint8_t xyz_type = 7;   // FLOAT32
  bool intensity = true;
  bool ring = true;
  TimeField time = TimeField::RelativeSecondsF32;
  std::uint32_t padding = 0;   // extra bytes at the end of each point
  bool big_endian = false;
  std::uint32_t height = 1;    // > 1: organized, width = ceil(n / height), NaN filled
};

struct OwnedCloud {
  PointCloud2View meta;  // data/data_size unset
  std::vector<std::uint8_t> data;
};

inline void put_value(std::uint8_t* p, std::uint8_t type, double v, bool big_endian) {
  std::uint8_t b[8];
  std::size_t n = point_field_size(type);
  // Integer fields wrap as a driver's would (a ring of -1 in a uint16 field is 65535): through
  // int64, since a double outside the target type's range is undefined behaviour to convert.
  const std::int64_t i = std::isfinite(v) ? static_cast<std::int64_t>(std::clamp(v, -9e18, 9e18)) : 0;
  switch (type) {
    case 1: { auto x = static_cast<std::int8_t>(i); std::memcpy(b, &x, 1); break; }
    case 2: { auto x = static_cast<std::uint8_t>(i); std::memcpy(b, &x, 1); break; }
    case 3: { auto x = static_cast<std::int16_t>(i); std::memcpy(b, &x, 2); break; }
    case 4: { auto x = static_cast<std::uint16_t>(i); std::memcpy(b, &x, 2); break; }
    case 5: { auto x = static_cast<std::int32_t>(i); std::memcpy(b, &x, 4); break; }
    case 6: { auto x = static_cast<std::uint32_t>(i); std::memcpy(b, &x, 4); break; }
    case 7: { auto x = static_cast<float>(v); std::memcpy(b, &x, 4); break; }
    default: { std::memcpy(b, &v, 8); break; }
  }
  if (big_endian)
    for (std::size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
  std::memcpy(p, b, n);
}

inline OwnedCloud make_cloud(const std::vector<LidarPoint>& pts, double stamp_s, const CloudLayout& L) {
  OwnedCloud c;
  c.meta.stamp_sec = static_cast<std::int64_t>(std::floor(stamp_s));
  c.meta.stamp_nanosec = static_cast<std::uint32_t>(std::llround((stamp_s - std::floor(stamp_s)) * 1e9));
  c.meta.frame_id = "velodyne";
  std::uint32_t off = 0;
  auto add = [&](const char* name, std::uint8_t type) {
    c.meta.fields.push_back({name, off, type, 1});
    off += static_cast<std::uint32_t>(point_field_size(type));
  };
  add("x", L.xyz_type);
  add("y", L.xyz_type);
  add("z", L.xyz_type);
  if (L.intensity) add("intensity", 7);
  if (L.ring) add("ring", 4);
  if (L.time == TimeField::RelativeSecondsF32) add("time", 7);
  if (L.time == TimeField::RelativeNanosU32) add("t", 6);
  if (L.time == TimeField::AbsoluteSecondsF64 || L.time == TimeField::AbsoluteNanosF64) add("timestamp", 8);
  c.meta.point_step = off + L.padding;
  c.meta.height = L.height;
  c.meta.width = static_cast<std::uint32_t>((pts.size() + L.height - 1) / L.height);
  c.meta.row_step = c.meta.width * c.meta.point_step;
  c.meta.is_bigendian = L.big_endian;
  c.meta.is_dense = L.height == 1;
  c.data.assign(std::size_t{c.meta.row_step} * L.height, 0xAB);  // padding bytes are garbage
  const std::size_t slots = std::size_t{c.meta.width} * L.height;
  for (std::size_t i = 0; i < slots; ++i) {
    std::uint8_t* p = c.data.data() + i * c.meta.point_step;
    const bool real = i < pts.size();
    const LidarPoint q = real ? pts[i] : LidarPoint{};
    const double nan = std::nan("");
    for (const PointField& f : c.meta.fields) {
      double v = 0;
      if (f.name == "x") v = real ? q.x : nan;
      else if (f.name == "y") v = real ? q.y : nan;
      else if (f.name == "z") v = real ? q.z : nan;
      else if (f.name == "intensity") v = q.intensity;
      else if (f.name == "ring") v = q.ring;
      else if (f.name == "time") v = q.time_s;
      else if (f.name == "t") v = std::llround(static_cast<double>(q.time_s) * 1e9);
      else if (f.name == "timestamp") v = L.time == TimeField::AbsoluteNanosF64 ? (stamp_s + q.time_s) * 1e9 : stamp_s + q.time_s;
      put_value(p + f.offset, f.datatype, v, L.big_endian);
    }
  }
  return c;
}

// CDR (XCDR1) serialization of sensor_msgs/msg/PointCloud2.
class CdrWriter {
 public:
  explicit CdrWriter(bool big_endian) : be_(big_endian) {
    out_ = {0, static_cast<std::uint8_t>(big_endian ? 0 : 1), 0, 0};
  }
  template <typename T>
  void put(T v) {
    while ((out_.size() - 4) % sizeof(T)) out_.push_back(0);
    std::uint8_t b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (be_)
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    out_.insert(out_.end(), b, b + sizeof(T));
  }
  void put_string(const std::string& s) {
    put<std::uint32_t>(static_cast<std::uint32_t>(s.size() + 1));
    out_.insert(out_.end(), s.begin(), s.end());
    out_.push_back(0);
  }
  void put_bytes(const std::vector<std::uint8_t>& b) {
    put<std::uint32_t>(static_cast<std::uint32_t>(b.size()));
    out_.insert(out_.end(), b.begin(), b.end());
  }
  std::vector<std::uint8_t> out_;

 private:
  bool be_;
};

inline std::vector<std::uint8_t> encode_cdr(const OwnedCloud& c, bool big_endian) {
  CdrWriter w(big_endian);
  w.put<std::int32_t>(static_cast<std::int32_t>(c.meta.stamp_sec));
  w.put<std::uint32_t>(c.meta.stamp_nanosec);
  w.put_string(c.meta.frame_id);
  w.put<std::uint32_t>(c.meta.height);
  w.put<std::uint32_t>(c.meta.width);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(c.meta.fields.size()));
  for (const PointField& f : c.meta.fields) {
    w.put_string(f.name);
    w.put<std::uint32_t>(f.offset);
    w.put<std::uint8_t>(f.datatype);
    w.put<std::uint32_t>(f.count);
  }
  w.put<std::uint8_t>(c.meta.is_bigendian);
  w.put<std::uint32_t>(c.meta.point_step);
  w.put<std::uint32_t>(c.meta.row_step);
  w.put_bytes(c.data);
  w.put<std::uint8_t>(c.meta.is_dense);
  return w.out_;
}

// Minimal MCAP writer: one schema and channel per topic, messages optionally in chunks of
// `per_chunk` messages, optional summary (schemas, channels, statistics, chunk indexes).
class McapTestWriter {
 public:
  McapTestWriter(std::string compression, bool chunked, bool summary, int per_chunk = 2)
      : compression_(std::move(compression)), chunked_(chunked), summary_(summary), per_chunk_(per_chunk) {
    const std::uint8_t magic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
    file_.assign(magic, magic + 8);
    std::vector<std::uint8_t> h;
    str(h, "ros2");
    str(h, "scfloam-test");
    record(file_, 0x01, h);
  }
  std::uint16_t add_topic(const std::string& topic, const std::string& type) {
    const auto id = static_cast<std::uint16_t>(topics_.size() + 1);
    std::vector<std::uint8_t> s;
    num<std::uint16_t>(s, id);
    str(s, type);
    str(s, "ros2msg");
    num<std::uint32_t>(s, 0);
    std::vector<std::uint8_t> c;
    num<std::uint16_t>(c, id);
    num<std::uint16_t>(c, id);
    str(c, topic);
    str(c, "cdr");
    num<std::uint32_t>(c, 0);
    record(file_, 0x03, s);
    record(file_, 0x04, c);
    schema_records_.push_back(s);
    channel_records_.push_back(c);
    topics_.push_back(topic);
    return id;
  }
  void write(std::uint16_t channel, std::uint64_t log_time_ns, const std::vector<std::uint8_t>& data) {
    std::vector<std::uint8_t> m;
    num<std::uint16_t>(m, channel);
    num<std::uint32_t>(m, count_);
    num<std::uint64_t>(m, log_time_ns);
    num<std::uint64_t>(m, log_time_ns);
    m.insert(m.end(), data.begin(), data.end());
    ++count_;
    ++per_channel_[channel];
    start_ = std::min(start_, log_time_ns);
    end_ = std::max(end_, log_time_ns);
    if (!chunked_) {
      record(file_, 0x05, m);
      return;
    }
    chunk_index_[channel].push_back({log_time_ns, chunk_.size()});
    record(chunk_, 0x05, m);
    chunk_start_ = std::min(chunk_start_, log_time_ns);
    chunk_end_ = std::max(chunk_end_, log_time_ns);
    if (++in_chunk_ == per_chunk_) flush_chunk();
  }
  std::vector<std::uint8_t> finish() {
    flush_chunk();
    std::vector<std::uint8_t> end;
    num<std::uint32_t>(end, 0);
    record(file_, 0x0F, end);
    std::uint64_t summary_start = 0;
    if (summary_) {
      summary_start = file_.size();
      for (auto& s : schema_records_) record(file_, 0x03, s);
      for (auto& c : channel_records_) record(file_, 0x04, c);
      std::vector<std::uint8_t> st;
      num<std::uint64_t>(st, count_);
      num<std::uint16_t>(st, static_cast<std::uint16_t>(topics_.size()));
      num<std::uint32_t>(st, static_cast<std::uint32_t>(topics_.size()));
      num<std::uint32_t>(st, 0);
      num<std::uint32_t>(st, 0);
      num<std::uint32_t>(st, static_cast<std::uint32_t>(chunk_indexes_.size()));
      num<std::uint64_t>(st, count_ ? start_ : 0);
      num<std::uint64_t>(st, count_ ? end_ : 0);
      num<std::uint32_t>(st, static_cast<std::uint32_t>(per_channel_.size() * 10));
      for (auto& [ch, n] : per_channel_) {
        num<std::uint16_t>(st, ch);
        num<std::uint64_t>(st, n);
      }
      record(file_, 0x0B, st);
      for (auto& ci : chunk_indexes_) record(file_, 0x08, ci);
    }
    std::vector<std::uint8_t> f;
    num<std::uint64_t>(f, summary_start);
    num<std::uint64_t>(f, 0);
    num<std::uint32_t>(f, 0);
    record(file_, 0x02, f);
    const std::uint8_t magic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
    file_.insert(file_.end(), magic, magic + 8);
    return file_;
  }

 private:
  template <typename T>
  static void num(std::vector<std::uint8_t>& o, T v) {
    for (std::size_t i = 0; i < sizeof(T); ++i) o.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  static void str(std::vector<std::uint8_t>& o, const std::string& s) {
    num<std::uint32_t>(o, static_cast<std::uint32_t>(s.size()));
    o.insert(o.end(), s.begin(), s.end());
  }
  static void record(std::vector<std::uint8_t>& o, std::uint8_t op, const std::vector<std::uint8_t>& body) {
    o.push_back(op);
    num<std::uint64_t>(o, body.size());
    o.insert(o.end(), body.begin(), body.end());
  }
  void flush_chunk() {
    if (in_chunk_ == 0) return;
    std::vector<std::uint8_t> packed;
    if (compression_ == "zstd") {
      packed.resize(ZSTD_compressBound(chunk_.size()));
      packed.resize(ZSTD_compress(packed.data(), packed.size(), chunk_.data(), chunk_.size(), 3));
    } else if (compression_ == "lz4") {
      packed.resize(LZ4F_compressFrameBound(chunk_.size(), nullptr));
      packed.resize(LZ4F_compressFrame(packed.data(), packed.size(), chunk_.data(), chunk_.size(), nullptr));
    } else {
      packed = chunk_;
    }
    std::vector<std::uint8_t> c;
    num<std::uint64_t>(c, chunk_start_);
    num<std::uint64_t>(c, chunk_end_);
    num<std::uint64_t>(c, chunk_.size());
    num<std::uint32_t>(c, 0);
    str(c, compression_);
    num<std::uint64_t>(c, packed.size());
    c.insert(c.end(), packed.begin(), packed.end());
    const std::uint64_t chunk_at = file_.size();
    record(file_, 0x06, c);
    const std::uint64_t chunk_len = file_.size() - chunk_at;
    std::vector<std::uint8_t> offsets;
    const std::uint64_t index_at = file_.size();
    for (auto& [ch, entries] : chunk_index_) {
      num<std::uint16_t>(offsets, ch);
      num<std::uint64_t>(offsets, file_.size());
      std::vector<std::uint8_t> mi;
      num<std::uint16_t>(mi, ch);
      num<std::uint32_t>(mi, static_cast<std::uint32_t>(entries.size() * 16));
      for (auto& [t, off] : entries) {
        num<std::uint64_t>(mi, t);
        num<std::uint64_t>(mi, off);
      }
      record(file_, 0x07, mi);
    }
    std::vector<std::uint8_t> ci;
    num<std::uint64_t>(ci, chunk_start_);
    num<std::uint64_t>(ci, chunk_end_);
    num<std::uint64_t>(ci, chunk_at);
    num<std::uint64_t>(ci, chunk_len);
    num<std::uint32_t>(ci, static_cast<std::uint32_t>(offsets.size()));
    ci.insert(ci.end(), offsets.begin(), offsets.end());
    num<std::uint64_t>(ci, file_.size() - index_at);
    str(ci, compression_);
    num<std::uint64_t>(ci, packed.size());
    num<std::uint64_t>(ci, chunk_.size());
    chunk_indexes_.push_back(ci);
    chunk_.clear();
    chunk_index_.clear();
    in_chunk_ = 0;
    chunk_start_ = ~std::uint64_t{0};
    chunk_end_ = 0;
  }

  std::string compression_;
  bool chunked_, summary_;
  int per_chunk_, in_chunk_ = 0;
  std::vector<std::uint8_t> file_, chunk_;
  std::vector<std::vector<std::uint8_t>> schema_records_, channel_records_, chunk_indexes_;
  std::vector<std::string> topics_;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::map<std::uint16_t, std::uint64_t> per_channel_;
  std::uint32_t count_ = 0;
  std::uint64_t start_ = ~std::uint64_t{0}, end_ = 0;
  std::uint64_t chunk_start_ = ~std::uint64_t{0}, chunk_end_ = 0;
};

inline void write_bytes(const std::filesystem::path& path, const std::vector<std::uint8_t>& b) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

// A rosbag2 sqlite3 file with the new schema (type_description_hash) or the old one.
inline void write_sqlite_bag(const std::filesystem::path& db_path, const std::string& topic,
                             const std::string& format,
                             const std::vector<std::pair<std::int64_t, std::vector<std::uint8_t>>>& msgs,
                             bool new_schema) {
  std::filesystem::remove(db_path);
  sqlite3* db = nullptr;
  sqlite3_open(db_path.c_str(), &db);
  const std::string topics =
      std::string("CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,"
                  "serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL") +
      (new_schema ? ",type_description_hash TEXT NOT NULL);" : ");");
  sqlite3_exec(db, topics.c_str(), nullptr, nullptr, nullptr);
  sqlite3_exec(db, "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,"
                   "timestamp INTEGER NOT NULL,data BLOB NOT NULL);", nullptr, nullptr, nullptr);
  const std::string insert_topic =
      "INSERT INTO topics VALUES(1,'/imu','sensor_msgs/msg/Imu','cdr',''" +
      std::string(new_schema ? ",''" : "") + "),(2,'" + topic + "','sensor_msgs/msg/PointCloud2','" +
      format + "',''" + (new_schema ? ",''" : "") + ");";
  sqlite3_exec(db, insert_topic.c_str(), nullptr, nullptr, nullptr);
  sqlite3_stmt* st = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO messages(topic_id,timestamp,data) VALUES(?,?,?)", -1, &st, nullptr);
  // Insert in reverse time order, with an IMU message between: the reader must sort by time.
  for (auto it = msgs.rbegin(); it != msgs.rend(); ++it) {
    for (int topic_id : {2, 1}) {
      sqlite3_bind_int(st, 1, topic_id);
      sqlite3_bind_int64(st, 2, it->first);
      const std::vector<std::uint8_t> imu(8, 0);
      const auto& blob = topic_id == 2 ? it->second : imu;
      sqlite3_bind_blob(st, 3, blob.data(), static_cast<int>(blob.size()), SQLITE_TRANSIENT);
      sqlite3_step(st);
      sqlite3_reset(st);
    }
  }
  sqlite3_finalize(st);
  sqlite3_close(db);
}

// ROS 1 bag through librosbag's writer (LZ4 chunks), messages built by ROS's sensor_msgs
// classes; every cloud goes to every topic.
inline void write_ros1_bag(const std::filesystem::path& path, const std::vector<std::string>& topics,
                           const std::vector<OwnedCloud>& clouds) {
  rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
  bag.setCompression(rosbag::compression::LZ4);
  for (const OwnedCloud& c : clouds) {
    sensor_msgs::PointCloud2 msg;
    msg.header.stamp = ros::Time(static_cast<std::uint32_t>(c.meta.stamp_sec), c.meta.stamp_nanosec);
    msg.header.frame_id = c.meta.frame_id;
    msg.height = c.meta.height;
    msg.width = c.meta.width;
    for (const PointField& f : c.meta.fields) {
      sensor_msgs::PointField pf;
      pf.name = f.name;
      pf.offset = f.offset;
      pf.datatype = f.datatype;
      pf.count = f.count;
      msg.fields.push_back(pf);
    }
    msg.is_bigendian = c.meta.is_bigendian;
    msg.point_step = c.meta.point_step;
    msg.row_step = c.meta.row_step;
    msg.data = c.data;
    msg.is_dense = c.meta.is_dense;
    for (const auto& topic : topics) bag.write(topic, msg.header.stamp, msg);
  }
}

}  // namespace scfloam::test
