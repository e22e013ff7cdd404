// Times from the azimuth for scans without a time field (features/sweep_times.hpp): known
// sweeps in the orders drivers keep, turning either way, with returns missing where a
// sensor sees nothing; and clouds whose order shows no sweep are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "scfloam/error.hpp"
#include "scfloam/features/sweep_times.hpp"

namespace scfloam {
namespace {

constexpr int kBeams = 16, kColumns = 1800;
constexpr double kPeriod = 0.1;

struct Sweep {
  std::vector<LidarPoint> points;
  std::vector<double> times;  // true time of each point from the sweep's middle
};

// A VLP-16-like sweep starting at azimuth `seam` (radians), rows or columns first. Returns are
// dropped at random (10 %) and, for the top four beams, over the first fifth of the sweep
// (open sky behind the car), so that no beam's first return need sit at the seam.
Sweep make_sweep(double seam, bool clockwise, bool ring_major, unsigned seed, double laser_offset_deg = 0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> range(4.0, 60.0), unit(0.0, 1.0);
  std::vector<std::vector<LidarPoint>> grid(kBeams, std::vector<LidarPoint>(kColumns));
  std::vector<std::vector<double>> when(kBeams, std::vector<double>(kColumns));
  std::vector<std::vector<bool>> kept(kBeams, std::vector<bool>(kColumns));
  for (int c = 0; c < kColumns; ++c) {
    const double frac = (c + 0.5) / kColumns;
    const double az_column = seam + (clockwise ? -1 : 1) * 2 * M_PI * frac;
    for (int b = 0; b < kBeams; ++b) {
      // Per-laser azimuth offsets (alternating, as in a column of staggered lasers): each beam
      // points off its column by up to laser_offset_deg, firing at the column's time.
      const double off = laser_offset_deg * M_PI / 180 * ((b % 4) - 1.5) / 1.5;
      const double el = (-15.0 + 2.0 * b) * M_PI / 180, r = range(rng), az = az_column + off;
      LidarPoint& p = grid[b][c];
      p.x = static_cast<float>(r * std::cos(el) * std::cos(az));
      p.y = static_cast<float>(r * std::cos(el) * std::sin(az));
      p.z = static_cast<float>(r * std::sin(el));
      when[b][c] = (frac - 0.5) * kPeriod;
      kept[b][c] = unit(rng) > 0.1 && !(b >= kBeams - 4 && frac < 0.2);
    }
  }
  Sweep s;
  auto take = [&](int b, int c) {
    if (!kept[b][c]) return;
    s.points.push_back(grid[b][c]);
    s.times.push_back(when[b][c]);
  };
  if (ring_major) {
    for (int b = 0; b < kBeams; ++b)
      for (int c = 0; c < kColumns; ++c) take(b, c);
  } else {
    for (int c = 0; c < kColumns; ++c)
      for (int b = 0; b < kBeams; ++b) take(b, c);
  }
  return s;
}

double max_time_error(const Sweep& s) {
  double worst = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i)
    worst = std::max(worst, std::abs(double(s.points[i].time_s) - s.times[i]));
  return worst;
}

TEST(SweepTimes, FastAtan2AgreesWithTheLibrary) {
  double worst = 0;
  for (int i = 0; i < 100000; ++i) {
    const double a = -M_PI + 2 * M_PI * (i + 0.5) / 100000, r = 0.5 + (i % 7);
    const float y = static_cast<float>(r * std::sin(a)), x = static_cast<float>(r * std::cos(a));
    worst = std::max(worst, std::abs(double(fast_atan2(y, x)) - std::atan2(double(y), double(x))));
  }
  EXPECT_LT(worst, 2e-5);
  EXPECT_EQ(fast_atan2(0.0f, 0.0f), 0.0f);
}

TEST(SweepTimes, EveryOrderAndTurnGivesEachPointItsTime) {
  // One column is 0.1 s / 1800 = 56 us; the seam is read to a fraction of a degree.
  for (const bool ring_major : {true, false})
    for (const bool clockwise : {true, false})
      for (const double seam : {M_PI, 1.0, -2.5}) {
        SCOPED_TRACE(::testing::Message() << (ring_major ? "beam by beam" : "column by column") << ", "
                                          << (clockwise ? "clockwise" : "counterclockwise") << ", seam " << seam);
        Sweep s = make_sweep(seam, clockwise, ring_major, 7);
        const SweepLayout layout = assign_times_from_azimuth(s.points, kPeriod);
        ASSERT_TRUE(layout.usable) << layout.why;
        EXPECT_EQ(layout.clockwise, clockwise);
        EXPECT_EQ(layout.ring_major, ring_major);
        EXPECT_LT(std::abs(std::remainder(layout.seam_rad - seam, 2 * M_PI)), 0.5 * M_PI / 180);
        EXPECT_LT(max_time_error(s), 2e-4);
      }
}

// Points with no direction (on the axis, not finite) neither break the layout nor get a time
// from it: they are put at the sweep's middle.
TEST(SweepTimes, PointsWithoutADirectionGetTheSweepsMiddle) {
  Sweep s = make_sweep(0.7, false, false, 9);
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i : {std::size_t{5}, std::size_t{5000}, std::size_t{9000}}) s.points[i] = LidarPoint{};
  s.points[6].x = inf;
  s.points[7].y = nan;
  s.points[8].z = -inf;
  const SweepLayout layout = assign_times_from_azimuth(s.points, kPeriod, sweep_stamp_fraction("start"));
  ASSERT_TRUE(layout.usable) << layout.why;
  for (std::size_t i : {5, 6, 7, 8, 5000, 9000}) EXPECT_FLOAT_EQ(s.points[i].time_s, 0.5 * kPeriod) << i;
  for (std::size_t i = 10; i < s.points.size(); i += 101) {
    if (i != 5000 && i != 9000) {
      EXPECT_NEAR(s.points[i].time_s, s.times[i] + 0.5 * kPeriod, 2e-4) << i;
    }
  }
}

// Column by column, a column's lasers may point a few degrees apart (per-laser azimuth
// offsets): the first column's points must still count as the sweep's start and the last
// column's as its end. A point's time then errs by its laser's offset (up to 8 deg here: 2 ms).
TEST(SweepTimes, LasersOffTheirColumnKeepTheirEndOfTheSweep) {
  for (const double offset : {3.4, 8.0})
    for (const bool clockwise : {true, false}) {
      SCOPED_TRACE(::testing::Message() << offset << " deg, " << (clockwise ? "clockwise" : "counterclockwise"));
      Sweep s = make_sweep(-0.4, clockwise, false, 13, offset);
      const SweepLayout layout = assign_times_from_azimuth(s.points, kPeriod);
      ASSERT_TRUE(layout.usable) << layout.why;
      EXPECT_LT(max_time_error(s), (offset / 360 + 0.002) * kPeriod);
    }
}

TEST(SweepTimes, TheStampsPlaceInTheSweepShiftsEveryTime) {
  Sweep start = make_sweep(0.3, true, true, 3), end = start;
  ASSERT_TRUE(assign_times_from_azimuth(start.points, kPeriod, sweep_stamp_fraction("start")).usable);
  ASSERT_TRUE(assign_times_from_azimuth(end.points, kPeriod, sweep_stamp_fraction("end")).usable);
  for (std::size_t i = 0; i < start.points.size(); i += 97) {
    EXPECT_NEAR(start.points[i].time_s, start.times[i] + 0.5 * kPeriod, 2e-4);
    EXPECT_NEAR(end.points[i].time_s, start.times[i] - 0.5 * kPeriod, 2e-4);
  }
  EXPECT_THROW(sweep_stamp_fraction("sideways"), Error);
}

// Where few beams return on both sides of the seam (open space behind the sensor), the scan
// alone does not show where its sweep starts; the driver's cut is fixed, so an earlier scan's
// seam serves, as long as the order turns the same way.
TEST(SweepTimes, AnUnclearSeamIsTakenFromAnEarlierScan) {
  const double seam = 2.0;
  Sweep clear = make_sweep(seam, true, true, 11);
  const SweepLayout earlier = assign_times_from_azimuth(clear.points, kPeriod);
  ASSERT_TRUE(earlier.usable);
  EXPECT_FALSE(earlier.seam_from_earlier);
  // Every beam but two loses its returns within 10 deg of the seam.
  Sweep open = make_sweep(seam, true, true, 12);
  Sweep kept;
  for (std::size_t i = 0; i < open.points.size(); ++i) {
    const LidarPoint& p = open.points[i];
    const double off = std::remainder(std::atan2(p.y, p.x) - seam, 2 * M_PI);
    const bool low_beam = p.z < -0.2 * std::hypot(p.x, p.y);  // the two lowest beams (-15, -13 deg)
    if (std::abs(off) < 10 * M_PI / 180 && !low_beam) continue;
    kept.points.push_back(p);
    kept.times.push_back(open.times[i]);
  }
  std::vector<LidarPoint> alone = kept.points;
  EXPECT_FALSE(assign_times_from_azimuth(alone, kPeriod).usable);
  const SweepLayout layout = assign_times_from_azimuth(kept.points, kPeriod, 0.5, &earlier);
  ASSERT_TRUE(layout.usable);
  EXPECT_TRUE(layout.seam_from_earlier);
  EXPECT_LT(max_time_error(kept), 2e-4);
  // Nor is it taken for an order that is no single sweep: column by column twice round.
  Sweep twice = make_sweep(seam, true, false, 14);
  const std::size_t half = twice.points.size();
  for (std::size_t i = 0; i < half; ++i) twice.points.push_back(twice.points[i]);
  const SweepLayout twice_layout = assign_times_from_azimuth(twice.points, kPeriod, 0.5, &earlier);
  EXPECT_FALSE(twice_layout.usable);
  EXPECT_FALSE(twice_layout.seam_from_earlier);
  // An earlier layout of the other turn is not taken.
  SweepLayout other = earlier;
  other.clockwise = false;
  std::vector<LidarPoint> again = kept.points;
  EXPECT_FALSE(assign_times_from_azimuth(again, kPeriod, 0.5, &other).usable);
}

TEST(SweepTimes, ACloudOutOfFiringOrderIsRefusedAndLeftAsItWas) {
  Sweep s = make_sweep(1.0, true, true, 5);
  std::shuffle(s.points.begin(), s.points.end(), std::mt19937(1));
  for (auto& p : s.points) p.time_s = 0.25f;
  const SweepLayout layout = assign_times_from_azimuth(s.points, kPeriod);
  EXPECT_FALSE(layout.usable);
  EXPECT_FALSE(layout.why.empty());
  for (const auto& p : s.points) ASSERT_EQ(p.time_s, 0.25f);

  // Sorted by range (a filter's output, say): one beam's neighbours jump around the circle.
  Sweep sorted = make_sweep(1.0, true, false, 5);
  std::sort(sorted.points.begin(), sorted.points.end(), [](const LidarPoint& a, const LidarPoint& b) {
    return a.x * a.x + a.y * a.y < b.x * b.x + b.y * b.y;
  });
  EXPECT_FALSE(sweep_layout(sorted.points).usable);
  EXPECT_FALSE(sweep_layout(std::vector<LidarPoint>(50)).usable);
}

}  // namespace
}  // namespace scfloam
