#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "scfloam/error.hpp"
#include "scfloam/loop/ring_key_index.hpp"

namespace scfloam {
namespace {

// Brute-force reference: the k nearest of the first `eligible` keys.
std::vector<int> brute_force(const std::vector<Eigen::VectorXf>& keys, const Eigen::VectorXf& q,
                             int k, std::size_t eligible) {
  std::vector<int> ids(eligible);
  for (std::size_t i = 0; i < eligible; ++i) ids[i] = static_cast<int>(i);
  std::sort(ids.begin(), ids.end(), [&](int a, int b) {
    const float da = (keys[a] - q).norm(), db = (keys[b] - q).norm();
    return da != db ? da < db : a < b;
  });
  ids.resize(std::min<std::size_t>(k, ids.size()));
  return ids;
}

void check_against_brute_force(bool async_rebuild) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 5.0f);
  RingKeyIndex index(20, 7, async_rebuild);
  std::vector<Eigen::VectorXf> keys;
  for (int n = 0; n < 300; ++n) {
    Eigen::VectorXf key(20);
    for (int d = 0; d < 20; ++d) key[d] = u(rng);
    keys.push_back(key);
    index.add(key);
    const std::size_t eligible = n > 50 ? n - 50 : 0;
    Eigen::VectorXf q(20);
    for (int d = 0; d < 20; ++d) q[d] = u(rng);
    std::vector<int> got;
    for (const auto& nb : index.nearest(q, 10, eligible)) got.push_back(nb.keyframe);
    ASSERT_EQ(got, brute_force(keys, q, 10, eligible)) << "database of " << n + 1;
    // A synchronous tree never lags more than one rebuild interval behind.
    if (!async_rebuild) {
      ASSERT_LT(eligible - std::min(eligible, index.tree_size()), 7u);
    }
  }
  // The trees did get built. A background rebuild is skipped while one is still running, so
  // under load the tree may lag: one more query once the last rebuild is in must catch up.
  index.wait_for_rebuild();
  Eigen::VectorXf q = Eigen::VectorXf::Zero(20);
  index.nearest(q, 10, 249);
  index.wait_for_rebuild();
  EXPECT_GT(index.tree_size(), 249u - 7u);
}

TEST(RingKeyIndex, MatchesBruteForceWhileGrowingAcrossRebuilds) { check_against_brute_force(false); }
TEST(RingKeyIndex, BackgroundRebuildsGiveTheSameAnswers) { check_against_brute_force(true); }

TEST(RingKeyIndex, NeverReturnsKeyframesOutsideTheEligiblePrefix) {
  RingKeyIndex index(2, 50);
  for (int i = 0; i < 100; ++i) index.add(Eigen::Vector2f(static_cast<float>(i), 0.0f));
  const auto found = index.nearest(Eigen::Vector2f(99.0f, 0.0f), 5, 40);
  ASSERT_EQ(found.size(), 5u);
  EXPECT_EQ(found[0].keyframe, 39);
  EXPECT_FLOAT_EQ(found[0].distance, 60.0f);
  for (const auto& nb : found) EXPECT_LT(nb.keyframe, 40);
  EXPECT_TRUE(index.nearest(Eigen::Vector2f(0.0f, 0.0f), 5, 0).empty());
}

TEST(RingKeyIndex, RejectsKeysOfTheWrongSize) {
  RingKeyIndex index(20, 50);
  EXPECT_THROW(index.add(Eigen::VectorXf::Zero(19)), Error);
  index.add(Eigen::VectorXf::Zero(20));
  EXPECT_THROW(index.nearest(Eigen::VectorXf::Zero(3), 1, 1), Error);
}

}  // namespace
}  // namespace scfloam
