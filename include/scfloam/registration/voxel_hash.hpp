// Integer voxel keys and a flat open-addressing key -> index table: the hot lookups of the
// voxel filter and the local map (std::unordered_map costs several times more per lookup).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

namespace scfloam {

// 21 bits per axis (+-1e6 voxels), packed into one 64-bit key.
inline std::uint64_t voxel_key(int ix, int iy, int iz) {
  constexpr std::uint64_t mask = (1u << 21) - 1;
  return ((static_cast<std::uint64_t>(ix) & mask) << 42) |
         ((static_cast<std::uint64_t>(iy) & mask) << 21) | (static_cast<std::uint64_t>(iz) & mask);
}

// floor() for |x| < 2^31, without the libm call that portable (pre-SSE4.1) x86-64 code makes.
inline int floor_to_int(float x) {
  const int i = static_cast<int>(x);  // truncates toward zero
  return i - (x < static_cast<float>(i));
}

inline Eigen::Vector3i voxel_coords(const Eigen::Vector3f& p, float inv_size) {
  return Eigen::Vector3i(floor_to_int(p.x() * inv_size), floor_to_int(p.y() * inv_size),
                         floor_to_int(p.z() * inv_size));
}

// key -> uint32 index; linear probing, power-of-two capacity, no erase (callers rebuild).
class FlatKeyIndex {
 public:
  static constexpr std::uint32_t kNone = 0xffffffffu;

  // The load past which the table grows: half (the default, short probes) or three quarters
  // (a third fewer slots for tables of millions of keys built once, such as map.pcd's). An
  // enum, not a number: 0 would make reset() loop forever, and at a full load find() of a
  // missing key would probe forever (insert() too, past it).
  enum class MaxLoad : unsigned { kHalf = 2, kThreeQuarters = 3 };
  explicit FlatKeyIndex(MaxLoad max_load = MaxLoad::kHalf)
      : max_load_quarters_(static_cast<unsigned>(max_load)) {}

  // Empties the table keeping capacity for at least `expected` keys at the maximum load.
  void reset(std::size_t expected) {
    std::size_t cap = 16;
    while (cap * max_load_quarters_ < 4 * expected) cap <<= 1;
    if (slots_.size() != cap) slots_.assign(cap, Slot{});
    else std::fill(slots_.begin(), slots_.end(), Slot{});
    size_ = 0;
  }

  std::uint32_t find(std::uint64_t key) const {
    if (slots_.empty()) return kNone;
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = hash(key) & mask;; i = (i + 1) & mask) {
      const Slot& s = slots_[i];
      if (s.value == kNone) return kNone;
      if (s.key == key) return s.value;
    }
  }

  // Returns the existing index, or stores `value` for a new key and returns it.
  std::uint32_t insert(std::uint64_t key, std::uint32_t value) {
    if (4 * (size_ + 1) > slots_.size() * max_load_quarters_) grow();
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = hash(key) & mask;; i = (i + 1) & mask) {
      Slot& s = slots_[i];
      if (s.value == kNone) {
        s.key = key;
        s.value = value;
        ++size_;
        return value;
      }
      if (s.key == key) return s.value;
    }
  }

  std::size_t size() const { return size_; }

 private:
  struct Slot {
    std::uint64_t key = 0;
    std::uint32_t value = kNone;
  };

  static std::size_t hash(std::uint64_t k) {  // splitmix64 finalizer
    k ^= k >> 30;
    k *= 0xbf58476d1ce4e5b9ull;
    k ^= k >> 27;
    k *= 0x94d049bb133111ebull;
    k ^= k >> 31;
    return static_cast<std::size_t>(k);
  }

  void grow() {
    std::vector<Slot> old;
    old.swap(slots_);
    slots_.assign(old.empty() ? 16 : old.size() * 2, Slot{});
    size_ = 0;
    for (const Slot& s : old)
      if (s.value != kNone) insert(s.key, s.value);
  }

  std::vector<Slot> slots_;
  std::size_t size_ = 0;
  unsigned max_load_quarters_ = 2;
};

}  // namespace scfloam
