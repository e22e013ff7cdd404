#include "pipeline/keyframe_store.hpp"

#include <unistd.h>

#include "scfloam/error.hpp"
#include "scfloam/se3.hpp"

namespace scfloam {
namespace {

std::filesystem::path spill_file_path(std::filesystem::path dir) {
  static std::atomic<int> counter{0};
  if (dir.empty()) dir = std::filesystem::temp_directory_path();
  return dir / ("scfloam-keyframes-" + std::to_string(::getpid()) + "-" +
                std::to_string(counter++) + ".bin");
}

void write_cloud(std::ostream& out, const FeatureCloud& cloud) {
  out.write(reinterpret_cast<const char*>(cloud.data()),
            static_cast<std::streamsize>(cloud.size() * sizeof(cloud[0])));
}

void read_cloud(std::istream& in, std::size_t count, FeatureCloud& cloud) {
  cloud.resize(count);
  in.read(reinterpret_cast<char*>(cloud.data()),
          static_cast<std::streamsize>(count * sizeof(cloud[0])));
}

}  // namespace

KeyframeStore::KeyframeStore(std::size_t resident_limit, std::filesystem::path spill_dir)
    : resident_limit_(resident_limit),
      spill_path_(resident_limit ? spill_file_path(std::move(spill_dir)) : std::filesystem::path{}) {}

KeyframeStore::~KeyframeStore() {
  if (spill_.is_open()) spill_.close();
  std::error_code ignored;
  if (!spill_path_.empty()) std::filesystem::remove(spill_path_, ignored);
}

void KeyframeStore::add(KeyframePtr keyframe) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (keyframe->index != entries_.size())
    throw Error("internal: keyframe " + std::to_string(keyframe->index) + " out of order");
  poses_.push_back(poses_.empty() ? Eigen::Isometry3d::Identity()
                                  : orthonormalized(poses_.back() * keyframe->T_prev_current));
  Entry entry;
  entry.frame = keyframe->frame;
  entry.T_prev_current = keyframe->T_prev_current;
  entry.edges = keyframe->edges.size();
  entry.planes = keyframe->planes.size();
  entry.raw = keyframe->raw.size();
  entry.resident = std::move(keyframe);
  entry.lru = lru_.insert(lru_.end(), entries_.size());
  entries_.push_back(std::move(entry));
  spill_excess();
}

void KeyframeStore::set_optimized(const PoseList& poses) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::size_t m = std::min(poses.size(), poses_.size());
    for (std::size_t i = 0; i < m; ++i) poses_[i] = poses[i];
    for (std::size_t i = std::max<std::size_t>(m, 1); i < poses_.size(); ++i)
      poses_[i] = orthonormalized(poses_[i - 1] * entries_[i].T_prev_current);
  }
  ++version_;
}

std::size_t KeyframeStore::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return entries_.size();
}

KeyframePtr KeyframeStore::get(std::size_t index) const {
  std::lock_guard<std::mutex> lock(mutex_);
  Entry& entry = entries_.at(index);
  if (entry.resident) {
    touch(entry, index);
    return entry.resident;
  }
  entry.resident = read_clouds(index, entry);
  ++reloads_;
  entry.lru = lru_.insert(lru_.end(), index);
  KeyframePtr kf = entry.resident;
  spill_excess();
  return kf;
}

PoseList KeyframeStore::current_poses() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return poses_;
}

Eigen::Isometry3d KeyframeStore::current_pose(std::size_t index) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return poses_.at(index);
}

KeyframeStore::Hold::Hold(const KeyframeStore& store) : store_(store) {
  std::lock_guard<std::mutex> lock(store_.mutex_);
  ++store_.holds_;
}

KeyframeStore::Hold::~Hold() {
  std::lock_guard<std::mutex> lock(store_.mutex_);
  --store_.holds_;
  try {
    store_.spill_excess();
  } catch (...) {
    // A spill that fails here is retried by the next add() or get(), which reports it.
  }
}

KeyframeStorageStats KeyframeStore::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  KeyframeStorageStats s;
  s.keyframes = entries_.size();
  s.resident = lru_.size();
  s.resident_limit = resident_limit_;
  s.spill_bytes = static_cast<std::size_t>(spill_end_);
  s.reloads = reloads_;
  for (const Entry& e : entries_) {
    s.edge_points += e.edges;
    s.plane_points += e.planes;
    s.raw_points += e.raw;
    s.spilled += e.file_offset >= 0;
  }
  return s;
}

void KeyframeStore::touch(Entry& entry, std::size_t index) const {
  lru_.erase(entry.lru);
  entry.lru = lru_.insert(lru_.end(), index);
}

void KeyframeStore::spill_excess() const {
  if (resident_limit_ == 0 || holds_ > 0) return;
  while (lru_.size() > resident_limit_) {
    Entry& entry = entries_[lru_.front()];
    if (entry.file_offset < 0) write_clouds(entry);
    // Whoever still holds the pointer keeps the clouds alive; the store lets go of them.
    entry.resident.reset();
    lru_.pop_front();
  }
}

void KeyframeStore::write_clouds(Entry& entry) const {
  if (!spill_.is_open()) {
    spill_.open(spill_path_, std::ios::binary | std::ios::in | std::ios::out | std::ios::trunc);
    if (!spill_) throw file_error(spill_path_, "cannot create the keyframe spill file");
  }
  spill_.seekp(spill_end_);
  write_cloud(spill_, entry.resident->edges);
  write_cloud(spill_, entry.resident->planes);
  write_cloud(spill_, entry.resident->raw);
  if (!spill_) throw file_error(spill_path_, "cannot write the keyframe spill file (disk full?)");
  entry.file_offset = spill_end_;
  spill_end_ += static_cast<std::int64_t>((entry.edges + entry.planes + entry.raw) *
                                          sizeof(Eigen::Vector3f));
}

KeyframePtr KeyframeStore::read_clouds(std::size_t index, const Entry& entry) const {
  auto kf = std::make_shared<Keyframe>();
  kf->index = index;
  kf->frame = entry.frame;
  kf->T_prev_current = entry.T_prev_current;
  spill_.flush();
  spill_.seekg(entry.file_offset);
  read_cloud(spill_, entry.edges, kf->edges);
  read_cloud(spill_, entry.planes, kf->planes);
  read_cloud(spill_, entry.raw, kf->raw);
  if (!spill_) throw file_error(spill_path_, "cannot read back keyframe " + std::to_string(index));
  return kf;
}

}  // namespace scfloam
