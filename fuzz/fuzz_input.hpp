// The readers take paths: each fuzz input is written to a per-process temporary file.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace scfloam::fuzz {

// "<tmp>/scfloam-fuzz-<stem>-<pid><suffix>" holding the input (the suffix matters to readers
// that look at extensions).
inline std::filesystem::path input_file(const std::uint8_t* data, std::size_t size,
                                        const std::string& stem, const std::string& suffix) {
  static const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const std::filesystem::path path =
      dir / ("scfloam-fuzz-" + stem + "-" + std::to_string(getpid()) + suffix);
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();  // the harness itself is broken: not a finding
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

}  // namespace scfloam::fuzz

// One fuzz target: the input as a file named with `suffix`, read by readers().at(name).
#define SCFLOAM_FUZZ_TARGET(name, suffix)                                             \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { \
    static const auto& read = scfloam::fuzz::readers().at(name);                     \
    read(scfloam::fuzz::input_file(data, size, name, suffix));                       \
    return 0;                                                                         \
  }
