// Nearest ring keys among the older keyframes. A nanoflann k-d tree covers a prefix of the
// database and is rebuilt once `rebuild_every` eligible keyframes lie outside it; those few are
// compared by brute force, so every query returns the exact k nearest of the eligible prefix
// whatever the rebuild schedule, and no single query pays for more than one small rebuild.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

namespace scfloam {

struct RingKeyNeighbour {
  int keyframe = -1;
  float distance = 0.0f;  // L2 distance between ring keys
};

class RingKeyIndex {
 public:
  RingKeyIndex(int key_size, int rebuild_every);
  ~RingKeyIndex();
  RingKeyIndex(const RingKeyIndex&) = delete;
  RingKeyIndex& operator=(const RingKeyIndex&) = delete;

  // Stores the key of keyframe size().
  void add(const Eigen::VectorXf& ring_key);
  std::size_t size() const { return count_; }
  std::size_t tree_size() const;

  // The k nearest keys among keyframes [0, eligible), closest first (ties: lower index first).
  std::vector<RingKeyNeighbour> nearest(const Eigen::VectorXf& query, int k, std::size_t eligible);

 private:
  struct Tree;
  void rebuild(std::size_t eligible);
  int key_size_, rebuild_every_;
  std::size_t count_ = 0;
  std::vector<float> keys_;  // count_ x key_size_, row after row
  std::unique_ptr<Tree> tree_;
};

}  // namespace scfloam
