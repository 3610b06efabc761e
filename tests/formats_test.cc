// The log formats gravcal recognises without flags (issue 19): one simulated
// session written as the contract CSV, as EuRoC CSV, as rosbag2 .db3, as ROS 1
// bags by the ROS project's own rosbag library (uncompressed, bz2, lz4) and as
// MCAP by the @mcap/core writer (plain, chunked, zstd, lz4) gives the same
// calibration JSON as the contract CSV, time fields apart. Broken files of
// each kind are refused with one line naming the file, exit 1, no output.
//
// The writers are independent of gravcal: tests/formats/write_formats.py
// (Python sqlite3 with CDR serialised there; Debian python3-rosbag) and
// tests/formats/write_mcap.mjs (Node with @mcap/core installed by .ci/run into
// <build>/npm_formats). A test whose writer is absent skips and says why.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/io/recording.h"

namespace gravcal {
namespace {

using testing_util::FileExists;
using testing_util::RunCli;
using testing_util::ScratchDir;
using testing_util::Slurp;

const std::string kConfig = std::string(GRAVCAL_SOURCE_DIR) + "/configs/twelve_position_gyro.yaml";

// The interpreter that has Debian's python3-rosbag (not a pyenv shim).
const char* kPython = "/usr/bin/python3";

std::string NpmModules() {
  return std::filesystem::path(GRAVCAL_CLI_PATH).parent_path().string() +
         "/npm_formats/node_modules";
}

// Drops the keys that differ between any two runs (time), as
// scripts/golden_outputs.sh does.
nlohmann::json StripTimes(const nlohmann::json& j) {
  if (j.is_object()) {
    nlohmann::json out = nlohmann::json::object();
    for (auto it = j.begin(); it != j.end(); ++it) {
      const std::string& k = it.key();
      if (k.size() >= 6 && k.compare(k.size() - 6, 6, "time_s") == 0) continue;
      if (k.find("_seconds") != std::string::npos || k == "message") continue;
      // The input file's name and content hash: a different file by design.
      if (k == "provenance") continue;
      out[k] = StripTimes(it.value());
    }
    return out;
  }
  if (j.is_array()) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& v : j) out.push_back(StripTimes(v));
    return out;
  }
  return j;
}

// What the suite's files are made from, as text: the tool (its size and
// modification time), the writers' and the config's modification times, and
// whether the MCAP writer is installed. Files written from the same sources
// are the same files.
std::string SourcesKey() {
  namespace fs = std::filesystem;
  std::string key;
  for (const std::string& path :
       {std::string(GRAVCAL_CLI_PATH),
        std::string(GRAVCAL_SOURCE_DIR) + "/tests/formats/write_formats.py",
        std::string(GRAVCAL_SOURCE_DIR) + "/tests/formats/write_mcap.mjs", kConfig}) {
    std::error_code ec;
    const auto size = fs::file_size(path, ec);
    const auto time = fs::last_write_time(path, ec);
    key += path + ":" + std::to_string(ec ? 0 : size) + ":" +
           std::to_string(ec ? 0 : time.time_since_epoch().count()) + ";";
  }
  key += FileExists(NpmModules() + "/@mcap/core") ? "mcap" : "no-mcap";
  return key;
}

// <build>/formats_cache/<hash of SourcesKey()>: the suite's input files and
// the contract CSV's calibration, kept once they are written. ctest starts
// every test in its own process, so without it each of them simulated the
// session and ran both writers again (about 4 s of a test's 5).
std::string CacheDir() {
  char hash[32];
  std::snprintf(hash, sizeof(hash), "%016zx", std::hash<std::string>()(SourcesKey()));
  return std::filesystem::path(GRAVCAL_CLI_PATH).parent_path().string() + "/formats_cache/" + hash;
}

// The session in every format, written once per build (CacheDir) and copied
// into the suite's scratch folder, where the tests write their outputs.
class Formats : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    namespace fs = std::filesystem;
    scratch_ = new ScratchDir();
    const ScratchDir& s = *scratch_;
    const std::string cache = CacheDir();
    std::error_code ec;
    if (fs::is_directory(cache, ec)) {
      fs::copy(cache, s.path(), fs::copy_options::recursive | fs::copy_options::overwrite_existing,
               ec);
      ASSERT_FALSE(ec) << cache << ": " << ec.message();
    } else {
      WriteEveryFormat(s);
      if (HasFatalFailure()) return;
      // Published whole or not at all: a copy renamed into place. A process
      // that loses the race to another writer drops its copy; the files of
      // an earlier build's tool are removed.
      const fs::path root = fs::path(cache).parent_path();
      const std::string staging = cache + ".staging." + std::to_string(getpid());
      fs::create_directories(root, ec);
      fs::copy(s.path(), staging, fs::copy_options::recursive, ec);
      if (!ec) fs::rename(staging, cache, ec);
      if (ec) fs::remove_all(staging, ec);
      for (const fs::directory_entry& e : fs::directory_iterator(root, ec)) {
        const std::string name = e.path().filename().string();
        if (name.size() == 16 && e.path() != fs::path(cache)) fs::remove_all(e.path(), ec);
      }
    }
    reference_ = new nlohmann::json(StripTimes(nlohmann::json::parse(Slurp(s / "contract.json"))));
  }

  // Simulates the session into `s` and writes it in every format, with the
  // contract CSV's calibration beside it (contract.json).
  static void WriteEveryFormat(const ScratchDir& s) {
    const auto simulated =
        RunCli({"simulate", "--config", kConfig, "--seed", "3", "--output-dir", s / "sim"}, s);
    ASSERT_EQ(simulated.exit_code, 0) << simulated.err;
    const std::string write = std::string(kPython) + " " + GRAVCAL_SOURCE_DIR +
                              "/tests/formats/write_formats.py " + (s / "sim/raw.csv") + " " +
                              s.path();
    ASSERT_EQ(std::system(write.c_str()), 0) << write;
    if (FileExists(NpmModules() + "/@mcap/core")) {
      const std::string mcap = std::string("node ") + GRAVCAL_SOURCE_DIR +
                               "/tests/formats/write_mcap.mjs " + NpmModules() + " " +
                               (s / "euroc.csv") + " " + s.path();
      ASSERT_EQ(std::system(mcap.c_str()), 0) << mcap;
    }
    const auto reference = RunCli({"calibrate", "--input", s / "contract.csv", "--config", kConfig,
                                   "--output", s / "contract.json"},
                                  s);
    ASSERT_EQ(reference.exit_code, 0) << reference.err;
  }
  static void TearDownTestSuite() {
    delete reference_;
    delete scratch_;
  }

  // Calibrates `file` (in the scratch folder) and compares with the CSV's.
  void ExpectSameCalibration(const std::string& file, const std::vector<std::string>& extra = {}) {
    const ScratchDir& s = *scratch_;
    ASSERT_TRUE(reference_ != nullptr);
    std::vector<std::string> args = {
        "calibrate", "--input", s / file, "--config", kConfig, "--output", s / (file + ".json")};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = RunCli(args, s);
    ASSERT_EQ(r.exit_code, 0) << file << ": " << r.err;
    const nlohmann::json got = StripTimes(nlohmann::json::parse(Slurp(s / (file + ".json"))));
    EXPECT_EQ(got, *reference_) << file << " differs from contract.csv:\n"
                                << nlohmann::json::diff(*reference_, got).dump(1);
  }

  static bool Have(const std::string& file) { return FileExists(*scratch_ / file); }

  static ScratchDir* scratch_;
  static nlohmann::json* reference_;
};

ScratchDir* Formats::scratch_ = nullptr;
nlohmann::json* Formats::reference_ = nullptr;

TEST_F(Formats, EurocCsvGivesTheSameCalibration) { ExpectSameCalibration("euroc.csv"); }

TEST_F(Formats, Rosbag2SqliteGivesTheSameCalibration) {
  ExpectSameCalibration("session.db3");
  ExpectSameCalibration("two_imus.db3", {"--topic", "/imu1"});
}

TEST_F(Formats, Ros1BagsGiveTheSameCalibration) {
  if (!Have("ros1_none.bag")) GTEST_SKIP() << Slurp(*scratch_ / "ros1_absent.txt");
  for (const char* bag : {"ros1_none.bag", "ros1_bz2.bag", "ros1_lz4.bag"}) {
    ExpectSameCalibration(bag);
  }
}

TEST_F(Formats, McapGivesTheSameCalibration) {
  if (!Have("mcap_plain.mcap")) {
    GTEST_SKIP() << "@mcap/core is not installed in " << NpmModules()
                 << " (npm install --prefix <build>/npm_formats @mcap/core)";
  }
  for (const char* mcap :
       {"mcap_plain.mcap", "mcap_chunked.mcap", "mcap_zstd.mcap", "mcap_lz4.mcap"}) {
    ExpectSameCalibration(mcap);
  }
}

// The reader gives the same samples, bit for bit, as the contract CSV.
TEST_F(Formats, SamplesAreIdenticalToTheCsv) {
  ImuLog csv;
  std::string error;
  ASSERT_TRUE(ReadImuLog(*scratch_ / "contract.csv", LogReaderOptions(), &csv, &error)) << error;
  std::vector<std::string> files = {"euroc.csv", "session.db3"};
  for (const char* f : {"ros1_lz4.bag", "mcap_zstd.mcap", "mcap_lz4.mcap"}) {
    if (Have(f)) files.push_back(f);
  }
  for (const std::string& f : files) {
    ImuLog log;
    ASSERT_TRUE(ReadImuLog(*scratch_ / f, LogReaderOptions(), &log, &error)) << error;
    EXPECT_EQ(log.t, csv.t) << f;
    EXPECT_EQ(log.accel, csv.accel) << f;
    EXPECT_EQ(log.gyro, csv.gyro) << f;
  }
}

TEST_F(Formats, RecordTimeIsTheRecordersTime) {
  LogReaderOptions options;
  options.record_time = true;
  ImuLog stamped, recorded;
  std::string error;
  ASSERT_TRUE(ReadImuLog(*scratch_ / "session.db3", LogReaderOptions(), &stamped, &error));
  ASSERT_TRUE(ReadImuLog(*scratch_ / "session.db3", options, &recorded, &error)) << error;
  ASSERT_EQ(stamped.t.size(), recorded.t.size());
  // The writer records each message 1000 ns after its stamp.
  EXPECT_NEAR(recorded.t[10] - stamped.t[10], 1e-6, 1e-9);
}

TEST_F(Formats, SeveralImuTopicsNeedTopic) {
  const ScratchDir& s = *scratch_;
  const auto r = RunCli(
      {"calibrate", "--input", s / "two_imus.db3", "--config", kConfig, "--output", s / "two.json"},
      s);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("2 sensor_msgs/Imu topics, give one with --topic: /imu0 "
                       "(sensor_msgs/msg/Imu), /imu1 (sensor_msgs/msg/Imu)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(FileExists(s / "two.json"));
  const auto wrong = RunCli({"calibrate", "--input", s / "session.db3", "--topic", "/rosout",
                             "--config", kConfig, "--output", s / "two.json"},
                            s);
  EXPECT_EQ(wrong.exit_code, 1);
  EXPECT_NE(wrong.err.find("topic '/rosout' holds rcl_interfaces/msg/Log, not sensor_msgs/Imu"),
            std::string::npos)
      << wrong.err;
}

TEST_F(Formats, BatchMakesOneUnitPerTopic) {
  const ScratchDir& s = *scratch_;
  const auto r = RunCli({"batch", "--input", s / "two_imus.db3", "--topics", "all", "--config",
                         kConfig, "--output-dir", s / "by_topic", "--threads", "1"},
                        s);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* unit : {"imu0", "imu1"}) {
    const std::string file = s / (std::string("by_topic/") + unit + ".json");
    ASSERT_TRUE(FileExists(file)) << file;
    EXPECT_EQ(StripTimes(nlohmann::json::parse(Slurp(file)))["accel"], (*reference_)["accel"]);
  }
}

TEST_F(Formats, InspectListsTopicsCountsAndRates) {
  const ScratchDir& s = *scratch_;
  ImuLog csv;
  std::string error;
  ASSERT_TRUE(ReadImuLog(s / "contract.csv", LogReaderOptions(), &csv, &error));
  RecordingSummary summary;
  ASSERT_TRUE(InspectRecording(s / "session.db3", LogReaderOptions(), &summary, &error)) << error;
  EXPECT_EQ(summary.format, "rosbag2 SQLite bag");
  ASSERT_EQ(summary.topics.size(), 2u);
  EXPECT_EQ(summary.topics[0].name, "/rosout");
  EXPECT_FALSE(summary.topics[0].imu);
  const TopicSummary& imu = summary.topics[1];
  EXPECT_EQ(imu.name, "/imu/data");
  EXPECT_TRUE(imu.imu);
  EXPECT_EQ(imu.messages, static_cast<int64_t>(csv.size()));
  EXPECT_EQ(imu.first_s, csv.t.front());
  EXPECT_EQ(imu.last_s, csv.t.back());
  EXPECT_NEAR(imu.rate_hz, (csv.size() - 1) / (csv.t.back() - csv.t.front()), 1e-9);
  EXPECT_EQ(imu.gaps, 0);

  const auto r = RunCli({"inspect", "--input", s / "session.db3"}, s);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("format: rosbag2 SQLite bag"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("/imu/data  [sensor_msgs/msg/Imu]"), std::string::npos) << r.out;
}

// --- Broken files -----------------------------------------------------------

std::string Truncated(const std::string& bytes) { return bytes.substr(0, bytes.size() / 2); }

// Overwrites `n` bytes at `at` with 0xA5: structure, not values, is hit
// (the offsets below are in each format's header or index).
std::string Corrupted(std::string bytes, size_t at, size_t n) {
  for (size_t i = at; i < at + n && i < bytes.size(); ++i) bytes[i] = static_cast<char>(0xA5);
  return bytes;
}

void ExpectRefused(const ScratchDir& s, const std::string& name, const std::string& bytes,
                   const std::string& expected) {
  const std::string path = s.Write(name, bytes);
  const std::string out = s / (name + ".json");
  const auto r = RunCli({"calibrate", "--input", path, "--config", kConfig, "--output", out}, s);
  EXPECT_EQ(r.exit_code, 1) << name << ": " << r.err;
  // "<path>: what" or, for text, "<path>:<line>: what".
  EXPECT_EQ(r.err.rfind("gravcal: error: " + path + ":", 0), 0u) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
  EXPECT_NE(r.err.find(expected), std::string::npos) << name << ": " << r.err;
  EXPECT_FALSE(FileExists(out)) << name;
}

TEST_F(Formats, BrokenMcapIsRefused) {
  if (!Have("mcap_zstd.mcap")) GTEST_SKIP() << "no MCAP writer (@mcap/core)";
  const ScratchDir& s = *scratch_;
  const std::string bytes = Slurp(s / "mcap_zstd.mcap");
  ExpectRefused(s, "truncated.mcap", Truncated(bytes), "truncated MCAP file");
  ExpectRefused(s, "corrupted.mcap", Corrupted(bytes, 9, 8), "past the end");
  ExpectRefused(s, "empty.mcap", "", "no samples");
  ExpectRefused(s, "magic_only.mcap", bytes.substr(0, 8), "truncated MCAP file");
  // A chunk whose compressed bytes are damaged.
  ExpectRefused(s, "bad_chunk.mcap", Corrupted(bytes, bytes.size() / 3, 64), "");
}

TEST_F(Formats, BrokenDb3IsRefused) {
  const ScratchDir& s = *scratch_;
  const std::string bytes = Slurp(s / "session.db3");
  ExpectRefused(s, "truncated.db3", Truncated(bytes), "");
  ExpectRefused(s, "corrupted.db3", Corrupted(bytes, 100, 16), "");
  ExpectRefused(s, "empty.db3", "", "no samples");
  ExpectRefused(s, "header_only.db3", bytes.substr(0, 100), "");
}

// The little-endian uint32 at `at`.
uint32_t U32At(const std::string& bytes, size_t at) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t{static_cast<uint8_t>(bytes[at + i])} << (8 * i);
  return v;
}

// The data offset of the first top-level record of a ROS 1 bag whose
// header holds `field` ("op=\x04" for an index), or npos.
size_t Ros1RecordData(const std::string& bag, const std::string& field) {
  size_t pos = 13;
  while (pos + 8 <= bag.size()) {
    const uint32_t header_len = U32At(bag, pos);
    const size_t data = pos + 8 + header_len;
    if (data > bag.size()) break;
    if (bag.substr(pos + 4, header_len).find(field) != std::string::npos) return data;
    pos = data + U32At(bag, pos + 4 + header_len);
  }
  return std::string::npos;
}

// Overwrites four bytes at `at` with the little-endian v.
std::string WithU32(std::string bytes, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<char>((v >> (8 * i)) & 0xFF);
  return bytes;
}

TEST_F(Formats, BrokenRos1BagIsRefused) {
  if (!Have("ros1_bz2.bag")) GTEST_SKIP() << Slurp(*scratch_ / "ros1_absent.txt");
  const ScratchDir& s = *scratch_;
  for (const char* name : {"ros1_none.bag", "ros1_bz2.bag", "ros1_lz4.bag"}) {
    const std::string bytes = Slurp(s / name);
    ExpectRefused(s, std::string("truncated_") + name, Truncated(bytes), "ROS 1 bag");
    ExpectRefused(s, std::string("corrupted_") + name, Corrupted(bytes, 13, 32), "ROS 1 bag");
  }
  ExpectRefused(s, "old.bag", "#ROSBAG V1.2\nxxxx", "a ROS 1 bag of version '1.2'");
  // Offsets librosbag_storage follows without a bounds check, each damaged
  // in an otherwise valid bag (fuzz/fuzz_ros1_bag found the first: a read
  // outside the chunk's buffer): refused before rosbag reads them.
  for (const char* name : {"ros1_none.bag", "ros1_lz4.bag"}) {
    const std::string bytes = Slurp(s / name);
    const size_t index = Ros1RecordData(bytes, std::string("op=\x04", 4));
    ASSERT_NE(index, std::string::npos) << name;
    // The first index entry's offset (after its 8-byte time) past the chunk.
    ExpectRefused(s, std::string("index_offset_") + name, WithU32(bytes, index + 8, 0xFFFFFFF0u),
                  "names no message of its chunk");
    // The same entry one byte into its message record.
    const uint32_t first = U32At(bytes, index + 8);
    ExpectRefused(s, std::string("index_inside_") + name, WithU32(bytes, index + 8, first + 1),
                  "names no message of its chunk");
  }
  {
    const std::string bytes = Slurp(s / "ros1_lz4.bag");
    const size_t chunk_pos = bytes.find("chunk_pos=");
    ASSERT_NE(chunk_pos, std::string::npos);
    ExpectRefused(s, "chunk_pos_ros1_lz4.bag", WithU32(bytes, chunk_pos + 10, 14), "not a chunk");
    // The chunk's declared uncompressed size one byte short.
    const size_t size = bytes.find("size=");
    ASSERT_NE(size, std::string::npos);
    const uint32_t declared = U32At(bytes, size + 5);
    ExpectRefused(s, "chunk_size_ros1_lz4.bag", WithU32(bytes, size + 5, declared - 1),
                  "does not uncompress to its declared size");
  }
}

TEST_F(Formats, BrokenEurocIsRefused) {
  const ScratchDir& s = *scratch_;
  std::string bytes = Slurp(s / "euroc.csv");
  // Cut just after a comma: the last row has too few fields. (A cut inside
  // the last number of a row leaves a shorter number no text reader can
  // tell from a real one.)
  std::string cut = Truncated(bytes);
  cut = cut.substr(0, cut.find_last_of(',') + 1);
  ExpectRefused(s, "truncated_euroc.csv", cut, "is empty");
  // The gyroscope x of a row in the middle replaced by "abc".
  const size_t field = bytes.find(',', bytes.find('\n', bytes.size() / 2)) + 1;
  ExpectRefused(s, "corrupted_euroc.csv",
                bytes.substr(0, field) + "abc" + bytes.substr(bytes.find(',', field)),
                "column 'gx': 'abc' is not a number");
  ExpectRefused(s, "header_only_euroc.csv", bytes.substr(0, bytes.find('\n') + 1), "no samples");
}

TEST_F(Formats, UnknownBinaryIsNamed) {
  ExpectRefused(*scratch_, "random.bin", std::string("PK\x03\x04\0\0garbage", 14),
                "binary data of a kind gravcal does not read");
  ExpectRefused(*scratch_, "not_a_bag.db3",
                Slurp(*scratch_ / "session.db3").substr(0, 16) + std::string(4080, '\0'), "");
}

}  // namespace
}  // namespace gravcal
