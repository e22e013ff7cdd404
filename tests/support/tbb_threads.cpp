// Linked into every test program: SCFLOAM_TBB_THREADS=N caps TBB at N threads for the whole
// run. scripts/tsan.sh sets 1, so that ThreadSanitizer watches only our own threads and queues:
// Debian's libtbb is not instrumented, and every hand-off to a TBB worker otherwise costs a
// (suppressed, but still processed) report.
#include <tbb/global_control.h>

#include <cstdlib>
#include <memory>
#include <string>

namespace {

std::unique_ptr<tbb::global_control> cap_from_environment() {
  const char* value = std::getenv("SCFLOAM_TBB_THREADS");
  if (!value || !*value) return nullptr;
  const int threads = std::atoi(value);
  if (threads < 1) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               static_cast<std::size_t>(threads));
}

const std::unique_ptr<tbb::global_control> tbb_cap = cap_from_environment();

}  // namespace
