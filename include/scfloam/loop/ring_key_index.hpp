// Nearest ring keys among the older keyframes. A nanoflann k-d tree covers a prefix of the
// database; keys added since are compared by brute force, so every query returns the exact k
// nearest of the eligible prefix whatever the rebuild schedule. Once `rebuild_every` eligible
// keys lie outside the tree, a new tree is built over a snapshot of the keys — on a
// background thread when `async_rebuild` is set, so that no query waits for a rebuild.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <future>
#include <memory>
#include <vector>

namespace scfloam {

struct RingKeyNeighbour {
  int keyframe = -1;
  float distance = 0.0f;  // L2 distance between ring keys
};

class RingKeyIndex {
 public:
  RingKeyIndex(int key_size, int rebuild_every, bool async_rebuild = false);
  ~RingKeyIndex();
  RingKeyIndex(RingKeyIndex&&) noexcept;
  RingKeyIndex& operator=(RingKeyIndex&&) noexcept;

  // Stores the key of keyframe size().
  void add(const Eigen::VectorXf& ring_key);
  std::size_t size() const { return keys_.size() / key_size_; }
  // Keys covered by the tree in use (a background rebuild may be under way).
  std::size_t tree_size() const;
  // Blocks until a background rebuild, if any, is done and in use (tests, shutdown).
  void wait_for_rebuild();

  // The k nearest keys among keyframes [0, eligible), closest first (ties: lower index first).
  std::vector<RingKeyNeighbour> nearest(const Eigen::VectorXf& query, int k, std::size_t eligible);

 private:
  struct Tree;
  static std::shared_ptr<const Tree> build(std::vector<float> keys, int key_size);
  void maybe_rebuild(std::size_t eligible);
  float key_distance(std::size_t keyframe, const Eigen::VectorXf& query) const;

  int key_size_, rebuild_every_;
  bool async_rebuild_;
  std::vector<float> keys_;  // size() x key_size_, row after row
  std::shared_ptr<const Tree> tree_;
  std::future<std::shared_ptr<const Tree>> pending_;
};

}  // namespace scfloam
