// Scans from a folder of .pcd, .ply or .bin files (one scan a file), or from a single file.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "scfloam/io/input_info.hpp"
#include "scfloam/io/scan_source.hpp"

namespace scfloam {

// Natural order: digit runs compare as numbers, so scan2 sorts before scan10.
bool natural_less(const std::string& a, const std::string& b);

// The scan files of a folder in natural order, with the kind ("PCD folder", "PLY folder",
// "KITTI .bin folder"). Error when the folder holds none or mixes kinds.
struct ScanFileList {
  std::vector<std::filesystem::path> files;
  std::string kind;
};
ScanFileList list_scan_folder(const std::filesystem::path& dir);
// A single .pcd/.ply/.bin file as a one-scan list ("PCD file", ...).
ScanFileList single_scan_file(const std::filesystem::path& file);
// True for the extensions a scan file may have (.pcd, .ply, .bin; any case).
bool is_scan_file_extension(const std::filesystem::path& path);

// Stamps, in order of preference: options.timestamps_file (one a line, count must match),
// file names that are stamps (seconds >= 1e8, or nanoseconds >= 1e17), the scans' own stamps
// (clouds with absolute per-point times), else 0.1 s apart from 0.
std::unique_ptr<ScanSource> open_file_list_source(ScanFileList list, const ScanSourceOptions& options);
InputInfo inspect_file_list(const ScanFileList& list, const ScanSourceOptions& options);

}  // namespace scfloam
