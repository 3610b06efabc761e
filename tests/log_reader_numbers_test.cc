// Issue 39: the one number parser of text input (util/numbers.h ParseNumber,
// fast_float behind a one-pass path for short decimals) is exact: on
// edge-case and random strings it gives strtod's double bit for bit and
// std::from_chars's outcome (where the number ends, out of range, not a
// number), so the readers refuse what they refused before, with the same
// messages. Also: a log read block by block from its file equals the log
// parsed in memory, and its content hash the hash of the whole text.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/io/recording.h"
#include "test_util.h"
#include "util/content_hash.h"
#include "util/numbers.h"

namespace gravcal {
namespace {

uint64_t Bits(double x) {
  uint64_t b;
  std::memcpy(&b, &x, sizeof(b));
  return b;
}

// Holds ParseNumber to std::from_chars (outcome, end, value) and, where
// both read the same characters as a number, to strtod (value). Returns
// false on the first difference, saying what it is in *why.
bool SameAsReference(const std::string& text, std::string* why) {
  const char* first = text.data();
  const char* last = first + text.size();
  double ours = -7.0, reference = -7.0;
  const std::from_chars_result a = internal::ParseNumber(first, last, &ours);
  const std::from_chars_result b = std::from_chars(first, last, reference);
  if (a.ec != b.ec || a.ptr != b.ptr) {
    *why = "'" + text + "': ec " + std::to_string(static_cast<int>(a.ec)) + " vs " +
           std::to_string(static_cast<int>(b.ec)) + ", length " + std::to_string(a.ptr - first) +
           " vs " + std::to_string(b.ptr - first);
    return false;
  }
  if (a.ec != std::errc()) return true;
  if (Bits(ours) != Bits(reference) && !(std::isnan(ours) && std::isnan(reference))) {
    *why = "'" + text + "': " + internal::ExactNumber(ours) + " vs from_chars " +
           internal::ExactNumber(reference);
    return false;
  }
  // strtod reads hex and leading blanks too; compare where it reads the
  // same characters.
  const std::string copy(first, a.ptr);
  char* end = nullptr;
  const double c = std::strtod(copy.c_str(), &end);
  if (end == copy.c_str() + copy.size() && Bits(c) != Bits(ours) &&
      !(std::isnan(c) && std::isnan(ours))) {
    *why =
        "'" + text + "': " + internal::ExactNumber(ours) + " vs strtod " + internal::ExactNumber(c);
    return false;
  }
  return true;
}

TEST(LogReaderNumbers, EdgeCasesMatchStrtodAndFromChars) {
  const std::vector<std::string> cases = {
      // Plain and short decimals with exponents (the fast path).
      "0", "-0", "00001.5", "-000.000", "1", "-1234", "3.3108000e+04", "3.3108000E-04",
      "9007199254740992", "9007199254740993", "-9007199254740993e-3", "1e22", "1e23", "1e-22",
      "1e-23", "123456789012345678", "1234567890123456789", "12345678901234567890", "0.1",
      "0.30000000000000004", ".5", "5.", "1.e5", "-.5e-1", "0e999999", "0.0e-99999",
      // 17 and more significant digits; halfway cases.
      "1.7976931348623157e308", "1.7976931348623158e308", "2.2250738585072011e-308",
      "2.2250738585072014e-308", "9007199254740993.0000000000000000001",
      "1.00000000000000011102230246251565404236316680908203125",
      "1.00000000000000011102230246251565404236316680908203124",
      "0.1000000000000000055511151231257827021181583404541015625",
      "123456789012345678901234567890e-20",
      // Subnormals and the limits of the range.
      "4.9406564584124654e-324", "2.4703282292062328e-324", "2.4703282292062327e-324", "5e-324",
      "3e-324", "1e-310", "2.2250738585072009e-308",
      // Out of range: a finite text overflowing or a nonzero one underflowing.
      "1e400", "-1e400", "1.7976931348623159e308", "1e-400", "2e-324", "1e99999999999999999999",
      "-1e-99999999999999999999", "0.000000000000000000000000000000001e-300",
      // Infinity and not-a-number.
      "inf", "-inf", "INF", "infinity", "Infinity", "nan", "-nan", "NaN", "nan(123)", "infx",
      // Not numbers, or numbers ending early.
      "", "-", "+1", "+-1", "--1", ".", "-.", "-.e1", "e5", "1e", "1e+", "1e-", "1.5e+x", "0x10",
      "1,5", " 1", "1 ", "1..2", "1.2.3", "1e5e5", "abc", "١"};
  for (const std::string& text : cases) {
    std::string why;
    EXPECT_TRUE(SameAsReference(text, &why)) << why;
  }
}

// Random strings shaped like numbers: digits of random length with leading
// zeros, a point anywhere, exponents across and beyond the range, signs,
// and some stray characters.
std::string RandomNumberText(std::mt19937_64* rng) {
  std::uniform_int_distribution<int> pick(0, 99);
  std::string s;
  if (pick(*rng) < 40) s += '-';
  if (pick(*rng) < 3) s += '+';
  const int zeros = pick(*rng) < 20 ? pick(*rng) % 6 : 0;
  s.append(static_cast<size_t>(zeros), '0');
  const int length = pick(*rng) < 70 ? 1 + pick(*rng) % 10 : 1 + pick(*rng) % 40;
  const int point = pick(*rng) < 75 ? pick(*rng) % (length + 1) : -1;
  for (int i = 0; i < length; ++i) {
    if (i == point) s += '.';
    s += static_cast<char>('0' + pick(*rng) % 10);
  }
  if (point == length) s += '.';
  const int e = pick(*rng);
  if (e < 50) {
    s += pick(*rng) < 50 ? 'e' : 'E';
    const int sign = pick(*rng);
    if (sign < 40) s += '-';
    if (sign >= 80) s += '+';
    const int magnitude = pick(*rng) < 60 ? pick(*rng) % 30 : pick(*rng) * 4;
    if (pick(*rng) < 2) s += "0000";
    if (pick(*rng) < 3)
      s += std::to_string(magnitude) + "000000000000";  // huge
    else
      s += std::to_string(magnitude);
  }
  if (pick(*rng) < 5) s.insert(s.begin() + pick(*rng) % (s.size() + 1), "x.e- +"[pick(*rng) % 6]);
  return s;
}

TEST(LogReaderNumbers, RandomTextsMatchStrtodAndFromChars) {
  std::mt19937_64 rng(39);
  int failures = 0;
  for (int i = 0; i < 100000 && failures < 10; ++i) {
    std::string why;
    if (!SameAsReference(RandomNumberText(&rng), &why)) {
      ADD_FAILURE() << why;
      ++failures;
    }
  }
}

TEST(LogReaderNumbers, RandomDoublesWrittenAnyWayReadBackExactly) {
  std::mt19937_64 rng(3939);
  std::uniform_int_distribution<uint64_t> any_bits;
  const char* formats[] = {"%.17g", "%.9g", "%.6e", "%.3f", "%.15e", "%.25g"};
  int failures = 0;
  for (int i = 0; i < 50000 && failures < 10; ++i) {
    double x;
    const uint64_t bits = any_bits(rng);
    std::memcpy(&x, &bits, sizeof(x));
    if (!std::isfinite(x)) continue;
    // Half of them sensor-like: a scale of 1e-6 to 1e6.
    if (i % 2 == 0)
      x = std::ldexp(static_cast<double>(bits >> 11), -53) * std::pow(10.0, i % 13 - 6);
    char text[400];
    std::snprintf(text, sizeof(text), formats[i % 6], x);
    std::string why;
    if (!SameAsReference(text, &why)) {
      ADD_FAILURE() << why;
      ++failures;
    }
  }
}

std::string ReadError(const std::string& cell) {
  ImuLog log;
  std::string error;
  EXPECT_FALSE(ParseImuLog("t,ax,ay,az\n0,1,2,3\n1,1," + cell + ",3\n", "n.csv", {}, &log, &error));
  return error;
}

TEST(LogReaderNumbers, TheReaderRefusesWhatItRefusedBeforeWithTheSameMessages) {
  EXPECT_EQ(ReadError("abc"), "n.csv:3: column 'ay': 'abc' is not a number");
  EXPECT_EQ(ReadError("+-1"), "n.csv:3: column 'ay': '+-1' is not a number");
  EXPECT_EQ(ReadError("0x10"), "n.csv:3: column 'ay': '0x10' is not a number");
  EXPECT_EQ(ReadError("1e"), "n.csv:3: column 'ay': '1e' is not a number");
  EXPECT_EQ(ReadError("1e400"), "n.csv:3: column 'ay': '1e400' is out of range");
  EXPECT_EQ(ReadError("-1e-400"), "n.csv:3: column 'ay': '-1e-400' is out of range");
  EXPECT_EQ(ReadError("nan"), "n.csv:3: column 'ay': 'nan' is not finite");
  EXPECT_EQ(ReadError("-inf"), "n.csv:3: column 'ay': '-inf' is not finite");
  EXPECT_EQ(ReadError(""), "n.csv:3: column 'ay' is empty");
  // What it reads: a leading '+', blanks around a CSV cell, subnormals.
  ImuLog log;
  std::string error;
  ASSERT_TRUE(
      ParseImuLog("t,ax,ay,az\n0, +3.3108000e+04 ,-0.5E-3,4.9e-324\n", "n.csv", {}, &log, &error))
      << error;
  EXPECT_EQ(Bits(log.accel[0].x()), Bits(33108.0));
  EXPECT_EQ(Bits(log.accel[0].y()), Bits(-0.0005));
  EXPECT_EQ(Bits(log.accel[0].z()), Bits(4.9406564584124654e-324));
}

TEST(LogReaderNumbers, ContentHashInPiecesEqualsTheWholeText) {
  std::string text;
  for (int i = 0; i < 1000; ++i) text += static_cast<char>('a' + (i * 7919) % 26);
  internal::ContentHash whole;
  whole.Add(text);
  for (size_t piece : {size_t{1}, size_t{5}, size_t{31}, size_t{32}, size_t{33}, size_t{100}}) {
    internal::ContentHash pieces;
    pieces.Begin(text.size());
    for (size_t at = 0; at < text.size(); at += piece) pieces.Append(text.substr(at, piece));
    pieces.End();
    EXPECT_EQ(pieces.Hex(), whole.Hex()) << piece;
  }
}

TEST(LogReaderNumbers, AFileReadBlockByBlockEqualsTheTextParsedInMemory) {
  // About 3 MB: the 1 MiB blocks of the reader end inside lines.
  std::string text = "t,ax,ay,az,gx,gy,gz,temp\n";
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> counts(-40000, 40000);
  char row[200];
  for (int i = 0; i < 60000; ++i) {
    std::snprintf(row, sizeof(row), "%.3f,%d,%d,%d,%.7e,%.7e,%.7e,%.2f\n", 0.01 * i, counts(rng),
                  counts(rng), counts(rng), counts(rng) * 1e-3, counts(rng) * 1e-5,
                  counts(rng) * 1e-7, 25.0 + counts(rng) * 1e-5);
    text += row;
  }
  std::string path = testing_util::ScratchFileTemplate("blockwise");
  const int fd = mkstemp(path.data());
  ASSERT_GE(fd, 0);
  std::FILE* file = fdopen(fd, "wb");
  ASSERT_NE(file, nullptr);
  ASSERT_EQ(std::fwrite(text.data(), 1, text.size(), file), text.size());
  std::fclose(file);

  ImuLog from_file, in_memory;
  CalibrationProvenance provenance;
  std::string error;
  ASSERT_TRUE(ReadImuLog(path, {}, &from_file, &provenance, &error)) << error;
  ASSERT_TRUE(ParseImuLog(text, path, {}, &in_memory, &error)) << error;
  ASSERT_EQ(from_file.size(), 60000u);
  ASSERT_EQ(in_memory.size(), from_file.size());
  for (size_t i = 0; i < from_file.size(); ++i) {
    ASSERT_EQ(from_file.t[i], in_memory.t[i]) << i;
    ASSERT_EQ(from_file.accel[i], in_memory.accel[i]) << i;
    ASSERT_EQ(from_file.gyro[i], in_memory.gyro[i]) << i;
    ASSERT_EQ(from_file.temperature[i], in_memory.temperature[i]) << i;
  }
  internal::ContentHash hash;
  hash.Add(text);
  EXPECT_EQ(provenance.log_hash, hash.Hex());
  std::remove(path.c_str());
}

TEST(LogReaderNumbers, InspectStreamsTheLogAndGivesTheStatisticsOfAllItsIntervals) {
  // 70000 samples (more than one block of the interval statistics) at a
  // jittering 100 Hz with gaps: what InspectRecording streams equals the
  // statistics of the whole log read into memory.
  std::string text = "t,ax,ay,az\n";
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> jitter(-3, 3), gap(0, 999);
  double t = 0.0;
  char row[100];
  for (int i = 0; i < 70000; ++i) {
    t += 0.01 + 0.0001 * jitter(rng) + (gap(rng) == 0 ? 0.05 : 0.0);
    std::snprintf(row, sizeof(row), "%.4f,1,2,3\n", t);
    text += row;
  }
  std::string path = testing_util::ScratchFileTemplate("inspect");
  const int fd = mkstemp(path.data());
  ASSERT_GE(fd, 0);
  ASSERT_EQ(write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  close(fd);
  RecordingSummary summary;
  ImuLog log;
  std::string error;
  ASSERT_TRUE(InspectRecording(path, {}, &summary, &error)) << error;
  ASSERT_TRUE(ReadImuLog(path, {}, &log, &error)) << error;
  std::remove(path.c_str());
  ASSERT_EQ(summary.topics.size(), 1u);
  const TopicSummary& s = summary.topics[0];
  std::vector<double> dt;
  for (size_t i = 1; i < log.size(); ++i) dt.push_back(log.t[i] - log.t[i - 1]);
  std::vector<double> sorted = dt;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  EXPECT_EQ(s.messages, 70000);
  EXPECT_EQ(s.first_s, log.t.front());
  EXPECT_EQ(s.last_s, log.t.back());
  EXPECT_EQ(s.median_interval_s, median);
  EXPECT_EQ(s.longest_interval_s, sorted.back());
  EXPECT_EQ(s.gaps, std::count_if(dt.begin(), dt.end(), [&](double d) { return d > 2 * median; }));
  EXPECT_GT(s.gaps, 20);
  EXPECT_LT(s.gaps, 140);
  // A file that cannot be read is named.
  EXPECT_FALSE(InspectRecording(path + "-missing", {}, &summary, &error));
  EXPECT_NE(error.find("-missing"), std::string::npos) << error;
}

}  // namespace
}  // namespace gravcal
