// Issue 36: the calibration store and a unit's history. Calibrations of a
// simulated unit (in process, test_util.h MakePositions) are filed at
// stated dates; the history must find a planted drift of the z bias (and its
// rate), none in a unit that does not drift, and the calibration closest to
// a date with a warning when it is too old. Bad unit names, dates and index
// files are refused with the key or name.
#include "gravcal/workflows/calibration_store.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "cli_runner.h"
#include "gravcal/io/calibration_io.h"
#include "test_util.h"
#include "twelve_pose_unit.h"

namespace gravcal {
namespace {

using testing_util::ScratchDir;

// The calibration JSON of a unit with z bias `bias_z`, seed `seed`.
std::string StoredCalibration(double bias_z, uint64_t seed, double* bias_z_std) {
  AccelModel truth;
  truth.bias = Eigen::Vector3d(0.02, -0.01, bias_z);
  truth.upper << 1.002, 0.001, -0.002, 0.0, 0.998, 0.0005, 0.0, 0.0, 1.001;
  const Calibration c = testing_util::CalibrateTwelvePoseUnit(truth, seed);
  if (bias_z_std != nullptr) *bias_z_std = c.accel.bias_std(2);
  return CalibrationToJson(c, true);
}

const char* const kDates[] = {"2026-01-01T08:00:00Z", "2026-02-01T08:00:00Z",
                              "2026-03-01T08:00:00Z", "2026-04-01T08:00:00Z",
                              "2026-05-01T08:00:00Z"};

TEST(CalibrationStore, HistoryFindsAPlantedDriftAndOnlyIt) {
  ScratchDir dir;
  const std::string store = dir / "store";
  std::string error;
  double sigma = 0.0;
  StoredCalibration(0.05, 1, &sigma);
  // Drifting unit: the z bias grows by 4 sigma a month; steady unit: none.
  for (int k = 0; k < 5; ++k) {
    ASSERT_TRUE(FileCalibration(store, "drifting", kDates[k],
                                StoredCalibration(0.05 + 4.0 * sigma * k, 10 + k, nullptr), &error))
        << error;
    ASSERT_TRUE(FileCalibration(store, "steady", kDates[k],
                                StoredCalibration(0.05, 100 + k, nullptr), &error))
        << error;
  }
  UnitHistory h;
  ASSERT_TRUE(ReadUnitHistory(store, "drifting", 0.01, &h, &error)) << error;
  ASSERT_EQ(h.calibrations.size(), 5u);
  ASSERT_EQ(h.steps.size(), 4u);
  int drifting = 0;
  for (const ParameterHistory& p : h.parameters) {
    drifting += p.drifts ? 1 : 0;
    if (p.name != "accel.bias_z") continue;
    EXPECT_TRUE(p.drifts) << p.p_value;
    // 16 sigma over the 120 days from January 1 to May 1.
    const double truth_per_day = 16.0 * sigma / 120.0;
    EXPECT_NEAR(p.slope_per_day, truth_per_day, 4.0 * p.slope_std);
    // The trend line through the middle of the values (day 60: 8 sigma).
    EXPECT_NEAR(p.intercept + 60.0 * p.slope_per_day, 0.05 + 8.0 * sigma, 3.0 * sigma);
    EXPECT_DOUBLE_EQ(p.days.back(), 120.0);
  }
  EXPECT_EQ(drifting, 1) << h.message;
  // The report: one plot per parameter, five values with sigma bars in
  // each, the drifting one titled so.
  const std::string html = UnitHistoryToHtml(h);
  EXPECT_EQ(testing_util::Count(html, "class='plot plot-history'"), h.parameters.size());
  EXPECT_EQ(testing_util::Count(html, "accel.bias_z: drifts"), 1u);
  EXPECT_EQ(testing_util::Count(html, "days since 2026-01-01T08:00:00Z"), h.parameters.size());
  ASSERT_TRUE(ReadUnitHistory(store, "steady", 0.01, &h, &error)) << error;
  for (const ParameterHistory& p : h.parameters) EXPECT_FALSE(p.drifts) << p.name;
  std::printf("steady: %s\n", h.message.c_str());
  EXPECT_NE(UnitHistoryToJson(h).find("\"slope_per_day\""), std::string::npos);

  // The closest calibration to a date, and a warning when it is too old.
  StoreEntry entry;
  std::string warning;
  ASSERT_TRUE(
      ClosestCalibration(store, "steady", "2026-02-20T00:00:00Z", 60.0, &entry, &warning, &error))
      << error;
  EXPECT_EQ(entry.date, "2026-03-01T08:00:00Z");
  EXPECT_TRUE(warning.empty()) << warning;
  ASSERT_TRUE(
      ClosestCalibration(store, "steady", "2026-12-01T00:00:00Z", 90.0, &entry, &warning, &error));
  EXPECT_EQ(entry.date, "2026-05-01T08:00:00Z");
  EXPECT_NE(warning.find("recalibrate"), std::string::npos);
  EXPECT_FALSE(
      ClosestCalibration(store, "nobody", "2026-12-01T00:00:00Z", 0.0, &entry, &warning, &error));
  EXPECT_NE(error.find("nobody"), std::string::npos);
}

// The drift test's false alarms: 60 steady units, four calibrations each
// (new noise, same truth). Bonferroni over the nine parameters keeps the
// share of units said to drift at most the level, 0.01: at most 2 of 60
// (binomial tail below 0.03 at 0.01; a per-parameter test at 0.01 calls
// about 9 % of steady units drifting, 5 of 60).
TEST(CalibrationStore, SteadyUnitsRarelyDrift) {
  ScratchDir dir;
  const std::string store = dir / "store";
  std::string error;
  int drifting = 0;
  for (int unit = 0; unit < 60; ++unit) {
    const std::string name = "s" + std::to_string(unit);
    for (int k = 0; k < 4; ++k) {
      ASSERT_TRUE(FileCalibration(store, name, kDates[k],
                                  StoredCalibration(0.05, 1000 + 10 * unit + k, nullptr), &error))
          << error;
    }
    UnitHistory h;
    ASSERT_TRUE(ReadUnitHistory(store, name, 0.01, &h, &error)) << error;
    bool any = false;
    for (const ParameterHistory& p : h.parameters) any = any || p.drifts;
    drifting += any ? 1 : 0;
  }
  std::printf("steady units said to drift: %d of 60\n", drifting);
  EXPECT_LE(drifting, 2);
}

// Two filings of one unit within the same second: both are kept, each in
// its own file (the second used to replace the first).
TEST(CalibrationStore, TwoFilingsInOneSecondAreBothKept) {
  ScratchDir dir;
  const std::string store = dir / "store";
  std::string error;
  const std::string first = StoredCalibration(0.05, 1, nullptr);
  const std::string second = StoredCalibration(0.06, 2, nullptr);
  ASSERT_TRUE(FileCalibration(store, "u1", kDates[0], first, &error)) << error;
  ASSERT_TRUE(FileCalibration(store, "u1", kDates[0], second, &error)) << error;
  std::vector<StoreEntry> entries;
  ASSERT_TRUE(ReadStoreIndex(store, &entries, &error)) << error;
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_NE(entries[0].file, entries[1].file);
  EXPECT_EQ(testing_util::Slurp(store + "/" + entries[0].file), first);
  EXPECT_EQ(testing_util::Slurp(store + "/" + entries[1].file), second);
}

TEST(CalibrationStore, BadNamesDatesAndIndexAreRefused) {
  ScratchDir dir;
  const std::string store = dir / "store";
  const std::string cal = StoredCalibration(0.0, 7, nullptr);
  std::string error;
  EXPECT_FALSE(FileCalibration(store, "../evil", kDates[0], cal, &error));
  EXPECT_NE(error.find("plain name"), std::string::npos);
  EXPECT_FALSE(FileCalibration(store, "u1", "2026-13-01T00:00:00Z", cal, &error));
  EXPECT_NE(error.find("date"), std::string::npos);
  EXPECT_FALSE(FileCalibration(store, "u1", kDates[0], "not json", &error));
  ASSERT_TRUE(FileCalibration(store, "u1", kDates[0], cal, &error)) << error;
  // Filing the same calibration of a unit and date again keeps one entry.
  ASSERT_TRUE(FileCalibration(store, "u1", kDates[0], cal, &error)) << error;
  std::vector<StoreEntry> entries;
  ASSERT_TRUE(ReadStoreIndex(store, &entries, &error));
  EXPECT_EQ(entries.size(), 1u);
  FILE* f = std::fopen((store + "/index.json").c_str(), "w");
  std::fputs("{\"calibrations\": [{\"unit\": \"u1\"}]}", f);
  std::fclose(f);
  EXPECT_FALSE(ReadStoreIndex(store, &entries, &error));
  EXPECT_NE(error.find("calibrations[0]"), std::string::npos) << error;
}

}  // namespace
}  // namespace gravcal
