// Issue 20: the log reader's size limits, escaped bytes in messages, and the
// reader messages log_reader_test.cc does not reach (each message of the
// reader has a test between the two files).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <string>

#include "gravcal/core/imu_log.h"
#include "gravcal/io/log_reader.h"
#include "io/file_text.h"
#include "util/cancellation.h"

namespace gravcal {
namespace {

std::string ParseError(const std::string& text, const LogReaderOptions& options = {}) {
  ImuLog log;
  std::string error;
  EXPECT_FALSE(ParseImuLog(text, "mem.csv", options, &log, &error)) << text.substr(0, 80);
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  return error;
}

bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(LogReaderLimits, AVeryLongLineIsRefusedWithItsLength) {
  const std::string line(200000, '1');
  const std::string error = ParseError("t,ax,ay,az\n" + line + "\n");
  EXPECT_TRUE(Has(error, "mem.csv:2: the line is 200000 bytes long")) << error;
  EXPECT_TRUE(Has(error, "at most 65536")) << error;
}

TEST(LogReaderLimits, MillionsOfColumnsAreRefusedCleanly) {
  // A header of a million columns is refused by its length before it is split.
  std::string header = "t,ax,ay,az";
  for (int i = 0; i < 1000000; ++i) header += ",c";
  std::string error = ParseError(header + "\n0,1,2,3\n");
  EXPECT_TRUE(Has(error, "mem.csv:1: the line is")) << error.substr(0, 200);
  // Fewer, shorter names within the line limit: the column count is refused.
  header = "t,ax,ay,az";
  for (int i = 0; i < 5000; ++i) header += ",c" + std::to_string(i % 10);
  error = ParseError(header + "\n");
  EXPECT_TRUE(Has(error, "mem.csv:1: the header has 5004 columns; a log has at most 4096"))
      << error;
  LogReaderOptions options;
  options.format = LogFormat::kWhitespace;
  for (int i = 0; i < 5000; ++i) options.columns.push_back("c" + std::to_string(i));
  options.columns[0] = "ax";
  options.columns[1] = "ay";
  options.columns[2] = "az";
  options.sample_rate = 10;
  error = ParseError("1 2 3\n", options);
  EXPECT_TRUE(Has(error, "columns lists 5000 columns")) << error;
}

TEST(LogReaderLimits, ALogTooLargeForMemoryIsRefusedUpFrontSayingWhatToDo) {
  std::string error;
  // 8 GB of log with 4 GB free: refused, with both sizes and a way out.
  EXPECT_FALSE(internal::CheckLogFitsInMemory("big.csv", 8000000000ull, 4000000000ull, &error));
  EXPECT_TRUE(Has(error, "big.csv: the log is 8.00 GB")) << error;
  EXPECT_TRUE(Has(error, "needs about 13.60 GB")) << error;
  EXPECT_TRUE(Has(error, "4.00 GB is available")) << error;
  EXPECT_TRUE(Has(error, "Split it into shorter sessions")) << error;
  // Within the memory, or memory unknown: read.
  error.clear();
  EXPECT_TRUE(internal::CheckLogFitsInMemory("small.csv", 1000000, 4000000000ull, &error));
  EXPECT_TRUE(internal::CheckLogFitsInMemory("small.csv", 8000000000ull, 0, &error));
  EXPECT_TRUE(error.empty());
  // This machine reports its available memory.
  EXPECT_GT(internal::AvailableMemoryBytes(), 0u);
}

TEST(LogReaderLimits, BinaryAndGarbledBytesAreEscapedInMessages) {
  // A binary header: control bytes and bytes that are not UTF-8 as \xNN.
  std::string error =
      ParseError(std::string("\x7f"
                             "ELF\x02\x01,\xc3(,az\n",
                             13));
  EXPECT_TRUE(Has(error, "\\x7fELF\\x02\\x01")) << error;
  EXPECT_TRUE(Has(error, "\\xc3(")) << error;
  for (char c : error) {
    const unsigned char u = static_cast<unsigned char>(c);
    EXPECT_TRUE(u >= 0x20 && u < 0x7f) << "raw byte " << static_cast<int>(u) << " in " << error;
  }
  // Valid UTF-8 passes whole.
  error = ParseError(
      "t,ax,ay,\xc2\xb0"
      "C\n");
  EXPECT_TRUE(Has(error,
                  "\xc2\xb0"
                  "C"))
      << error;
  // A garbled cell, bounded.
  error = ParseError("t,ax,ay,az\n0,1,2,\x1b[2J" + std::string(100, 'x') + "\n");
  EXPECT_TRUE(Has(error, "'\\x1b[2Jxxx")) << error;
  EXPECT_TRUE(Has(error, "...'")) << error;
}

TEST(LogReaderLimits, MessagesNotReachedElsewhere) {
  EXPECT_TRUE(Has(ParseError("t,ax,ay,\"az\" x\n"), "mem.csv:1: unexpected text after a quoted"));
  LogReaderOptions gyro_file;
  gyro_file.gyro_path = "g.txt";
  EXPECT_TRUE(Has(ParseError("t,ax,ay,az,gx,gy,gz\n0,1,2,3,4,5,6\n", gyro_file),
                  "mem.csv:1: has gyroscope columns and gyro_path 'g.txt' is given too"));
  LogReaderOptions scaled;
  scaled.time_scale = 1e300;
  EXPECT_TRUE(Has(ParseError("t,ax,ay,az\n1e300,1,2,3\n", scaled),
                  "mem.csv:2: time 1e+300 times time_scale is not finite"));
  std::string error;
  EXPECT_FALSE(ParseImuLog("t,ax,ay,az\n", "mem.csv", LogReaderOptions(), nullptr, &error));
  EXPECT_EQ(error, "mem.csv: no log to read into");
  EXPECT_FALSE(ReadImuLog("x.csv", LogReaderOptions(), nullptr, &error));
  EXPECT_EQ(error, "x.csv: no log to read into");
  ImuLog bad;
  bad.t = {0.0, 0.0};
  bad.accel = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  EXPECT_FALSE(WriteImuLogCsv(bad, "/nonexistent/out.csv", &error));
  EXPECT_TRUE(Has(error,
                  "/nonexistent/out.csv: cannot write log: sample 1: time does not "
                  "increase"))
      << error;
}

// A batch unit over its time limit asks the reader to stop: it checks
// between lines (every 65536).
TEST(LogReaderLimits, ReadingStopsWhenCancelled) {
  std::string text = "t,ax,ay,az\n";
  for (int i = 0; i < 70000; ++i) text += std::to_string(i) + ",1,2,3\n";
  std::atomic<bool> cancel{true};
  internal::ScopedCancelFlag scope(&cancel);
  const std::string error = ParseError(text);
  EXPECT_TRUE(Has(error, "mem.csv:65536: reading was cancelled (time limit)")) << error;
}

}  // namespace
}  // namespace gravcal
