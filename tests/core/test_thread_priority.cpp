#include <gtest/gtest.h>

#include <algorithm>
#include <thread>

#include "scfloam/thread_priority.hpp"

namespace scfloam {
namespace {

#if defined(__linux__)
// A background stage lowers only its own thread: the caller's priority is untouched.
TEST(ThreadPriority, LowersOnlyTheCallingThread) {
  const int main_before = current_thread_nice();
  int worker_before = 0, worker_after = 0;
  bool ok = false;
  std::thread worker([&] {
    worker_before = current_thread_nice();
    ok = lower_current_thread_priority(5);
    worker_after = current_thread_nice();
  });
  worker.join();
  ASSERT_TRUE(ok);
  EXPECT_EQ(worker_after, std::min(worker_before + 5, 19));
  EXPECT_EQ(current_thread_nice(), main_before);
}

TEST(ThreadPriority, ZeroIsANoOpAndTheCeilingIsNineteen) {
  std::thread worker([] {
    const int before = current_thread_nice();
    EXPECT_TRUE(lower_current_thread_priority(0));
    EXPECT_EQ(current_thread_nice(), before);
    EXPECT_TRUE(lower_current_thread_priority(100));
    EXPECT_EQ(current_thread_nice(), 19);
  });
  worker.join();
}
#endif

}  // namespace
}  // namespace scfloam
