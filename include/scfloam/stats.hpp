// Timing statistics as summary.json reports them: {"median", "mean", "p95", "count"}.
#pragma once

#include <chrono>
#include <cstddef>
#include <vector>

namespace scfloam {

struct TimingStats {
  double median = 0, mean = 0, p95 = 0;
  std::size_t count = 0;
};

// Order statistics of the samples (any unit); empty input gives all zeros.
TimingStats summarize(std::vector<double> samples);

// Wall-clock stopwatch in milliseconds.
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  void restart() { start_ = std::chrono::steady_clock::now(); }
  double elapsed_ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
        .count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

// Peak resident set size of this process in MB (from /proc/self/status VmHWM), 0 if unknown.
double peak_rss_mb();

}  // namespace scfloam
