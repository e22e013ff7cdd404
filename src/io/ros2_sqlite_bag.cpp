// ROS 2 bags in sqlite3 storage: one or several .db3 files (split bags). Both schemas are read
// (topics with or without offered_qos_profiles / type_description_hash): only id, name, type
// and serialization_format are used. Messages are fetched one by one by row id.
#include <sqlite3.h>

#include <algorithm>
#include <map>
#include <mutex>

#include "bag_source_internal.hpp"
#include "scfloam/error.hpp"

namespace scfloam {
namespace {

std::string uri_escape(const std::string& path) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (const unsigned char c : path) {
    if (c == '%' || c == '?' || c == '#' || c < 0x20 || c >= 0x7F) {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

class Database {
 public:
  explicit Database(const std::filesystem::path& path) : path_(path) {
    // Bags are never written here. Without a non-empty write-ahead log the database is opened
    // immutable, so that SQLite touches no file next to it (as root it would rewrite the
    // -shm / -wal files even of a read-only connection). A non-empty -wal holds messages of a
    // recording that was not closed cleanly: it must be read, so that case opens read-only.
    std::error_code ec;
    const auto wal = std::filesystem::path(path.string() + "-wal");
    const bool wal_has_data = std::filesystem::exists(wal, ec) && std::filesystem::file_size(wal, ec) > 0;
    const std::string target = wal_has_data ? path.string() : "file:" + uri_escape(path.string()) + "?immutable=1";
    if (sqlite3_open_v2(target.c_str(), &db_, SQLITE_OPEN_READONLY | SQLITE_OPEN_FULLMUTEX | SQLITE_OPEN_URI,
                        nullptr) != SQLITE_OK)
      fail("cannot open as sqlite3");
  }
  ~Database() { sqlite3_close(db_); }
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  // Runs `sql` with optional text parameter; calls `row(stmt)` per result row.
  template <typename RowFn>
  void query(const std::string& sql, const std::string* param, RowFn row) const {
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) fail(sql);
    if (param) sqlite3_bind_text(stmt, 1, param->c_str(), -1, SQLITE_TRANSIENT);
    int rc;
    while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) row(stmt);
    sqlite3_finalize(stmt);
    if (rc != SQLITE_DONE) fail(sql);
  }

  void read_blob(std::int64_t id, std::vector<std::uint8_t>& out) const {
    std::lock_guard<std::mutex> lock(mutex_);
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v2(db_, "SELECT data FROM messages WHERE id = ?", -1, &stmt, nullptr) != SQLITE_OK)
      fail("reading a message");
    sqlite3_bind_int64(stmt, 1, id);
    const int rc = sqlite3_step(stmt);
    if (rc != SQLITE_ROW) {
      sqlite3_finalize(stmt);
      fail("message row " + std::to_string(id) + " is missing");
    }
    const auto* p = static_cast<const std::uint8_t*>(sqlite3_column_blob(stmt, 0));
    const int n = sqlite3_column_bytes(stmt, 0);
    out.assign(p, p + n);
    sqlite3_finalize(stmt);
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw file_error(path_, "sqlite3 error (" + what + "): " + sqlite3_errmsg(db_));
  }

 private:
  std::filesystem::path path_;
  sqlite3* db_ = nullptr;
  mutable std::mutex mutex_;
};

std::string column_text(sqlite3_stmt* stmt, int col) {
  const unsigned char* t = sqlite3_column_text(stmt, col);
  return t ? reinterpret_cast<const char*>(t) : "";
}

class Ros2SqliteBag final : public BagFile {
 public:
  Ros2SqliteBag(const std::vector<std::filesystem::path>& files, const std::filesystem::path& name)
      : name_(name) {
    std::map<std::string, TopicInfo> by_name;
    for (const auto& path : files) {
      dbs_.push_back(std::make_unique<Database>(path));
      const Database& db = *dbs_.back();
      db.query("SELECT id, name, type, serialization_format FROM topics", nullptr,
               [&](sqlite3_stmt* s) {
                 const std::string topic = column_text(s, 1);
                 TopicInfo& t = by_name[topic];
                 t.name = topic;
                 t.type = column_text(s, 2);
                 formats_[topic] = column_text(s, 3);
               });
      db.query("SELECT t.name, COUNT(*) FROM messages m JOIN topics t ON m.topic_id = t.id GROUP BY t.name",
               nullptr, [&](sqlite3_stmt* s) {
                 by_name[column_text(s, 0)].messages += static_cast<std::size_t>(sqlite3_column_int64(s, 1));
               });
    }
    for (auto& [n, info] : by_name) topics_.push_back(info);
  }

  std::string kind() const override { return "ROS 2 bag (sqlite3)"; }
  const std::vector<TopicInfo>& topics() const override { return topics_; }
  WireFormat wire_format() const override { return WireFormat::Cdr; }
  std::string serialization_format(const std::string& topic) const override {
    const auto it = formats_.find(topic);
    return it == formats_.end() ? std::string() : it->second;
  }

  void select_topic(const std::string& topic) override {
    index_.clear();
    for (std::size_t i = 0; i < dbs_.size(); ++i)
      dbs_[i]->query(
          "SELECT m.id, m.timestamp FROM messages m JOIN topics t ON m.topic_id = t.id "
          "WHERE t.name = ? ORDER BY m.timestamp, m.id",
          &topic, [&](sqlite3_stmt* s) {
            index_.push_back({i, sqlite3_column_int64(s, 0), sqlite3_column_int64(s, 1)});
          });
    std::stable_sort(index_.begin(), index_.end(),
                     [](const Entry& a, const Entry& b) { return a.stamp_ns < b.stamp_ns; });
  }
  std::size_t size() const override { return index_.size(); }
  void read(std::size_t index, std::vector<std::uint8_t>& bytes) const override {
    const Entry& e = index_.at(index);
    dbs_[e.file]->read_blob(e.row_id, bytes);
  }

 private:
  struct Entry {
    std::size_t file;
    std::int64_t row_id, stamp_ns;
  };
  std::filesystem::path name_;
  std::vector<std::unique_ptr<Database>> dbs_;
  std::vector<TopicInfo> topics_;
  std::map<std::string, std::string> formats_;
  std::vector<Entry> index_;
};

}  // namespace

std::unique_ptr<BagFile> open_ros2_sqlite_bag(const std::vector<std::filesystem::path>& files,
                                              const std::filesystem::path& name) {
  return std::make_unique<Ros2SqliteBag>(files, name);
}

}  // namespace scfloam
