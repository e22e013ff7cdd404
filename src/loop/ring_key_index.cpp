#include "scfloam/loop/ring_key_index.hpp"

#include <algorithm>
#include <cmath>
#include <nanoflann.hpp>
#include <string>

#include "scfloam/error.hpp"

namespace scfloam {

// nanoflann reads the keys through this adaptor; `count` freezes the indexed prefix while the
// key store keeps growing (the tree only holds indices, never pointers into the vector).
struct RingKeyIndex::Tree {
  struct Keys {
    const std::vector<float>* keys = nullptr;
    std::size_t key_size = 0, count = 0;
    std::size_t kdtree_get_point_count() const { return count; }
    float kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*keys)[i * key_size + dim]; }
    template <class BBox>
    bool kdtree_get_bbox(BBox&) const { return false; }
  };
  using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Keys>,
                                                     Keys, -1, std::uint32_t>;
  Keys keys;
  std::unique_ptr<KdTree> index;
};

RingKeyIndex::RingKeyIndex(int key_size, int rebuild_every)
    : key_size_(key_size), rebuild_every_(rebuild_every), tree_(std::make_unique<Tree>()) {
  if (key_size < 1 || rebuild_every < 1)
    throw Error("ring key index: key size and rebuild interval must be >= 1 (got " +
                std::to_string(key_size) + ", " + std::to_string(rebuild_every) + ")");
  tree_->keys.keys = &keys_;
  tree_->keys.key_size = static_cast<std::size_t>(key_size);
}

RingKeyIndex::~RingKeyIndex() = default;

std::size_t RingKeyIndex::tree_size() const { return tree_->index ? tree_->keys.count : 0; }

void RingKeyIndex::add(const Eigen::VectorXf& ring_key) {
  if (ring_key.size() != key_size_)
    throw Error("ring key index: key of size " + std::to_string(ring_key.size()) + ", expected " +
                std::to_string(key_size_));
  keys_.insert(keys_.end(), ring_key.data(), ring_key.data() + key_size_);
  ++count_;
}

void RingKeyIndex::rebuild(std::size_t eligible) {
  tree_->keys.count = eligible;
  tree_->index = std::make_unique<Tree::KdTree>(key_size_, tree_->keys,
                                                nanoflann::KDTreeSingleIndexAdaptorParams(10));
}

std::vector<RingKeyNeighbour> RingKeyIndex::nearest(const Eigen::VectorXf& query, int k,
                                                    std::size_t eligible) {
  eligible = std::min(eligible, count_);
  if (k < 1 || eligible == 0) return {};
  if (query.size() != key_size_)
    throw Error("ring key index: query of size " + std::to_string(query.size()) + ", expected " +
                std::to_string(key_size_));
  if (eligible < tree_size() || eligible - tree_size() >= static_cast<std::size_t>(rebuild_every_))
    rebuild(eligible);

  std::vector<RingKeyNeighbour> found;
  const std::size_t indexed = tree_size();
  if (indexed > 0) {
    const std::size_t want = std::min<std::size_t>(k, indexed);
    std::vector<std::uint32_t> ids(want);
    std::vector<float> dist_sq(want);
    const std::size_t got = tree_->index->knnSearch(query.data(), want, ids.data(), dist_sq.data());
    for (std::size_t i = 0; i < got; ++i)
      found.push_back({static_cast<int>(ids[i]), std::sqrt(dist_sq[i])});
  }
  // Keys added since the last rebuild: few, compared directly.
  for (std::size_t i = indexed; i < eligible; ++i) {
    const Eigen::Map<const Eigen::VectorXf> key(&keys_[i * key_size_], key_size_);
    found.push_back({static_cast<int>(i), (key - query).norm()});
  }
  std::sort(found.begin(), found.end(), [](const RingKeyNeighbour& a, const RingKeyNeighbour& b) {
    return a.distance != b.distance ? a.distance < b.distance : a.keyframe < b.keyframe;
  });
  if (found.size() > static_cast<std::size_t>(k)) found.resize(k);
  return found;
}

}  // namespace scfloam
