// Outputs are written to a temporary file beside the target and renamed into place, so a
// reader never sees half a file and an interrupted run never destroys an earlier result.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <string_view>

namespace scfloam {

// Calls `write` with a stream on "<path>.tmp-<pid>", checks the stream, then renames.
// Throws scfloam::Error naming `path` on any failure (and removes the temporary file).
void write_file_atomic(const std::filesystem::path& path,
                       const std::function<void(std::ostream&)>& write);
void write_file_atomic(const std::filesystem::path& path, std::string_view bytes);

}  // namespace scfloam
