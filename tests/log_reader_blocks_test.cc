// A long text log parsed on several threads (io/log_blocks.h) gives what the
// line-by-line reader gives: the same rows, bit for bit, the same line count
// and, for a bad file, the same one-line error at the same line. Blocks are
// made tiny here so that every kind of line and every error falls on and
// around block boundaries.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gravcal/io/log_reader.h"
#include "gravcal/io/long_log.h"
#include "io/log_blocks.h"
#include "io/log_text.h"

namespace gravcal {
namespace {

using internal::kNumSlots;

struct BlockParse {
  std::vector<double> rows;  // kNumSlots values a row
  size_t count = 0;
  size_t lines = 0;
  std::string error;
  bool blocks = false;  // ParseLogBlocks took over
};

// Reads `path` as ParseText does: line by line (threads 0), or line by line
// up to the first row and the rest with ParseLogBlocks.
BlockParse ParseWithBlocks(const std::string& path, const LogReaderOptions& options, int threads,
                           size_t block_bytes) {
  BlockParse out;
  std::FILE* file = std::fopen(path.c_str(), "rb");
  EXPECT_NE(file, nullptr);
  if (file == nullptr) return out;
  internal::LogLines source(file, path);
  internal::LogRowParser parser(path, options, false);
  const internal::LogRowSink sink = [&](const double* rows, size_t count) {
    out.rows.insert(out.rows.end(), rows, rows + count * kNumSlots);
  };
  std::string_view line;
  std::string why;
  while (source.Next(&line, &why)) {
    bool row = false;
    if (!parser.Line(line, source.number(), &row, &why)) break;
    if (!row) continue;
    sink(parser.values(), 1);
    if (threads > 0 && internal::CanParseLogBlocks(source, parser)) {
      out.blocks = true;
      if (!internal::ParseLogBlocks(&source, &parser, threads, sink, &why, block_bytes)) break;
    }
  }
  std::fclose(file);
  out.error = why;
  out.count = parser.rows();
  out.lines = source.number();
  return out;
}

std::string WriteScratch(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/log_blocks_" + name;
  std::FILE* file = std::fopen(path.c_str(), "wb");
  EXPECT_NE(file, nullptr);
  EXPECT_EQ(std::fwrite(text.data(), 1, text.size(), file), text.size());
  std::fclose(file);
  return path;
}

// Every block size and thread count (`all`; else two sizes smaller than a
// row or two, on two threads) against the line-by-line reader; returns the
// line-by-line reader's error ("" when the file is good).
std::string ExpectSameAsLineByLine(const std::string& name, const std::string& text,
                                   const LogReaderOptions& options = LogReaderOptions(),
                                   bool all = true) {
  const std::string path = WriteScratch(name, text);
  const BlockParse reference = ParseWithBlocks(path, options, 0, 0);
  const std::vector<size_t> sizes =
      all ? std::vector<size_t>{61, 97, 1000, size_t{1} << 16} : std::vector<size_t>{61, 97};
  const std::vector<int> thread_counts = all ? std::vector<int>{1, 2, 3} : std::vector<int>{2};
  for (size_t block_bytes : sizes) {
    for (int threads : thread_counts) {
      const BlockParse blocks = ParseWithBlocks(path, options, threads, block_bytes);
      SCOPED_TRACE(name + ", blocks of " + std::to_string(block_bytes) + " bytes, " +
                   std::to_string(threads) + " threads");
      EXPECT_TRUE(blocks.blocks);
      EXPECT_EQ(blocks.error, reference.error);
      EXPECT_EQ(blocks.count, reference.count);
      EXPECT_EQ(blocks.lines, reference.lines);
      EXPECT_TRUE(blocks.rows.size() == reference.rows.size() &&
                  std::memcmp(blocks.rows.data(), reference.rows.data(),
                              sizeof(double) * reference.rows.size()) == 0);
    }
  }
  std::remove(path.c_str());
  return reference.error;
}

// Rows of raw counts and decimals, with comments, blank lines, blanks
// around cells, '+' signs and exponents among them.
std::string MixedRows(int n, const char* end = "\n", int first = 0) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> counts(-40000, 40000);
  std::string text;
  char row[200];
  for (int i = first; i < first + n; ++i) {
    if (i % 97 == 5) text += std::string("# a comment") + end;
    if (i % 89 == 7) text += std::string("  ") + end;
    const int kind = i % 4;
    if (kind == 0) {
      std::snprintf(row, sizeof(row), "%.3f,%d,%d,%d,%d,%d,%d,25%s", 0.01 * i, counts(rng),
                    counts(rng), counts(rng), counts(rng), counts(rng), counts(rng), end);
    } else if (kind == 1) {
      std::snprintf(row, sizeof(row), "%.3f, +%d ,%d,%.7e,%.7e,%.7e,%.7e,%.2f%s", 0.01 * i,
                    std::abs(counts(rng)), counts(rng), counts(rng) * 1e-3, counts(rng) * 1e-5,
                    counts(rng) * 1e-7, counts(rng) * 1e9, 25.0 + counts(rng) * 1e-5, end);
    } else {
      std::snprintf(row, sizeof(row), "%.17g,%.17g,%d.%04d,-0.%d,%dE-3,%d,0,%d%s", 0.01 * i,
                    counts(rng) * 0.1234567, counts(rng), i % 10000, i % 1000, counts(rng),
                    counts(rng), counts(rng), end);
    }
    text += row;
  }
  return text;
}

const char kHeader[] = "t,ax,ay,az,gx,gy,gz,temp\n";

TEST(LogReaderBlocks, GoodLogsGiveTheSameRows) {
  EXPECT_EQ(ExpectSameAsLineByLine("good.csv", kHeader + MixedRows(1500)), "");
  EXPECT_EQ(
      ExpectSameAsLineByLine("crlf.csv", "t,ax,ay,az,gx,gy,gz,temp\r\n" + MixedRows(800, "\r\n")),
      "");
  std::string no_end = kHeader + MixedRows(700);
  no_end.pop_back();  // The last line has no line end.
  EXPECT_EQ(ExpectSameAsLineByLine("no_end.csv", no_end), "");
  // A column not used comes first: a comment or a blank line that looks like
  // a row after it stays a comment; CR LF and lone CR around unused cells.
  std::string unused = "seq,t,ax,ay,az,note\n";
  for (int i = 0; i < 900; ++i) {
    const std::string n = std::to_string(i);
    unused += i % 7 == 3   ? "#" + n + "," + n + ",1,2,3,x\n"
              : i % 7 == 4 ? "  #" + n + "," + n + ",1,2,3,x\n"
              : i % 7 == 5 ? n + "," + n + ".5,1,2,3,a\r\n"
                           : n + "," + n + ",4,-5," + n + ",\n";
  }
  EXPECT_EQ(ExpectSameAsLineByLine("unused.csv", unused), "");
  // No time column: t = row / sample_rate, counted across blocks.
  std::string untimed = "ax,ay,az\n";
  for (int i = 0; i < 900; ++i)
    untimed += std::to_string(i) + ",-2," + std::to_string(i % 7) + "\n";
  LogReaderOptions rate;
  rate.sample_rate = 200.0;
  EXPECT_EQ(ExpectSameAsLineByLine("untimed.csv", untimed, rate), "");
  // Whitespace columns, nanosecond time.
  std::string spaced;
  for (int i = 0; i < 900; ++i) {
    spaced += std::to_string(1700000000000000000LL + 5000000LL * i) + " \t1.5  -2 " +
              std::to_string(i) + "e-2\n";
  }
  LogReaderOptions columns;
  columns.format = LogFormat::kWhitespace;
  columns.columns = {"t", "ax", "ay", "az"};
  columns.time_scale = 1e-9;
  EXPECT_EQ(ExpectSameAsLineByLine("spaced.txt", spaced, columns), "");
}

TEST(LogReaderBlocks, BadLogsGiveTheSameErrorAtTheSameLine) {
  const std::string good = MixedRows(600);
  // Each fault replaces one line, at several places (so that some fall on a
  // block's first or last line).
  const std::vector<std::string> faults = {
      "1e9,1,2,3,4,5,6,abc",                           // not a number
      "1e9,1,2,3,4,5,6",                               // a field missing
      "1e9,1,2,3,4,5,6,7,8",                           // one too many
      "1e9,1,,3,4,5,6,7",                              // empty cell
      "1e9,1,nan,3,4,5,6,7",                           // not finite
      "1e9,1,1e999,3,4,5,6,7",                         // out of range
      "0,1,2,3,4,5,6,7",                               // time goes back
      "1e9,1,2\r,3,4,5,6,7",                           // a carriage return inside a line
      "1e9,1,2,3,4,5,6,7\r\r",                         // two before the line end
      std::string(70000, '7'),                         // longer than a log line
      "1e9,1,2,3,4,5,6,7," + std::string(65600, ' '),  // long, with its line end
  };
  int f = 0;
  for (const std::string& fault : faults) {
    for (size_t at : {size_t{3}, size_t{57}, size_t{400}}) {
      std::string text = kHeader;
      size_t line_start = 0;
      for (size_t line = 0; line_start < good.size(); ++line) {
        const size_t line_end = good.find('\n', line_start) + 1;
        text += line == at ? fault + "\n" : good.substr(line_start, line_end - line_start);
        line_start = line_end;
      }
      const std::string error =
          ExpectSameAsLineByLine("bad" + std::to_string(f) + ".csv", text, {}, false);
      // The fault's line (after the header), or the next one for a time
      // the next row does not exceed.
      EXPECT_TRUE(error.find(":" + std::to_string(at + 2) + ": ") != std::string::npos ||
                  error.find(":" + std::to_string(at + 3) + ": ") != std::string::npos)
          << error;
    }
    ++f;
  }
  // A last line too long, without a line end; a time equal to the one before
  // in the last row.
  EXPECT_NE(
      ExpectSameAsLineByLine("long_end.csv", kHeader + MixedRows(300) + std::string(66000, '1'))
          .find("66000 bytes long"),
      std::string::npos);
  EXPECT_NE(
      ExpectSameAsLineByLine("repeat_end.csv", kHeader + MixedRows(300) + "2.99,1,2,3,4,5,6,7\n")
          .find("does not increase"),
      std::string::npos);
}

TEST(LogReaderBlocks, ALongFileReadOnTwoThreadsEqualsOneThread) {
  // Above kMinBlockParseBytes, so that ReadImuLogBounded parses it on
  // several threads; averaged (max_samples) as a long log is.
  std::string text = kHeader;
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> counts(-40000, 40000);
  char row[160];
  for (int i = 0; text.size() < internal::kMinBlockParseBytes + 3000000; ++i) {
    std::snprintf(row, sizeof(row), "%.3f,%d,%d,%d,%d,%d,%d,%.2f\n", 0.001 * i, counts(rng),
                  counts(rng), counts(rng), counts(rng), counts(rng), counts(rng),
                  25.0 + 1e-4 * (i % 1000));
    text += row;
  }
  const std::string path = WriteScratch("long.csv", text);
  ImuLog one, two;
  LongLogReading one_reading, two_reading;
  one_reading.max_samples = two_reading.max_samples = 100000;
  one_reading.threads = 1;
  two_reading.threads = 2;
  CalibrationProvenance one_provenance, two_provenance;
  std::string error;
  ASSERT_TRUE(ReadImuLogBounded(path, {}, &one_reading, &one, &one_provenance, &error)) << error;
  ASSERT_TRUE(ReadImuLogBounded(path, {}, &two_reading, &two, &two_provenance, &error)) << error;
  std::remove(path.c_str());
  EXPECT_GT(one_reading.samples_averaged, 1u);
  EXPECT_EQ(two_reading.samples_averaged, one_reading.samples_averaged);
  EXPECT_EQ(two_reading.rows_read, one_reading.rows_read);
  EXPECT_EQ(two_provenance.log_hash, one_provenance.log_hash);
  // Every entry, bit for bit.
  EXPECT_TRUE(two.t == one.t && two.accel == one.accel && two.gyro == one.gyro &&
              two.temperature == one.temperature);
}

// A log with a second gyroscope file, in bounded memory: both files in step
// (io/log_pair.h), with the log or the error ReadImuLog gives; a longer pair
// is held as the block means of the same rows in one file.
TEST(LogReaderBlocks, GyroFileReadInStepInBoundedMemory) {
  LogReaderOptions options;
  options.format = LogFormat::kWhitespace;
  options.columns = {"t", "ax", "ay", "az"};
  const std::string main_path = WriteScratch("step_accel.txt", "");
  options.gyro_path = WriteScratch("step_gyro.txt", "");
  const std::string accel = "1.0 1 2 3\n1.1 4 5 6\n1.2 7 8 9\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {accel, "# gyro\n1.0 0.1 0.2 0.3\n1.1 0.4 0.5 0.6\n1.2 0.7 0.8 0.9\n"},
      {accel, "1.0 0.1 0.2 0.3\n1.1 0.4 0.5 0.6\n1.25 0.7 0.8 0.9\n"},  // a time differs
      {accel, "1.0 0.1 0.2 0.3\n1.1 x 0.5 0.6\n"},                      // bad, and short
      {accel, "1.0 0.1 0.2 0.3\n1.1 0.4 0.5 0.6\n"},                    // fewer rows
      {accel, "1.0 0 0 0\n1.1 0 0 0\n1.2 0 0 0\n1.3 0 0 0\n"},          // more rows
      {"1.0 1 2 3\n1.1 4 5\n", "1.0 0 0 0\n1.3 0 0 0\n"},               // both bad
      {"# nothing\n", "1.0 0 0 0\n"},                                   // no rows
      {accel, ""}};
  for (const auto& [main_text, gyro_text] : cases) {
    WriteScratch("step_accel.txt", main_text);
    WriteScratch("step_gyro.txt", gyro_text);
    for (const bool missing : {false, true}) {
      LogReaderOptions o = options;
      if (missing) o.gyro_path += ".missing";
      ImuLog whole, in_step;
      std::string whole_error, step_error;
      const bool whole_ok = ReadImuLog(main_path, o, &whole, &whole_error);
      LongLogReading reading;
      EXPECT_EQ(ReadImuLogBounded(main_path, o, &reading, &in_step, nullptr, &step_error), whole_ok)
          << gyro_text;
      EXPECT_EQ(step_error, whole_error);
      EXPECT_TRUE(in_step.t == whole.t && in_step.accel == whole.accel &&
                  in_step.gyro == whole.gyro);
    }
  }
  // 100 rows held as means of 8 (at most 16 entries): those of one file.
  std::string main_text, gyro_text, joined = "t,ax,ay,az,gx,gy,gz\n";
  for (int i = 0; i < 100; ++i) {
    const std::string t = std::to_string(i) + ".5 ";
    const std::string a = std::to_string(i % 7) + " " + std::to_string(-i) + " 0.25";
    const std::string g = std::to_string(3 * i) + " 0.125 " + std::to_string(i % 5);
    main_text += t + a + "\n";
    gyro_text += t + g + "\n";
    std::string row = t + a + " " + g + "\n";
    for (char& c : row) c = c == ' ' ? ',' : c;
    joined += row;
  }
  WriteScratch("step_accel.txt", main_text);
  WriteScratch("step_gyro.txt", gyro_text);
  const std::string joined_path = WriteScratch("step_joined.csv", joined);
  LongLogReading pair_reading, joined_reading;
  pair_reading.max_samples = joined_reading.max_samples = 16;
  ImuLog pair, one;
  std::string error;
  ASSERT_TRUE(ReadImuLogBounded(main_path, options, &pair_reading, &pair, nullptr, &error))
      << error;
  ASSERT_TRUE(ReadImuLogBounded(joined_path, {}, &joined_reading, &one, nullptr, &error)) << error;
  EXPECT_EQ(pair_reading.samples_averaged, 8u);
  EXPECT_EQ(pair_reading.rows_read, 100u);
  EXPECT_EQ(pair.size(), 12u);
  EXPECT_TRUE(pair.t == one.t && pair.accel == one.accel && pair.gyro == one.gyro);
  for (const std::string& path : {main_path, options.gyro_path, joined_path}) {
    std::remove(path.c_str());
  }
}

}  // namespace
}  // namespace gravcal
