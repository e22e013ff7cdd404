#include "scfloam/loop/ring_key_index.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <nanoflann.hpp>
#include <string>

#include "scfloam/error.hpp"

namespace scfloam {

// A k-d tree over its own snapshot of the first `count` keys: the live key store may grow
// (and reallocate) while a background thread builds or a query reads this tree.
struct RingKeyIndex::Tree {
  struct Keys {
    std::vector<float> data;
    std::size_t key_size = 0;
    std::size_t kdtree_get_point_count() const { return data.size() / key_size; }
    float kdtree_get_pt(std::size_t i, std::size_t dim) const { return data[i * key_size + dim]; }
    template <class BBox>
    bool kdtree_get_bbox(BBox&) const { return false; }
  };
  using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Keys>,
                                                     Keys, -1, std::uint32_t>;
  Keys keys;
  std::unique_ptr<KdTree> index;
  std::size_t count() const { return keys.kdtree_get_point_count(); }
};

RingKeyIndex::RingKeyIndex(int key_size, int rebuild_every, bool async_rebuild)
    : key_size_(key_size), rebuild_every_(rebuild_every), async_rebuild_(async_rebuild) {
  if (key_size < 1 || rebuild_every < 1)
    throw Error("ring key index: key size and rebuild interval must be >= 1 (got " +
                std::to_string(key_size) + ", " + std::to_string(rebuild_every) + ")");
}

RingKeyIndex::~RingKeyIndex() = default;  // a pending future waits for its thread
RingKeyIndex::RingKeyIndex(RingKeyIndex&&) noexcept = default;
RingKeyIndex& RingKeyIndex::operator=(RingKeyIndex&&) noexcept = default;

std::size_t RingKeyIndex::tree_size() const { return tree_ ? tree_->count() : 0; }

void RingKeyIndex::add(const Eigen::VectorXf& ring_key) {
  if (ring_key.size() != key_size_)
    throw Error("ring key index: key of size " + std::to_string(ring_key.size()) + ", expected " +
                std::to_string(key_size_));
  keys_.insert(keys_.end(), ring_key.data(), ring_key.data() + key_size_);
}

std::shared_ptr<const RingKeyIndex::Tree> RingKeyIndex::build(std::vector<float> keys, int key_size) {
  auto tree = std::make_shared<Tree>();
  tree->keys.data = std::move(keys);
  tree->keys.key_size = static_cast<std::size_t>(key_size);
  tree->index = std::make_unique<Tree::KdTree>(key_size, tree->keys,
                                               nanoflann::KDTreeSingleIndexAdaptorParams(10));
  return tree;
}

void RingKeyIndex::wait_for_rebuild() {
  if (pending_.valid()) tree_ = pending_.get();
}

void RingKeyIndex::maybe_rebuild(std::size_t eligible) {
  if (pending_.valid() &&
      pending_.wait_for(std::chrono::seconds(0)) == std::future_status::ready)
    tree_ = pending_.get();
  auto snapshot = [&](std::size_t count) {
    return std::vector<float>(keys_.begin(), keys_.begin() + count * key_size_);
  };
  if (eligible < tree_size()) {  // the eligible prefix shrank (not in normal use)
    if (pending_.valid()) pending_.get();  // discarded: it may cover newer keys too
    tree_ = build(snapshot(eligible), key_size_);
    return;
  }
  if (pending_.valid() || eligible - tree_size() < static_cast<std::size_t>(rebuild_every_)) return;
  if (async_rebuild_)
    pending_ = std::async(std::launch::async, &RingKeyIndex::build, snapshot(eligible), key_size_);
  else
    tree_ = build(snapshot(eligible), key_size_);
}

float RingKeyIndex::key_distance(std::size_t keyframe, const Eigen::VectorXf& query) const {
  const Eigen::Map<const Eigen::VectorXf> key(&keys_[keyframe * key_size_], key_size_);
  return (key - query).norm();
}

std::vector<RingKeyNeighbour> RingKeyIndex::nearest(const Eigen::VectorXf& query, int k,
                                                    std::size_t eligible) {
  eligible = std::min(eligible, size());
  if (k < 1 || eligible == 0) return {};
  if (query.size() != key_size_)
    throw Error("ring key index: query of size " + std::to_string(query.size()) + ", expected " +
                std::to_string(key_size_));
  maybe_rebuild(eligible);

  // Distances are recomputed one way for tree hits and tail alike, and the tree is asked for
  // 2k, so that rounding in its own distances cannot change the k kept: the answer does not
  // depend on which keys happen to be in the tree (the background rebuild's timing).
  std::vector<RingKeyNeighbour> found;
  const std::size_t indexed = tree_size();
  if (indexed > 0) {
    const std::size_t want = std::min<std::size_t>(2 * static_cast<std::size_t>(k), indexed);
    std::vector<std::uint32_t> ids(want);
    std::vector<float> dist_sq(want);
    const std::size_t got = tree_->index->knnSearch(query.data(), want, ids.data(), dist_sq.data());
    for (std::size_t i = 0; i < got; ++i)
      found.push_back({static_cast<int>(ids[i]), key_distance(ids[i], query)});
  }
  for (std::size_t i = indexed; i < eligible; ++i)
    found.push_back({static_cast<int>(i), key_distance(i, query)});
  std::sort(found.begin(), found.end(), [](const RingKeyNeighbour& a, const RingKeyNeighbour& b) {
    return a.distance != b.distance ? a.distance < b.distance : a.keyframe < b.keyframe;
  });
  if (found.size() > static_cast<std::size_t>(k)) found.resize(k);
  return found;
}

}  // namespace scfloam
