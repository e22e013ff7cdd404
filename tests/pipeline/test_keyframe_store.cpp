// The keyframe store's memory bound: clouds beyond the resident limit go to the spill file and
// come back bit-exact; nothing is spilled while a Hold exists; the file disappears with the store.
#include <gtest/gtest.h>

#include <random>
#include <thread>

#include "pipeline/keyframe_store.hpp"
#include "test_paths.hpp"

using namespace scfloam;
namespace fs = std::filesystem;

namespace {

std::shared_ptr<Keyframe> random_keyframe(std::size_t index, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-50.f, 50.f);
  auto kf = std::make_shared<Keyframe>();
  kf->index = index;
  kf->frame = 3 * index + 1;
  kf->T_prev_current.translation() = Eigen::Vector3d(2.0, 0.1 * index, 0);
  const auto fill = [&](FeatureCloud& cloud, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) cloud.emplace_back(u(rng), u(rng), u(rng));
  };
  fill(kf->edges, 50 + index);
  fill(kf->planes, 200 + 3 * index);
  fill(kf->raw, index % 3 == 0 ? 0 : 80);  // empty raw clouds too (optimized mode)
  return kf;
}

void expect_same(const Keyframe& a, const Keyframe& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.frame, b.frame);
  EXPECT_TRUE(a.T_prev_current.matrix() == b.T_prev_current.matrix());
  EXPECT_EQ(a.edges, b.edges);
  EXPECT_EQ(a.planes, b.planes);
  EXPECT_EQ(a.raw, b.raw);
}

std::size_t files_in(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}));
}

}  // namespace

TEST(KeyframeStore, SpilledCloudsComeBackExactlyAndTheResidentCountStaysBounded) {
  const fs::path dir = test::scratch_dir("keyframe_store_spill");
  std::mt19937 rng(7);
  std::vector<std::shared_ptr<Keyframe>> originals;
  {
    KeyframeStore store(3, dir);
    for (std::size_t i = 0; i < 20; ++i) {
      originals.push_back(random_keyframe(i, rng));
      store.add(std::make_shared<Keyframe>(*originals.back()));  // the store's own copy
      EXPECT_LE(store.stats().resident, 3u);
    }
    EXPECT_EQ(store.stats().spilled, 17u);
    EXPECT_EQ(files_in(dir), 1u);
    // Every keyframe, in an order that reloads spilled ones and re-spills reloaded ones.
    for (std::size_t round = 0; round < 2; ++round)
      for (std::size_t i : {0, 19, 5, 6, 0, 12, 18, 17, 1, 2, 3, 4, 7, 8, 9, 10, 11, 13, 14, 15, 16})
        expect_same(*store.get(i), *originals[i]);
    const KeyframeStorageStats s = store.stats();
    EXPECT_EQ(s.keyframes, 20u);
    EXPECT_LE(s.resident, 3u);
    EXPECT_EQ(s.spilled, 20u);  // each written once, however often it was reloaded
    EXPECT_GT(s.reloads, 20u);
    std::size_t points = 0;
    for (const auto& kf : originals) points += kf->edges.size() + kf->planes.size() + kf->raw.size();
    EXPECT_EQ(s.spill_bytes, points * sizeof(Eigen::Vector3f));
    // Poses chain through spilled keyframes as through resident ones.
    EXPECT_NEAR(store.current_pose(19).translation().x(), 2.0 * 19, 1e-9);
  }
  EXPECT_EQ(files_in(dir), 0u);  // the spill file went with the store
}

TEST(KeyframeStore, NothingIsSpilledWhileAHoldExists) {
  const fs::path dir = test::scratch_dir("keyframe_store_hold");
  std::mt19937 rng(8);
  KeyframeStore store(2, dir);
  {
    const KeyframeStore::Hold hold(store);
    for (std::size_t i = 0; i < 6; ++i) store.add(random_keyframe(i, rng));
    EXPECT_EQ(store.stats().resident, 6u);
    EXPECT_EQ(store.stats().spilled, 0u);
  }
  EXPECT_EQ(store.stats().resident, 2u);  // the excess went when the hold ended
  EXPECT_EQ(store.stats().spilled, 4u);
}

TEST(KeyframeStore, WithoutALimitEveryKeyframeStaysInMemory) {
  std::mt19937 rng(9);
  KeyframeStore store;
  std::vector<KeyframePtr> added;
  for (std::size_t i = 0; i < 30; ++i) {
    added.push_back(random_keyframe(i, rng));
    store.add(added.back());
  }
  for (std::size_t i = 0; i < 30; ++i) EXPECT_EQ(store.get(i), added[i]);  // the same objects
  EXPECT_EQ(store.stats().spilled, 0u);
  EXPECT_EQ(store.stats().resident, 30u);
}

TEST(KeyframeStore, ConcurrentReadersAndAWriterSeeExactClouds) {
  const fs::path dir = test::scratch_dir("keyframe_store_threads");
  std::mt19937 rng(10);
  std::vector<std::shared_ptr<Keyframe>> originals;
  for (std::size_t i = 0; i < 60; ++i) originals.push_back(random_keyframe(i, rng));
  KeyframeStore store(5, dir);
  for (std::size_t i = 0; i < 10; ++i) store.add(std::make_shared<Keyframe>(*originals[i]));
  std::atomic<bool> ok{true};
  std::thread reader([&] {
    std::mt19937 pick(11);
    for (int n = 0; n < 400; ++n) {
      const KeyframeStore::Hold hold(store);
      const std::size_t i = pick() % 10;  // the first ten exist from the start
      const KeyframePtr kf = store.get(i);
      if (kf->edges != originals[i]->edges || kf->planes != originals[i]->planes) ok = false;
    }
  });
  for (std::size_t i = 10; i < 60; ++i) {
    store.add(std::make_shared<Keyframe>(*originals[i]));
    const KeyframePtr kf = store.get(i / 2);
    if (kf->raw != originals[i / 2]->raw) ok = false;
  }
  reader.join();
  EXPECT_TRUE(ok.load());
  EXPECT_LE(store.stats().resident, 5u);
}
