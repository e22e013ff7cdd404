#include "scfloam/thread_priority.hpp"

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#endif

namespace scfloam {

#if defined(__linux__)
namespace {
id_t this_thread_id() { return static_cast<id_t>(syscall(SYS_gettid)); }
}  // namespace

int current_thread_nice() {
  errno = 0;
  const int nice = getpriority(PRIO_PROCESS, this_thread_id());
  return errno == 0 ? nice : 0;
}

bool lower_current_thread_priority(int increment) {
  if (increment <= 0) return increment == 0;
  const int target = current_thread_nice() + increment;
  return setpriority(PRIO_PROCESS, this_thread_id(), target > 19 ? 19 : target) == 0;
}
#else
int current_thread_nice() { return 0; }
bool lower_current_thread_priority(int increment) { return increment == 0; }
#endif

}  // namespace scfloam
