#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "scfloam/error.hpp"
#include "scfloam/loop/loops_csv.hpp"
#include "test_paths.hpp"

namespace scfloam {
namespace {

std::string first_line(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

TEST(LoopsCsv, RoundTripKeepsEveryColumn) {
  const auto dir = test::scratch_dir("loops_csv_round_trip");
  std::vector<LoopCandidate> rows(3);
  rows[0] = {1200, 15, 600, 7, 0.123456, -3.0892, 0.25, 4.5, 35.0, LoopVerdict::kAccepted, 0.9, 0.031};
  rows[1] = {1210, 16, 601, 8, 0.35, 1.5, 3.0, 35.025, 6.0, LoopVerdict::kRejectedScore};
  rows[2] = {4000, 1, 2000, 0, 0.1, 0.0, 80.0, 70.0, 2.0, LoopVerdict::kRejectedGate};
  rows.push_back(rows[0]);
  rows.back().verdict = LoopVerdict::kRejectedMatch;
  write_loops_csv(dir / "loops.csv", rows);

  EXPECT_EQ(first_line(dir / "loops.csv"),
            "current_frame,loop_frame,current_kf,loop_kf,sc_score,yaw_rad,distance_m,gate_m,verdict,"
            "ring_key_distance,match_inlier_fraction,match_residual_m");
  const auto back = read_loops_csv(dir / "loops.csv");
  ASSERT_EQ(back.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(back[i].current_frame, rows[i].current_frame);
    EXPECT_EQ(back[i].loop_frame, rows[i].loop_frame);
    EXPECT_EQ(back[i].current_kf, rows[i].current_kf);
    EXPECT_EQ(back[i].loop_kf, rows[i].loop_kf);
    EXPECT_NEAR(back[i].sc_score, rows[i].sc_score, 1e-8);
    EXPECT_NEAR(back[i].yaw_rad, rows[i].yaw_rad, 1e-8);
    EXPECT_NEAR(back[i].distance_m, rows[i].distance_m, 1e-8);
    EXPECT_NEAR(back[i].gate_m, rows[i].gate_m, 1e-8);
    EXPECT_NEAR(back[i].ring_key_distance, rows[i].ring_key_distance, 1e-8);
    EXPECT_EQ(back[i].verdict, rows[i].verdict);
    EXPECT_EQ(std::isnan(back[i].match_inlier_fraction), std::isnan(rows[i].match_inlier_fraction));
  }
  EXPECT_NEAR(back[0].match_residual_m, 0.031, 1e-12);
  EXPECT_TRUE(std::isnan(back[1].match_residual_m));
  EXPECT_EQ(back[3].verdict, LoopVerdict::kRejectedMatch);
}

TEST(LoopsCsv, LogRecordsTheRegistrationOutcomeOfTheAcceptedRow) {
  LoopQuery query;
  query.evaluated.resize(3);
  query.evaluated[0] = {120, 2, 60, 1, 0.5, 0, 1, 1, 21, LoopVerdict::kRejectedScore};
  query.evaluated[1] = {120, 3, 60, 2, 0.1, 0, 1, 1, 21, LoopVerdict::kAccepted};
  query.evaluated[2] = {120, 4, 60, 3, 0.15, 0, 1, 1, 21, LoopVerdict::kRejectedRank};
  query.best = query.evaluated[1];
  LoopLog log;
  const auto row = log.add(query);
  ASSERT_TRUE(row.has_value());
  ASSERT_EQ(log.rows().size(), 2u);  // the score-rejected one is not worth a row here
  EXPECT_EQ(log.rows()[*row].loop_kf, 2);
  log.set_match(*row, LoopVerdict::kRejectedMatch, 0.2, 0.4);
  EXPECT_EQ(log.rows()[*row].verdict, LoopVerdict::kRejectedMatch);
  EXPECT_DOUBLE_EQ(log.rows()[*row].match_inlier_fraction, 0.2);
  EXPECT_THROW(log.set_match(7, LoopVerdict::kAccepted, 1, 0), Error);
}

TEST(LoopsCsv, BadFilesNameTheFileAndTheProblem) {
  const auto dir = test::scratch_dir("loops_csv_bad");
  std::ofstream(dir / "no_verdict.csv") << "current_frame,loop_frame,current_kf,loop_kf,sc_score,yaw_rad,distance_m,gate_m\n";
  std::ofstream(dir / "bad_verdict.csv")
      << "current_frame,loop_frame,current_kf,loop_kf,sc_score,yaw_rad,distance_m,gate_m,verdict\n"
      << "1,2,3,4,0.1,0,1,20,maybe\n";
  std::ofstream(dir / "bad_number.csv")
      << "current_frame,loop_frame,current_kf,loop_kf,sc_score,yaw_rad,distance_m,gate_m,verdict\n"
      << "1,2,3,4,0.1x,0,1,20,accepted\n";
  for (const char* name : {"no_verdict.csv", "bad_verdict.csv", "bad_number.csv", "missing.csv"}) {
    try {
      read_loops_csv(dir / name);
      ADD_FAILURE() << name << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(parse_loop_verdict("rejected_"), Error);
  EXPECT_EQ(parse_loop_verdict(to_string(LoopVerdict::kRejectedGate)), LoopVerdict::kRejectedGate);
}

}  // namespace
}  // namespace scfloam
