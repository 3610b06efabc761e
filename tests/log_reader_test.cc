#include "gravcal/io/log_reader.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "test_util.h"

namespace gravcal {
namespace {

using testing_util::FileExists;
using testing_util::Slurp;

// True when `text` contains `part`; gtest prints both on failure.
::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

// A fresh path in the test's temporary folder.
std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "log_reader_test_" + std::to_string(getpid()) + "_" + name;
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

ImuLog MakeLog(int n, bool gyro, bool temperature) {
  ImuLog log;
  for (int i = 0; i < n; ++i) {
    // Values with full 53-bit mantissas, and a few awkward ones.
    log.t.push_back(1e9 + i / 102.4 + std::sqrt(2.0) * 1e-7);
    log.accel.emplace_back(std::sin(i * 0.37) * 9.81, -1.0 / (i + 3.0), 1e-300 * (i + 1));
    if (gyro) log.gyro.emplace_back(std::cos(i * 1.1) * 1e5, -0.0, 4.9e-324 * (i % 3));
    if (temperature) log.temperature.push_back(25.0 + std::exp(-i * 0.1) / 3.0);
  }
  return log;
}

void ExpectSameBits(const ImuLog& a, const ImuLog& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.gyro.size(), b.gyro.size());
  ASSERT_EQ(a.temperature.size(), b.temperature.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(SameBits(a.t[i], b.t[i])) << i;
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(SameBits(a.accel[i][k], b.accel[i][k])) << i << " " << k;
      if (a.has_gyro()) {
        EXPECT_TRUE(SameBits(a.gyro[i][k], b.gyro[i][k])) << i << " " << k;
      }
    }
    if (a.has_temperature()) {
      EXPECT_TRUE(SameBits(a.temperature[i], b.temperature[i])) << i;
    }
  }
}

bool Parse(const std::string& text, const LogReaderOptions& options, ImuLog* log,
           std::string* error, const std::string& name = "mem.csv") {
  return ParseImuLog(text, name, options, log, error);
}

LogReaderOptions WhitespaceOptions(std::vector<std::string> columns) {
  LogReaderOptions options;
  options.format = LogFormat::kWhitespace;
  options.columns = std::move(columns);
  return options;
}

TEST(LogReader, FormatNamesRoundTrip) {
  for (LogFormat format : {LogFormat::kCsv, LogFormat::kWhitespace}) {
    LogFormat parsed;
    ASSERT_TRUE(FromString(ToString(format), &parsed));
    EXPECT_EQ(parsed, format);
  }
  LogFormat parsed = LogFormat::kWhitespace;
  EXPECT_FALSE(FromString("tsv", &parsed));
  EXPECT_EQ(parsed, LogFormat::kWhitespace);
  EXPECT_STREQ(ToString(LogFormat::kCsv), "csv");
  EXPECT_STREQ(ToString(LogFormat::kWhitespace), "whitespace");
}

TEST(LogReader, WriteThenReadIsBitExact) {
  for (bool gyro : {false, true}) {
    for (bool temperature : {false, true}) {
      const ImuLog log = MakeLog(200, gyro, temperature);
      const std::string path = TempPath("round_trip.csv");
      std::string error;
      ASSERT_TRUE(WriteImuLogCsv(log, path, &error)) << error;
      ImuLog read;
      ASSERT_TRUE(ReadImuLog(path, LogReaderOptions(), &read, &error)) << error;
      EXPECT_EQ(read.source, path);
      ExpectSameBits(log, read);
      const std::string text = Slurp(path);
      std::string header = "t,ax,ay,az";
      if (gyro) header += ",gx,gy,gz";
      if (temperature) header += ",temp";
      EXPECT_EQ(text.substr(0, header.size() + 1), header + "\n");
      std::remove(path.c_str());
    }
  }
}

TEST(LogReader, WriteRejectsInvalidLog) {
  ImuLog log = MakeLog(5, true, false);
  log.accel[2].y() = std::numeric_limits<double>::quiet_NaN();
  const std::string path = TempPath("invalid.csv");
  std::string error;
  EXPECT_FALSE(WriteImuLogCsv(log, path, &error));
  EXPECT_TRUE(Contains(error, path));
  EXPECT_FALSE(FileExists(path));
}

TEST(LogReader, SkipsCommentsBlankLinesAndCrlf) {
  const std::string text =
      "# recorded by hand\r\n"
      "\r\n"
      "t,ax,ay,az\r\n"
      "  # indented comment\r\n"
      "0.0,1,2,3\r\n"
      "   \t \r\n"
      "0.5, +4 ,5e0,\t-6\r\n"
      "\n"
      "1.0,7,8,9";  // No final newline.
  ImuLog log;
  std::string error;
  ASSERT_TRUE(Parse(text, LogReaderOptions(), &log, &error)) << error;
  ASSERT_EQ(log.size(), 3u);
  EXPECT_FALSE(log.has_gyro());
  EXPECT_FALSE(log.has_temperature());
  EXPECT_EQ(log.t[1], 0.5);
  EXPECT_EQ(log.accel[1], Eigen::Vector3d(4, 5, -6));
  EXPECT_EQ(log.accel[2], Eigen::Vector3d(7, 8, 9));
  EXPECT_EQ(log.source, "mem.csv");
}

TEST(LogReader, IgnoresUnknownColumnsAndReadsOptionalOnes) {
  const std::string text =
      "temp,label,gz,t,ax,ay,az,gx,gy,extra\n"
      "21.5,abc,0.3,0,1,2,3,0.1,0.2,x\n"
      "21.6,def,0.6,0.01,4,5,6,0.4,0.5,y\n";
  ImuLog log;
  std::string error;
  ASSERT_TRUE(Parse(text, LogReaderOptions(), &log, &error)) << error;
  ASSERT_EQ(log.size(), 2u);
  ASSERT_TRUE(log.has_gyro());
  ASSERT_TRUE(log.has_temperature());
  EXPECT_EQ(log.gyro[1], Eigen::Vector3d(0.4, 0.5, 0.6));
  EXPECT_EQ(log.temperature[0], 21.5);
  EXPECT_EQ(log.accel[0], Eigen::Vector3d(1, 2, 3));
  std::string why;
  EXPECT_TRUE(log.Validate(&why)) << why;
}

TEST(LogReader, RenameSkipLinesAndSampleRate) {
  const std::string text =
      "Fs,100\n"
      "Logging Type,0\n"
      "acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n"
      "1,2,3,4,5,6\n"
      "7,8,9,10,11,12\n"
      "13,14,15,16,17,18\n";
  LogReaderOptions options;
  options.skip_lines = 2;
  options.sample_rate = 100.0;
  options.rename = {{"ax", "acc_x"}, {"ay", "acc_y"}, {"az", "acc_z"},
                    {"gx", "gyr_x"}, {"gy", "gyr_y"}, {"gz", "gyr_z"}};
  ImuLog log;
  std::string error;
  ASSERT_TRUE(Parse(text, options, &log, &error)) << error;
  ASSERT_EQ(log.size(), 3u);
  EXPECT_EQ(log.t[0], 0.0);
  EXPECT_EQ(log.t[2], 2.0 / 100.0);
  EXPECT_EQ(log.accel[2], Eigen::Vector3d(13, 14, 15));
  EXPECT_EQ(log.gyro[1], Eigen::Vector3d(10, 11, 12));
}

TEST(LogReader, SampleCounterAsTime) {
  const std::string text = "n_samples,ax,ay,az\n0,1,1,1\n1,1,1,1\n2,1,1,1\n";
  LogReaderOptions options;
  options.rename = {{"t", "n_samples"}};
  options.time_scale = 1.0 / 102.4;
  ImuLog log;
  std::string error;
  ASSERT_TRUE(Parse(text, options, &log, &error)) << error;
  ASSERT_EQ(log.size(), 3u);
  EXPECT_DOUBLE_EQ(log.t[2], 2.0 / 102.4);
}

TEST(LogReader, CsvColumnsReplaceTheHeader) {
  // The header row is still there; `columns` names the fields instead.
  const std::string text = "A,B,C,D\n0,1,2,3\n1,4,5,6\n";
  LogReaderOptions options;
  options.columns = {"t", "ax", "ay", "az"};
  ImuLog log;
  std::string error;
  ASSERT_TRUE(Parse(text, options, &log, &error)) << error;
  ASSERT_EQ(log.size(), 2u);
  EXPECT_EQ(log.accel[1], Eigen::Vector3d(4, 5, 6));
}

TEST(LogReader, WhitespaceWithTrailingSpacesAndTabs) {
  const std::string text =
      "# t ax ay az junk\n"
      "0.0 1 2 3 q \n"
      "\t0.1\t4  5 6\tr\t\r\n"
      "0.2 7 8 9 s";
  ImuLog log;
  std::string error;
  ASSERT_TRUE(Parse(text, WhitespaceOptions({"t", "ax", "ay", "az", "junk"}), &log, &error))
      << error;
  ASSERT_EQ(log.size(), 3u);
  EXPECT_EQ(log.accel[1], Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(log.t[2], 0.2);
}

TEST(LogReader, WhitespaceWithGyroFile) {
  const std::string accel_path = TempPath("accel.txt");
  const std::string gyro_path = TempPath("gyro.txt");
  WriteText(accel_path, "1.0 1 2 3\n1.1 4 5 6\n1.2 7 8 9\n");
  WriteText(gyro_path, "# gyro\n1.0 0.1 0.2 0.3\n1.1 0.4 0.5 0.6\n1.2 0.7 0.8 0.9\n");
  LogReaderOptions options = WhitespaceOptions({"t", "ax", "ay", "az"});
  options.gyro_path = gyro_path;
  ImuLog log;
  std::string error;
  ASSERT_TRUE(ReadImuLog(accel_path, options, &log, &error)) << error;
  ASSERT_EQ(log.size(), 3u);
  ASSERT_TRUE(log.has_gyro());
  EXPECT_EQ(log.gyro[2], Eigen::Vector3d(0.7, 0.8, 0.9));

  // A different timestamp.
  WriteText(gyro_path, "1.0 0.1 0.2 0.3\n1.1 0.4 0.5 0.6\n1.25 0.7 0.8 0.9\n");
  const ImuLog before = log;
  EXPECT_FALSE(ReadImuLog(accel_path, options, &log, &error));
  EXPECT_TRUE(Contains(error, gyro_path + ":3:"));
  ExpectSameBits(before, log);

  // Fewer rows.
  WriteText(gyro_path, "1.0 0.1 0.2 0.3\n1.1 0.4 0.5 0.6\n");
  EXPECT_FALSE(ReadImuLog(accel_path, options, &log, &error));
  EXPECT_TRUE(Contains(error, gyro_path + ":2:"));
  EXPECT_TRUE(Contains(error, "ends after 2 samples"));

  // More rows.
  WriteText(gyro_path, "1.0 0 0 0\n1.1 0 0 0\n1.2 0 0 0\n1.3 0 0 0\n");
  EXPECT_FALSE(ReadImuLog(accel_path, options, &log, &error));
  EXPECT_TRUE(Contains(error, gyro_path + ":4:"));

  // A gyroscope file without gz.
  options.gyro_columns = {"t", "gx", "gy", "gq"};
  WriteText(gyro_path, "1.0 0 0 0\n1.1 0 0 0\n1.2 0 0 0\n");
  EXPECT_FALSE(ReadImuLog(accel_path, options, &log, &error));
  EXPECT_TRUE(Contains(error, gyro_path + ":1:"));
  EXPECT_TRUE(Contains(error, "'gz'"));

  // A missing gyroscope file.
  options.gyro_columns = {"t", "gx", "gy", "gz"};
  options.gyro_path = TempPath("no_such_gyro.txt");
  EXPECT_FALSE(ReadImuLog(accel_path, options, &log, &error));
  EXPECT_TRUE(Contains(error, options.gyro_path + ": cannot open: "));
  std::remove(accel_path.c_str());
  std::remove(gyro_path.c_str());
}

struct BadCase {
  const char* label;
  std::string text;
  LogReaderOptions options;
  // Each must appear in the message.
  std::vector<std::string> expected;
};

TEST(LogReader, BadInputNamesFileLineAndColumn) {
  LogReaderOptions renamed;
  renamed.rename = {{"ay", "acc_y"}};
  LogReaderOptions with_rate;
  with_rate.sample_rate = 10.0;
  const std::vector<BadCase> cases = {
      {"missing column", "t,ax,az\n0,1,2\n", {}, {"mem.csv:1:", "'ay'", "t, ax, az"}},
      {"missing renamed column",
       "# c\nt,ax,ay,az\n0,1,2,3\n",
       renamed,
       {"mem.csv:2:", "'acc_y'", "t, ax, ay, az"}},
      {"not a number", "t,ax,ay,az\n0,1,2,3\n1,1,abc,3\n", {}, {"mem.csv:3:", "'ay'", "'abc'"}},
      {"renamed not a number",
       "t,ax,acc_y,az\n0,1,2x,3\n",
       renamed,
       {"mem.csv:2:", "'acc_y'", "'2x'"}},
      {"empty cell", "t,ax,ay,az\n0,1,,3\n", {}, {"mem.csv:2:", "'ay'", "empty"}},
      {"nan", "t,ax,ay,az\n0,1,2,3\n1,nan,2,3\n", {}, {"mem.csv:3:", "'ax'", "not finite"}},
      {"inf", "t,ax,ay,az\n0,1,2,-inf\n", {}, {"mem.csv:2:", "'az'", "not finite"}},
      {"out of range", "t,ax,ay,az\n0,1e999,2,3\n", {}, {"mem.csv:2:", "'ax'", "out of range"}},
      {"time goes back",
       "t,ax,ay,az\n0,1,2,3\n1,1,2,3\n0.5,1,2,3\n",
       {},
       {"mem.csv:4:", "does not increase"}},
      {"time repeats", "t,ax,ay,az\n0,1,2,3\n0,1,2,3\n", {}, {"mem.csv:3:", "does not increase"}},
      {"empty file", "", {}, {"mem.csv: no samples"}},
      {"header only", "t,ax,ay,az\n\n# nothing\n", {}, {"mem.csv: no samples"}},
      {"too many fields", "t,ax,ay,az\n0,1,2,3,4\n", {}, {"mem.csv:2:", "5 fields, expected 4"}},
      {"too few fields", "t,ax,ay,az\n0,1,2,3\n1,2,3\n", {}, {"mem.csv:3:", "3 fields"}},
      {"partial gyroscope",
       "t,ax,ay,az,gx,gy\n0,1,2,3,4,5\n",
       {},
       {"mem.csv:1:", "'gz'", "gx, gy"}},
      {"no time", "ax,ay,az\n1,2,3\n", {}, {"mem.csv:1:", "no column 't'", "sample_rate"}},
      {"duplicate column", "t,ax,ay,az,ax\n0,1,2,3,4\n", {}, {"mem.csv:1:", "'ax'", "twice"}},
      {"no header row",
       "0,1,2,3\n1,1,2,3\n",
       {},
       {"mem.csv:1:", "no column 'ax'", "no header row", "4 columns"}},
      {"no header row, space separated",
       "# t ax ay az\n0 1.5 -2e-3 3\n1 1 2 3\n",
       {},
       {"mem.csv:2:", "no header row", "4 columns", "--format whitespace"}},
      {"whitespace field count",
       "0 1 2 3\n1 1 2\n",
       WhitespaceOptions({"t", "ax", "ay", "az"}),
       {"mem.csv:2:", "3 fields, expected 4"}},
      {"whitespace not a number",
       "0 1 2 3\n1 1 2 z3\n",
       WhitespaceOptions({"t", "ax", "ay", "az"}),
       {"mem.csv:2:", "'az'", "'z3'"}},
      {"whitespace missing column",
       "0 1 2 3\n",
       WhitespaceOptions({"t", "ax", "ay", "bz"}),
       {"mem.csv:1:", "'az'", "t, ax, ay, bz"}},
      {"invalid options", "t,ax,ay,az\n0,1,2,3\n", WhitespaceOptions({}), {"mem.csv:", "columns"}},
      {"time with rate still checked",
       "t,ax,ay,az\n1,1,2,3\n1,1,2,3\n",
       with_rate,
       {"mem.csv:3:", "does not increase"}},
  };
  for (const BadCase& c : cases) {
    ImuLog log = MakeLog(3, true, true);
    log.source = "untouched";
    const ImuLog before = log;
    std::string error;
    EXPECT_FALSE(Parse(c.text, c.options, &log, &error)) << c.label;
    for (const std::string& part : c.expected) {
      EXPECT_TRUE(Contains(error, part)) << c.label;
    }
    EXPECT_EQ(error.find('\n'), std::string::npos) << c.label << ": " << error;
    EXPECT_EQ(log.source, "untouched") << c.label;
    ExpectSameBits(before, log);
  }
}

// With `columns` given, a CSV file's first line is its header row and is
// skipped, unless it is numbers: then it is the first sample, not lost.
TEST(LogReader, ColumnsGivenKeepAFirstLineOfNumbers) {
  LogReaderOptions options;
  options.columns = {"t", "ax", "ay", "az"};
  ImuLog log;
  std::string error;
  ASSERT_TRUE(Parse("0,1,2,3\n0.1,4,5,6\n", options, &log, &error)) << error;
  ASSERT_EQ(log.size(), 2u);
  EXPECT_EQ(log.accel[0].x(), 1.0);
  ASSERT_TRUE(Parse("time,a,b,c\n0,1,2,3\n0.1,4,5,6\n", options, &log, &error)) << error;
  ASSERT_EQ(log.size(), 2u) << "a header row of names is still skipped";
  EXPECT_EQ(log.accel[0].x(), 1.0);
}

TEST(LogReader, UnreadableFileNamesTheFile) {
  const std::string path = TempPath("does_not_exist.csv");
  ImuLog log;
  std::string error;
  EXPECT_FALSE(ReadImuLog(path, LogReaderOptions(), &log, &error));
  EXPECT_EQ(error, path + ": cannot open: " + std::strerror(ENOENT));
  EXPECT_TRUE(log.t.empty());
}

TEST(LogReader, ErrorsFromFilesNameTheFile) {
  const std::string path = TempPath("bad.csv");
  WriteText(path, "t,ax,ay,az\r\n0,1,2,3\r\n1,1,oops,3\r\n");
  ImuLog log;
  std::string error;
  EXPECT_FALSE(ReadImuLog(path, LogReaderOptions(), &log, &error));
  EXPECT_EQ(error, path + ":3: column 'ay': 'oops' is not a number");
  std::remove(path.c_str());
}

TEST(LogReader, OptionsValidity) {
  std::string error;
  EXPECT_TRUE(LogReaderOptions().IsValid(&error)) << error;
  auto invalid = [](auto change, const std::string& expected) {
    LogReaderOptions options;
    change(&options);
    std::string why;
    EXPECT_FALSE(options.IsValid(&why)) << expected;
    EXPECT_TRUE(Contains(why, expected));
  };
  invalid([](LogReaderOptions* o) { o->skip_lines = -1; }, "skip_lines");
  invalid([](LogReaderOptions* o) { o->sample_rate = -1; }, "sample_rate");
  invalid([](LogReaderOptions* o) { o->sample_rate = std::nan(""); }, "sample_rate");
  invalid([](LogReaderOptions* o) { o->time_scale = 0; }, "time_scale");
  invalid([](LogReaderOptions* o) { o->time_scale = INFINITY; }, "time_scale");
  invalid([](LogReaderOptions* o) { o->format = LogFormat::kWhitespace; }, "columns");
  invalid([](LogReaderOptions* o) { o->columns = {"t", "ax", "t"}; }, "'t' twice");
  invalid([](LogReaderOptions* o) { o->columns = {"t", ""}; }, "empty");
  invalid([](LogReaderOptions* o) { o->rename = {{"accel_x", "ax"}}; }, "'accel_x'");
  invalid([](LogReaderOptions* o) { o->rename = {{"ax", ""}}; }, "'ax'");
  invalid([](LogReaderOptions* o) { o->rename = {{"ax", "t"}}; }, "column 't'");
  invalid(
      [](LogReaderOptions* o) {
        o->gyro_path = "g.txt";
        o->gyro_columns.clear();
      },
      "gyro_columns");
  LogReaderOptions swapped;
  swapped.rename = {{"ax", "ay"}, {"ay", "ax"}};
  EXPECT_TRUE(swapped.IsValid(&error)) << error;
}

TEST(LogReader, WriteFileAtomically) {
  const std::string path = TempPath("atomic.txt");
  std::string error;
  ASSERT_TRUE(WriteFileAtomically(path, "first", &error)) << error;
  ASSERT_TRUE(WriteFileAtomically(path, "second\n", &error)) << error;
  EXPECT_EQ(Slurp(path), "second\n");
  EXPECT_FALSE(FileExists(path + ".tmp." + std::to_string(getpid())));
  std::remove(path.c_str());

  const std::string bad = TempPath("no_such_dir") + "/x.txt";
  EXPECT_FALSE(WriteFileAtomically(bad, "x", &error));
  EXPECT_TRUE(Contains(error, bad));
  EXPECT_EQ(error.find('\n'), std::string::npos);

  // Renaming onto a directory fails; the temporary file must not remain.
  const std::string dir = TempPath("a_dir");
  ASSERT_EQ(mkdir(dir.c_str(), 0755), 0);
  // Make the directory non-empty so rename cannot replace it.
  WriteText(dir + "/keep", "k");
  EXPECT_FALSE(WriteFileAtomically(dir, "x", &error));
  EXPECT_TRUE(Contains(error, dir));
  EXPECT_FALSE(FileExists(dir + ".tmp." + std::to_string(getpid())));
  std::remove((dir + "/keep").c_str());
  rmdir(dir.c_str());
}

// Real recordings (../shared/data/real); skipped when absent.

TEST(LogReader, ReadsFerrarisNilsPodSession) {
  const std::string dir = testing_util::RealDataDir();
  if (dir.empty()) GTEST_SKIP() << "no real data";
  LogReaderOptions options;
  options.rename = {{"t", "n_samples"}, {"ax", "acc_x"}, {"ay", "acc_y"}, {"az", "acc_z"},
                    {"gx", "gyr_x"},    {"gy", "gyr_y"}, {"gz", "gyr_z"}};
  options.time_scale = 1.0 / 102.4;
  ImuLog log;
  std::string error;
  ASSERT_TRUE(ReadImuLog(dir + "/ferraris_nilspod/session.csv", options, &log, &error)) << error;
  EXPECT_EQ(log.size(), 10376u);
  ASSERT_TRUE(log.has_gyro());
  EXPECT_NEAR(log.t.back(), 10375 / 102.4, 1e-9);
  // First row: 0,-0.6103515625,-0.30517578125,0.06103515625,10.332114257812501,...
  EXPECT_EQ(log.accel[0].x(), 10.332114257812501);
  EXPECT_EQ(log.gyro[0].x(), -0.6103515625);
  EXPECT_NEAR(log.accel[0].norm(), 9.81, 0.7);
  EXPECT_TRUE(log.Validate(&error)) << error;
}

TEST(LogReader, ReadsMpu6050TenPoseSession) {
  const std::string dir = testing_util::RealDataDir();
  if (dir.empty()) GTEST_SKIP() << "no real data";
  LogReaderOptions options;
  options.skip_lines = 4;
  options.sample_rate = 100.0;
  ImuLog log;
  std::string error;
  ASSERT_TRUE(ReadImuLog(dir + "/mpu6050_ten_pose/session.csv", options, &log, &error)) << error;
  // 10250 lines: four metadata lines, the header and 10245 rows.
  EXPECT_EQ(log.size(), 10245u);
  ASSERT_TRUE(log.has_gyro());
  EXPECT_EQ(log.accel[0], Eigen::Vector3d(-12, -812, 15032));
  EXPECT_EQ(log.gyro[0], Eigen::Vector3d(-447, 156, -86));
  EXPECT_DOUBLE_EQ(log.t.back(), 10244 / 100.0);
  EXPECT_TRUE(log.Validate(&error)) << error;
}

TEST(LogReader, ReadsAhrsStaticPoses) {
  const std::string dir = testing_util::RealDataDir();
  if (dir.empty()) GTEST_SKIP() << "no real data";
  const LogReaderOptions options = WhitespaceOptions(
      {"t", "ax", "ay", "az", "gx", "gy", "gz", "mx", "my", "mz", "qx", "qy", "qz", "qw"});
  ImuLog log;
  std::string error;
  ASSERT_TRUE(ReadImuLog(dir + "/ahrs_static_poses/imu_good1.txt", options, &log, &error)) << error;
  EXPECT_EQ(log.size(), 6566u);
  ASSERT_TRUE(log.has_gyro());
  EXPECT_EQ(log.t[0], 1535630275.916451);
  EXPECT_EQ(log.accel[0], Eigen::Vector3d(0.06808426231146, -0.04261315613985, -9.42799282074));
  EXPECT_NEAR(log.t.back() - log.t.front(), 65.65, 0.5);
  EXPECT_TRUE(log.Validate(&error)) << error;
}

// Integer cells take a fast path; every value must equal from_chars's.
TEST(LogReader, IntegerCellsReadAsFromCharsWould) {
  const std::vector<std::string> cells = {
      "0",    "-0",   "7",     "007", "-16384", "32767", "123456789012345", "1234567890123456789",
      "12.5", "12e3", "-12E-1"};
  std::string text = "t,ax,ay,az\n";
  for (size_t i = 0; i < cells.size(); ++i) {
    text += std::to_string(i) + "," + cells[i] + ",1,-1\n";
  }
  ImuLog log;
  std::string error;
  ASSERT_TRUE(ParseImuLog(text, "ints.csv", LogReaderOptions(), &log, &error)) << error;
  ASSERT_EQ(log.size(), cells.size());
  for (size_t i = 0; i < cells.size(); ++i) {
    double expected = 0.0;
    std::from_chars(cells[i].data(), cells[i].data() + cells[i].size(), expected);
    EXPECT_EQ(std::memcmp(&log.accel[i].x(), &expected, sizeof(double)), 0) << cells[i];
  }
  EXPECT_TRUE(std::signbit(log.accel[1].x()));
  EXPECT_FALSE(ParseImuLog("t,ax,ay,az\n0,12x,1,1\n", "bad.csv", LogReaderOptions(), &log, &error));
  EXPECT_NE(error.find("bad.csv:2"), std::string::npos) << error;
}

// The header row goes through the one CSV tokeniser (io/csv_table.h): quoted
// names, blanks around them, and an unclosed quote reported.
TEST(LogReader, HeaderUsesTheCsvTokeniser) {
  ImuLog log;
  std::string error;
  ASSERT_TRUE(ParseImuLog(" \"t\" , ax,\"ay\",az \n0,1,2,3\n1,1,2,3\n", "quoted.csv",
                          LogReaderOptions(), &log, &error))
      << error;
  ASSERT_EQ(log.size(), 2u);
  EXPECT_EQ(log.accel[1].z(), 3.0);
  EXPECT_FALSE(
      ParseImuLog("t,ax,\"ay,az\n0,1,2,3\n", "open.csv", LogReaderOptions(), &log, &error));
  EXPECT_EQ(error, "open.csv:1: the quoted field is not closed");
}

}  // namespace
}  // namespace gravcal
