// `scfloam info`: what an input holds, found without running anything.
#pragma once

#include <filesystem>
#include <string>

#include "scfloam/io/input_info.hpp"
#include "scfloam/io/scan_source.hpp"

namespace scfloam {

// Dispatches like open_scan_source (KITTI, folders, single files; bags -> inspect_bag) and
// reads the first scan. Error naming the file and the problem when the input cannot be read.
InputInfo inspect_input(const std::filesystem::path& path, const ScanSourceOptions& options = {});

// The same report as text lines (for humans) and as one JSON object (for scripts).
std::string input_info_text(const InputInfo& info);
std::string input_info_json(const InputInfo& info);

}  // namespace scfloam
