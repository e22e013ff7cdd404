// The one exception type for bad input: its message names the file and the problem.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

namespace scfloam {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "path: problem", the form every reader uses.
inline Error file_error(const std::filesystem::path& path, const std::string& problem) {
  return Error(path.string() + ": " + problem);
}

}  // namespace scfloam
