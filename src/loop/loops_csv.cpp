#include "scfloam/loop/loops_csv.hpp"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "scfloam/atomic_file.hpp"
#include "scfloam/error.hpp"

namespace scfloam {
namespace {

const char* const kColumns[] = {"current_frame", "loop_frame",        "current_kf",
                                "loop_kf",       "sc_score",          "yaw_rad",
                                "distance_m",    "gate_m",            "verdict",
                                "ring_key_distance", "match_inlier_fraction", "match_residual_m"};
constexpr int kRequiredColumns = 9;

// NaN (not measured) is an empty cell.
void put_number(std::ostream& out, double value) {
  if (!std::isnan(value)) out << value;
}

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

double parse_double(const std::string& cell, const std::filesystem::path& path, std::size_t line) {
  if (cell.empty()) return std::nan("");
  try {
    std::size_t used = 0;
    const double v = std::stod(cell, &used);
    if (used == cell.size()) return v;
  } catch (const std::exception&) {
  }
  throw file_error(path, "line " + std::to_string(line) + ": '" + cell + "' is not a number");
}

}  // namespace

void write_loops_csv(const std::filesystem::path& path, const std::vector<LoopCandidate>& rows) {
  write_file_atomic(path, [&](std::ostream& out) {
    bool first = true;
    for (const char* name : kColumns) {
      out << (first ? "" : ",") << name;
      first = false;
    }
    out << '\n';
    out.precision(9);
    for (const LoopCandidate& c : rows) {
      out << c.current_frame << ',' << c.loop_frame << ',' << c.current_kf << ',' << c.loop_kf << ','
          << c.sc_score << ',' << c.yaw_rad << ',' << c.distance_m << ',' << c.gate_m << ','
          << to_string(c.verdict) << ',' << c.ring_key_distance << ',';
      put_number(out, c.match_inlier_fraction);
      out << ',';
      put_number(out, c.match_residual_m);
      out << '\n';
    }
  });
}

std::vector<LoopCandidate> read_loops_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw file_error(path, "cannot open");
  std::string line;
  if (!std::getline(in, line)) throw file_error(path, "empty file, expected a header line");
  std::map<std::string, std::size_t> column_of;
  const auto header = split_csv_line(line);
  for (std::size_t i = 0; i < header.size(); ++i) column_of[header[i]] = i;
  for (int i = 0; i < kRequiredColumns; ++i)
    if (!column_of.count(kColumns[i]))
      throw file_error(path, std::string("header lacks column '") + kColumns[i] + "'");

  std::vector<LoopCandidate> rows;
  for (std::size_t line_no = 2; std::getline(in, line); ++line_no) {
    if (line.empty()) continue;
    const auto cells = split_csv_line(line);
    if (cells.size() != header.size())
      throw file_error(path, "line " + std::to_string(line_no) + ": " + std::to_string(cells.size()) +
                                 " cells, header has " + std::to_string(header.size()));
    auto number = [&](const char* name, double fallback) {
      const auto it = column_of.find(name);
      return it == column_of.end() ? fallback : parse_double(cells[it->second], path, line_no);
    };
    LoopCandidate c;
    c.current_frame = static_cast<std::int64_t>(number("current_frame", -1));
    c.loop_frame = static_cast<std::int64_t>(number("loop_frame", -1));
    c.current_kf = static_cast<int>(number("current_kf", -1));
    c.loop_kf = static_cast<int>(number("loop_kf", -1));
    c.sc_score = number("sc_score", 1.0);
    c.yaw_rad = number("yaw_rad", 0.0);
    c.distance_m = number("distance_m", 0.0);
    c.gate_m = number("gate_m", 0.0);
    c.ring_key_distance = number("ring_key_distance", 0.0);
    c.match_inlier_fraction = number("match_inlier_fraction", std::nan(""));
    c.match_residual_m = number("match_residual_m", std::nan(""));
    try {
      c.verdict = parse_loop_verdict(cells[column_of["verdict"]]);
    } catch (const Error& e) {
      throw file_error(path, "line " + std::to_string(line_no) + ": " + e.what());
    }
    rows.push_back(c);
  }
  return rows;
}

std::optional<std::size_t> LoopLog::add(const LoopQuery& query) {
  std::optional<std::size_t> best_row;
  for (const LoopCandidate& c : rows_to_log(query)) {
    if (query.best && c.loop_kf == query.best->loop_kf && c.verdict == LoopVerdict::kAccepted)
      best_row = rows_.size();
    rows_.push_back(c);
  }
  return best_row;
}

void LoopLog::set_match(std::size_t row, LoopVerdict verdict, double inlier_fraction,
                        double residual_m) {
  if (row >= rows_.size())
    throw Error("loop log: row " + std::to_string(row) + " of " + std::to_string(rows_.size()));
  rows_[row].verdict = verdict;
  rows_[row].match_inlier_fraction = inlier_fraction;
  rows_[row].match_residual_m = residual_m;
}

}  // namespace scfloam
