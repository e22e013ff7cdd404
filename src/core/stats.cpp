#include "scfloam/stats.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <string>

namespace scfloam {

TimingStats summarize(std::vector<double> samples) {
  TimingStats s;
  s.count = samples.size();
  if (samples.empty()) return s;
  std::sort(samples.begin(), samples.end());
  const std::size_t n = samples.size();
  s.median = n % 2 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
  s.mean = std::accumulate(samples.begin(), samples.end(), 0.0) / n;
  // Nearest-rank percentile: the smallest sample with at least 95 % of samples at or below it.
  const std::size_t rank = static_cast<std::size_t>(std::ceil(0.95 * n));
  s.p95 = samples[std::max<std::size_t>(rank, 1) - 1];
  return s;
}

double peak_rss_mb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
  }
  return 0;
}

}  // namespace scfloam
