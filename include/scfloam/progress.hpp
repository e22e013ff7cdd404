// A terminal progress bar for long steps. On a terminal it redraws one line; otherwise
// (CI logs, pipes) it prints a line every 10 % so logs stay short.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace scfloam {

class ProgressBar {
 public:
  ProgressBar(std::string label, std::size_t total, bool enabled = true);
  ~ProgressBar();
  // Sets the number of finished items; `note` is shown after the counter (e.g. "12.3 ms/frame").
  void update(std::size_t done, const std::string& note = "");
  void finish(const std::string& note = "");

 private:
  std::string label_;
  std::size_t total_;
  bool enabled_, tty_, finished_ = false;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace scfloam
