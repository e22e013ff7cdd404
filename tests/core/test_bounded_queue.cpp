// BoundedQueue between threads: order, the capacity bound, close() waking both sides.
// Also run under ThreadSanitizer by scripts/tsan.sh.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "scfloam/bounded_queue.hpp"

namespace scfloam {
namespace {

TEST(BoundedQueue, OneProducerOneConsumerKeepsOrderAndBound) {
  BoundedQueue<int> queue(4);
  std::atomic<std::size_t> max_size{0};
  std::thread producer([&] {
    for (int i = 0; i < 5000; ++i) ASSERT_TRUE(queue.push(i));
    queue.close();
  });
  std::vector<int> got;
  while (auto item = queue.pop()) {
    got.push_back(*item);
    const std::size_t s = queue.size();
    if (s > max_size) max_size = s;
  }
  producer.join();
  ASSERT_EQ(got.size(), 5000u);
  for (int i = 0; i < 5000; ++i) ASSERT_EQ(got[i], i);
  EXPECT_LE(max_size.load(), 4u);
}

TEST(BoundedQueue, ManyProducersManyConsumersLoseNothing) {
  BoundedQueue<int> queue(3);
  std::atomic<long> sum{0};
  std::atomic<int> count{0};
  std::vector<std::thread> producers, consumers;
  for (int p = 0; p < 3; ++p)
    producers.emplace_back([&, p] {
      for (int i = 1; i <= 1000; ++i) queue.push(p * 1000 + i);
    });
  for (int c = 0; c < 3; ++c)
    consumers.emplace_back([&] {
      while (auto item = queue.pop()) {
        sum += *item;
        ++count;
      }
    });
  for (auto& t : producers) t.join();
  queue.close();
  for (auto& t : consumers) t.join();
  EXPECT_EQ(count.load(), 3000);
  long expected = 0;
  for (int p = 0; p < 3; ++p)
    for (int i = 1; i <= 1000; ++i) expected += p * 1000 + i;
  EXPECT_EQ(sum.load(), expected);
}

TEST(BoundedQueue, CloseWakesABlockedProducerAndDrainsForTheConsumer) {
  BoundedQueue<int> queue(1);
  ASSERT_TRUE(queue.push(1));
  std::atomic<bool> second_push_result{true};
  std::thread producer([&] { second_push_result = queue.push(2); });  // blocks: full
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  queue.close();
  producer.join();
  EXPECT_FALSE(second_push_result.load());  // dropped once closed
  auto first = queue.pop();
  ASSERT_TRUE(first.has_value());  // what was queued before close() is still delivered
  EXPECT_EQ(*first, 1);
  EXPECT_FALSE(queue.pop().has_value());
}

}  // namespace
}  // namespace scfloam
