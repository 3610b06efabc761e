// Issue 32, "one reader": every text log, read whole (calibrate, the
// library's ReadImuLog, Python) or streamed (apply, ImuCsvStreamReader),
// goes through one checked line reader. Over one shared list of hostile logs
// (tests/hostile_logs/cases.tsv, also read by python/tests/test_hostile_logs.py)
// every reader gives the same one-line message, and the line-end and byte
// order mark variants of a real session give the same results.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "gravcal/io/imu_stream.h"
#include "gravcal/io/log_reader.h"
#include "test_util.h"

namespace gravcal {
namespace {

using testing_util::CliResult;
using testing_util::RunCli;
using testing_util::ScratchDir;
using testing_util::Slurp;

struct HostileLog {
  std::string file;
  std::string fragment;  // a part of the message after the file's name
};

std::string HostileDir() { return testing_util::SourceDir() + "/tests/hostile_logs"; }

std::vector<HostileLog> HostileLogs() {
  std::ifstream in(HostileDir() + "/cases.tsv");
  std::vector<HostileLog> cases;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    const size_t tab = line.find('\t');
    cases.push_back({line.substr(0, tab), tab == std::string::npos ? "" : line.substr(tab + 1)});
  }
  return cases;
}

// The message of `gravcal: error: <message>` in the CLI's standard error.
std::string CliError(const CliResult& r) {
  std::istringstream in(r.err);
  std::string message;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("gravcal: error: ", 0) == 0) message = line.substr(16);
  }
  return message;
}

// The error of reading `path` sample by sample ("" when it reads to the end).
std::string StreamError(const std::string& path) {
  ImuCsvStreamReader reader;
  std::string error;
  if (!reader.Open(path, &error)) return error;
  ImuSample sample;
  while (reader.Next(&sample, &error)) {
  }
  return error;
}

// A calibration with a scale and a bias only.
std::string WriteCalibration(const ScratchDir& scratch) {
  const nlohmann::json m = {{0.001, 0.0, 0.0}, {0.0, 0.002, 0.0}, {0.0, 0.0, 0.003}};
  const nlohmann::json j = {
      {"method", "twelve_position"},
      {"accel", {{"model", "scale"}, {"bias", {1.0, 2.0, 3.0}}, {"matrix", m}}},
      {"gravity", {{"value", 9.81}}}};
  return scratch.Write("calib.json", j.dump(2));
}

// The files in the scratch folder other than the CLI's captured output.
std::vector<std::string> LeftBehind(const ScratchDir& scratch, const std::string& keep) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(scratch.path())) {
    const std::string name = entry.path().filename().string();
    if (name != "cli_stdout.txt" && name != "cli_stderr.txt" && name != keep) names.push_back(name);
  }
  return names;
}

TEST(HostileLogs, EveryReaderRefusesWithTheSameMessage) {
  const std::vector<HostileLog> cases = HostileLogs();
  ASSERT_GE(cases.size(), 20u);
  const ScratchDir scratch;
  const std::string calib = WriteCalibration(scratch);
  for (const HostileLog& c : cases) {
    SCOPED_TRACE(c.file);
    const std::string path = HostileDir() + "/" + c.file;
    ImuLog log;
    std::string whole;
    EXPECT_FALSE(ReadImuLog(path, LogReaderOptions(), &log, &whole));
    EXPECT_NE(whole.find(path + (c.fragment.empty() ? ":" : c.fragment)), std::string::npos)
        << whole;
    EXPECT_EQ(whole.find('\n'), std::string::npos) << whole;
    EXPECT_EQ(StreamError(path), whole);

    const std::string out = scratch / "out.csv";
    CliResult r =
        RunCli({"apply", "--calibration", calib, "--input", path, "--output", out}, scratch);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(CliError(r), whole) << r.err;
    r = RunCli({"calibrate", "--input", path, "--output", scratch / "c.json"}, scratch);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(CliError(r), whole) << r.err;
    EXPECT_EQ(LeftBehind(scratch, "calib.json"), std::vector<std::string>());
  }
}

// A file without a line end after its first row, far larger than the
// memory apply may use: refused naming the line and its length, in bounded
// memory, with no temporary file left (today's main grew its buffer until
// bad_alloc, exit 134, and left the temporary behind).
TEST(HostileLogs, ALineWithoutEndIsRefusedInBoundedMemory) {
  const ScratchDir scratch;
  const std::string calib = WriteCalibration(scratch);
  const std::string out = scratch / "out.csv";
  const std::string script =
      scratch.Write("stream.sh",
                    "set -o pipefail\n(printf 't,ax,ay,az\\n0,1,2,3\\n'; head -c 300000000 "
                    "/dev/zero | tr '\\0' '7') | (ulimit -v 250000; exec " +
                        std::string(GRAVCAL_CLI_PATH) + " apply --calibration " + calib +
                        " --input - --output " + out + ") 2> " + (scratch / "err.txt") + "\n");
  EXPECT_NE(std::system(("bash " + script).c_str()), 0);
  const std::string err = Slurp(scratch / "err.txt");
  EXPECT_NE(err.find("gravcal: error: standard input:3: the line is 300000000 bytes long"),
            std::string::npos)
      << err;
  EXPECT_FALSE(testing_util::FileExists(out));
  EXPECT_EQ(LeftBehind(scratch, "calib.json").size(), 2u);  // stream.sh, err.txt
}

// The same session with other line ends, a byte order mark, comments, blank
// lines and no final line end: calibrate gives the same calibration and
// apply the same corrected log as for the plain file.
TEST(HostileLogs, LineEndVariantsGiveIdenticalResults) {
  const ScratchDir scratch;
  const std::string config = testing_util::SourceDir() + "/configs/twelve_position.yaml";
  CliResult r = RunCli(
      "simulate --config " + config + " --seed 5 --output-dir " + (scratch / "sim"), scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string plain = Slurp(scratch / "sim/raw.csv");
  ASSERT_GT(plain.size(), 1000u);
  auto replace_all = [](std::string s, const std::string& from, const std::string& to) {
    std::string out;
    size_t at = 0;
    for (size_t next; (next = s.find(from, at)) != std::string::npos; at = next + from.size()) {
      out += s.substr(at, next - at) + to;
    }
    return out + s.substr(at);
  };
  struct Variant {
    std::string name;
    std::string text;
  };
  std::string commented = plain;
  commented.insert(commented.find('\n') + 1, "# a comment\n\n   \n");
  commented.pop_back();  // no final line end
  const std::vector<Variant> variants = {
      {"bom.csv", "\xEF\xBB\xBF" + plain},
      {"crlf.csv", replace_all(plain, "\n", "\r\n")},
      {"cr.csv", "\xEF\xBB\xBF" + replace_all(plain, "\n", "\r")},
      {"commented.csv", commented},
  };
  auto run = [&](const std::string& input, const std::string& tag, std::string* calibration,
                 std::string* corrected) {
    const std::string calib = scratch / (tag + ".json");
    CliResult c = RunCli(
        "calibrate --config " + config + " --input " + input + " --output " + calib, scratch);
    ASSERT_EQ(c.exit_code, 0) << c.err;
    nlohmann::json j = nlohmann::json::parse(Slurp(calib));
    *calibration = j["accel"].dump() + j["positions"].dump();
    // apply with the plain file's calibration.
    const std::string out = scratch / (tag + "_corrected.csv");
    c = RunCli("apply --calibration " + (scratch / "plain.json") + " --input " + input +
                   " --output " + out,
               scratch);
    ASSERT_EQ(c.exit_code, 0) << c.err;
    *corrected = Slurp(out);
  };
  std::string plain_calibration, plain_corrected;
  run(scratch / "sim/raw.csv", "plain", &plain_calibration, &plain_corrected);
  ImuLog plain_log;
  std::string error;
  ASSERT_TRUE(ReadImuLog(scratch / "sim/raw.csv", LogReaderOptions(), &plain_log, &error));
  for (const Variant& v : variants) {
    SCOPED_TRACE(v.name);
    const std::string path = scratch.Write(v.name, v.text);
    ImuLog log;
    ASSERT_TRUE(ReadImuLog(path, LogReaderOptions(), &log, &error)) << error;
    EXPECT_EQ(log.t, plain_log.t);
    EXPECT_EQ(log.accel, plain_log.accel);
    EXPECT_EQ(StreamError(path), "");
    std::string calibration, corrected;
    run(path, v.name, &calibration, &corrected);
    EXPECT_EQ(calibration, plain_calibration);
    EXPECT_EQ(corrected, plain_corrected);
  }
}

// The streamed reader reads through a 1 MiB buffer: every alignment of a
// line end ("\r\n" split across the refill, a lone '\r' as the buffer's
// last byte) gives the samples the whole-file reader gives.
TEST(HostileLogs, StreamedLineEndsAcrossTheBufferMatchTheWholeReader) {
  const ScratchDir scratch;
  constexpr size_t kBuffer = size_t{1} << 20;
  for (const std::string end : {"\n", "\r\n", "\r"}) {
    for (size_t shift = 0; shift < 3; ++shift) {
      SCOPED_TRACE(testing::PrintToString(end) + " shift " + std::to_string(shift));
      std::string text = "t,ax,ay,az" + end;
      size_t rows = 0;
      while (text.size() < kBuffer - 200) {
        text += std::to_string(rows) + "," + std::to_string(rows % 977) + ",2,3" + end;
        ++rows;
      }
      // A comment line whose last byte is the buffer's byte kBuffer - shift:
      // "\r|\n" across the refill (shift 0), a lone '\r' as its last (1).
      text += "#" + std::string(kBuffer - shift - text.size() - end.size(), 'c') + end;
      for (size_t i = 0; i < 1000; ++i, ++rows) {
        text += std::to_string(rows) + "," + std::to_string(rows % 977) + ",2,3" + end;
      }
      const std::string path = scratch.Write("log.csv", text);
      ImuLog whole;
      std::string error;
      ASSERT_TRUE(ReadImuLog(path, LogReaderOptions(), &whole, &error)) << error;
      ASSERT_EQ(whole.size(), rows);
      ImuCsvStreamReader reader;
      ASSERT_TRUE(reader.Open(path, &error)) << error;
      ImuSample sample;
      size_t n = 0;
      while (reader.Next(&sample, &error)) {
        ASSERT_LT(n, whole.size());
        ASSERT_EQ(sample.t, whole.t[n]);
        ASSERT_EQ(sample.accel, whole.accel[n]);
        ++n;
      }
      EXPECT_EQ(error, "");
      EXPECT_EQ(n, rows);
    }
  }
}

// A `nan` temperature with a calibration that has a temperature term: the
// same error naming the line (today's main skipped the term silently).
TEST(HostileLogs, ANanTemperatureWithATemperatureTermNamesTheLine) {
  const ScratchDir scratch;
  nlohmann::json j = nlohmann::json::parse(Slurp(WriteCalibration(scratch)));
  j["effects"] = {{"reference_time", 0.0},
                  {"reference_temperature", 25.0},
                  {"accel_temperature_bias", {{"value", {0.01, 0.02, 0.03}}}}};
  const std::string calib = scratch.Write("calib.json", j.dump());
  const std::string path = HostileDir() + "/nan_temperature.csv";
  const CliResult r = RunCli(
      {"apply", "--calibration", calib, "--input", path, "--output", scratch / "out.csv"}, scratch);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(CliError(r), path + ":3: column 'temp': 'nan' is not finite") << r.err;
  EXPECT_EQ(LeftBehind(scratch, "calib.json"), std::vector<std::string>());
}

// Finite readings times a checked calibration can overflow: apply writes no
// inf, names the line and leaves no file.
TEST(HostileLogs, ACorrectedSampleThatOverflowsIsRefusedByLine) {
  const ScratchDir scratch;
  nlohmann::json j = nlohmann::json::parse(Slurp(WriteCalibration(scratch)));
  j["accel"]["matrix"] = {{1e100, 0.0, 0.0}, {0.0, 1e100, 0.0}, {0.0, 0.0, 1e100}};
  const std::string calib = scratch.Write("calib.json", j.dump());
  const std::string log = scratch.Write("raw.csv", "t,ax,ay,az\n0,1,2,3\n0.01,1e300,2,3\n");
  const CliResult r = RunCli(
      {"apply", "--calibration", calib, "--input", log, "--output", scratch / "out.csv"}, scratch);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(CliError(r), log +
                             ":3: the corrected sample is not finite (the reading times the "
                             "calibration overflows)")
      << r.err;
  EXPECT_FALSE(testing_util::FileExists(scratch / "out.csv"));
}

// apply streams every layout calibrate reads, with the same input keys: a
// whitespace file without a header (its first line is a row), metadata lines
// to skip, renamed columns, a sample rate for a log without time.
TEST(HostileLogs, ApplyStreamsOtherLayoutsAsCalibrateReadsThem) {
  const ScratchDir scratch;
  const std::string calib = WriteCalibration(scratch);
  struct Layout {
    std::string config;
    std::string text;
  };
  const std::vector<Layout> layouts = {
      {"format: whitespace\ncolumns: [t, ax, ay, az, extra]\n",
       "0 1 2 3 9\n0.5 4 5 6 9\n1 7 8 9 9\n"},
      {"skip_lines: 2\nrename: {ax: acc_x}\n",
       "Fs,2\nmeta\nt,acc_x,ay,az\r\n0,1,2,3\r\n0.5,4,5,6\r\n1,7,8,9\r\n"},
      {"sample_rate: 2\n", "ax,ay,az\n1,2,3\n4,5,6\n7,8,9"},
  };
  std::string first;
  for (size_t k = 0; k < layouts.size(); ++k) {
    SCOPED_TRACE(layouts[k].config);
    const std::string config = scratch.Write("layout.yaml", layouts[k].config);
    const std::string input = scratch.Write("in.txt", layouts[k].text);
    for (const std::string& via : {std::string("file"), std::string("-")}) {
      const std::string out = scratch / "out.csv";
      const std::string script = scratch.Write(
          "run.sh", std::string(GRAVCAL_CLI_PATH) + " apply --config " + config +
                        " --calibration " + calib + " --input " + (via == "-" ? "-" : input) +
                        " --output " + out + " < " + input + " 2> " + (scratch / "err.txt") + "\n");
      ASSERT_EQ(std::system(("bash " + script).c_str()), 0) << Slurp(scratch / "err.txt");
      ImuLog corrected;
      std::string error;
      ASSERT_TRUE(ReadImuLog(out, LogReaderOptions(), &corrected, &error)) << error;
      ASSERT_EQ(corrected.size(), 3u);
      EXPECT_EQ(corrected.t, std::vector<double>({0.0, 0.5, 1.0}));
      // M (v - b): diag(1e-3, 2e-3, 3e-3), b = (1, 2, 3).
      EXPECT_DOUBLE_EQ(corrected.accel[2].x(), 0.006);
      EXPECT_DOUBLE_EQ(corrected.accel[2].z(), 0.018);
      const std::string body = Slurp(out).substr(Slurp(out).find("\nt,") + 1);
      if (first.empty()) first = body;
      EXPECT_EQ(body, first);
    }
  }
}

}  // namespace
}  // namespace gravcal
