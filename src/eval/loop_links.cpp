#include <fstream>
#include <unordered_map>

#include "scfloam/error.hpp"
#include "scfloam/eval/eval_plots.hpp"

namespace scfloam {
namespace {

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  for (char c : line) {
    if (c == ',') {
      cells.push_back(cell);
      cell.clear();
    } else if (c != '\r' && c != '"') {
      cell += c;
    }
  }
  cells.push_back(cell);
  for (auto& s : cells) {  // trim spaces
    const auto a = s.find_first_not_of(' '), b = s.find_last_not_of(' ');
    s = a == std::string::npos ? "" : s.substr(a, b - a + 1);
  }
  return cells;
}

std::size_t parse_frame(const std::string& cell, const std::filesystem::path& path,
                        std::size_t line_no) {
  std::size_t used = 0;
  long long v = -1;
  try {
    v = std::stoll(cell, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != cell.size() || cell.empty() || v < 0)
    throw file_error(path, "line " + std::to_string(line_no) + ": '" + cell +
                               "' is not a frame index");
  return static_cast<std::size_t>(v);
}

}  // namespace

std::vector<LoopLink> read_accepted_loops(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw file_error(path, "cannot open the loops file");
  std::string line;
  if (!std::getline(in, line)) throw file_error(path, "empty file (expected a CSV header)");
  const auto header = split_csv(line);
  auto column = [&](const std::string& name) {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return i;
    throw file_error(path, "header has no '" + name + "' column");
  };
  const std::size_t c_cur = column("current_frame"), c_loop = column("loop_frame"),
                    c_verdict = column("verdict");
  std::vector<LoopLink> loops;
  std::size_t line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \r") == std::string::npos) continue;
    const auto cells = split_csv(line);
    if (cells.size() < header.size())
      throw file_error(path, "line " + std::to_string(line_no) + ": " +
                                 std::to_string(cells.size()) + " columns, header has " +
                                 std::to_string(header.size()));
    if (cells[c_verdict] != "accepted") continue;
    loops.push_back({parse_frame(cells[c_cur], path, line_no), parse_frame(cells[c_loop], path, line_no)});
  }
  return loops;
}

std::vector<LoopLink> loops_to_pairs(const std::vector<LoopLink>& loops,
                                     const std::vector<std::size_t>& est_index) {
  std::unordered_map<std::size_t, std::size_t> pair_of_row;
  for (std::size_t k = 0; k < est_index.size(); ++k) pair_of_row[est_index[k]] = k;
  std::vector<LoopLink> out;
  for (const auto& l : loops) {
    const auto a = pair_of_row.find(l.current_frame), b = pair_of_row.find(l.loop_frame);
    if (a != pair_of_row.end() && b != pair_of_row.end()) out.push_back({a->second, b->second});
  }
  return out;
}

}  // namespace scfloam
