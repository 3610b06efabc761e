// gravcal record and simulate --stream (issue 37) through the command line:
// the closed loop through pipes, garbage lines, a stall, a saturated axis, a
// TCP disconnect, Ctrl-C, and the terminal UI under tmux. Each ends with a
// valid record.csv holding every sample the recorder read.
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_runner.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/virtual_hand.h"
#include "test_util.h"

namespace gravcal {
namespace {

using testing_util::CliResult;
using testing_util::RunCli;
using testing_util::ScratchDir;
using testing_util::Slurp;
using testing_util::SourceDir;

constexpr char kRecordTargets[] = "accel_bias=0.3mg accel_scale=100ppm accel_misalignment=0.2mrad";

std::string RecordConfigPath() { return SourceDir() + "/configs/twelve_position.yaml"; }

std::vector<std::string> RecordArgs(const ScratchDir& dir, const std::string& input) {
  return {"record",       "--input",      input,       "--config", RecordConfigPath(),  "--target",
          kRecordTargets, "--output-dir", dir / "out", "--events", dir / "events.jsonl"};
}

// A scripted hand: the six faces, each held `hold` seconds, as contract CSV
// lines (header first).
std::vector<std::string> ScriptedLines(uint64_t seed, double hold, double saturate = 0.0) {
  VirtualHandOptions options;
  options.saturate_counts = saturate;
  VirtualHand hand(options, seed);
  const std::vector<Eigen::Vector3d> ups = {Eigen::Vector3d::UnitX(),  -Eigen::Vector3d::UnitX(),
                                            Eigen::Vector3d::UnitY(),  -Eigen::Vector3d::UnitY(),
                                            -Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ()};
  std::vector<std::string> lines = {"t,ax,ay,az,gx,gy,gz"};
  double hold_start = 0.0;
  size_t next = 0;
  bool was_moving = false;
  for (;;) {
    const ImuSample s = hand.Next();
    if (was_moving && !hand.moving()) hold_start = s.t;
    was_moving = hand.moving();
    if (!hand.moving() && s.t - hold_start >= hold) {
      if (next == ups.size()) break;
      hand.MoveTo(ups[next++]);
      was_moving = true;
    }
    char b[200];
    std::snprintf(b, sizeof(b), "%.6f,%.0f,%.0f,%.0f,%.0f,%.0f,%.0f", s.t, s.accel(0), s.accel(1),
                  s.accel(2), s.gyro(0), s.gyro(1), s.gyro(2));
    lines.push_back(b);
  }
  return lines;
}

std::string Joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

// Starts the CLI with standard input from `stdin_fd`.
pid_t SpawnWithInput(const std::vector<std::string>& args, int stdin_fd, const ScratchDir& dir) {
  return testing_util::SpawnCli(args, dir / "stdout.txt", dir / "stderr.txt", stdin_fd);
}

std::vector<nlohmann::json> Events(const ScratchDir& dir) {
  std::vector<nlohmann::json> out;
  std::istringstream in(Slurp(dir / "events.jsonl"));
  std::string line;
  while (std::getline(in, line)) out.push_back(nlohmann::json::parse(line));
  return out;
}

int CountKind(const std::vector<nlohmann::json>& events, const std::string& kind) {
  int n = 0;
  for (const auto& e : events) n += e["event"] == "warning" && e["kind"] == kind;
  return n;
}

// record.csv reads back and holds as many samples as the done event says.
void ExpectValidLog(const ScratchDir& dir, const nlohmann::json& done) {
  ImuLog log;
  std::string error;
  ASSERT_TRUE(ReadImuLog(dir / "out/record.csv", LogReaderOptions(), &log, &error)) << error;
  EXPECT_EQ(log.size(), done["samples"].get<size_t>());
}

TEST(RecordCli, ClosedLoopThroughPipesMeetsTargetsAndEqualsCalibrate) {
  ScratchDir dir;
  const std::string cli = GRAVCAL_CLI_PATH;
  std::string command = cli + " simulate --stream - --follow-events " + (dir / "events.jsonl") +
                        " --config " + RecordConfigPath() + " --seed 5 | " + cli;
  for (const std::string& a : RecordArgs(dir, "-")) command += " '" + a + "'";
  command += " 2>" + (dir / "stderr.txt");
  ASSERT_EQ(std::system(command.c_str()), 0) << Slurp(dir / "stderr.txt");
  const std::vector<nlohmann::json> events = Events(dir);
  ASSERT_FALSE(events.empty());
  const nlohmann::json& done = events.back();
  EXPECT_EQ(done["reason"], "targets_met");
  int plan_poses = 0;
  for (const auto& e : events) {
    if (e["event"] == "sigma") plan_poses = e["plan_poses"].get<int>();
  }
  EXPECT_GT(plan_poses, 0);
  // Through pipes the hand's pacing depends on how fast each side runs, so
  // the poses vary by one or two between runs of one seed; the bound of the
  // issue (plan + 2) is asserted on the deterministic loop of
  // recorder_test.cc. Here: not far from the plan.
  EXPECT_LE(done["poses"].get<int>(), plan_poses + 4);
  ExpectValidLog(dir, done);
  const CliResult calibrate = RunCli({"calibrate", "--input", dir / "out/record.csv", "--config",
                                      RecordConfigPath(), "--output", dir / "again.json"},
                                     dir);
  ASSERT_EQ(calibrate.exit_code, 0) << calibrate.err;
  EXPECT_EQ(nlohmann::json::parse(Slurp(dir / "out/calibration.json"))["accel"],
            nlohmann::json::parse(Slurp(dir / "again.json"))["accel"]);
}

TEST(RecordCli, GarbageLinesAreCountedAndShownNotFatal) {
  ScratchDir dir;
  std::vector<std::string> lines = ScriptedLines(11, 6.0);
  // Garbage among the rows: text, a short row, binary bytes, a number that
  // is not one, a time going back.
  const std::vector<std::string> garbage = {
      "hello", "1,2", std::string("\x01\xff\xfe", 3), "5.0,1,2,abc,4,5,6", "0.001,1,2,3,4,5,6",
      "#ok"};
  for (size_t k = 0; k < garbage.size(); ++k) {
    lines.insert(lines.begin() + 500 + 700 * k, garbage[k]);
  }
  const std::string input = dir.Write("in.csv", Joined(lines));
  const int fd = open(input.c_str(), O_RDONLY);
  const int code = testing_util::WaitForExit(SpawnWithInput(RecordArgs(dir, "-"), fd, dir));
  close(fd);
  EXPECT_TRUE(code == 0 || code == 2) << Slurp(dir / "stderr.txt");
  const std::vector<nlohmann::json> events = Events(dir);
  ASSERT_FALSE(events.empty());
  const nlohmann::json& done = events.back();
  EXPECT_EQ(done["reason"], "end_of_input");
  // Five are not a comment.
  EXPECT_EQ(done["garbage_lines"].get<int>(), 5);
  EXPECT_EQ(CountKind(events, "garbage"), 5);
  EXPECT_NE(Slurp(dir / "stderr.txt").find("'abc' is not a number"), std::string::npos);
  ExpectValidLog(dir, done);
  EXPECT_EQ(done["samples"].get<size_t>(), lines.size() - 1 - 5 - 1);
}

TEST(RecordCli, SaturatedAxisIsNamedAndItsHoldNotUsed) {
  ScratchDir dir;
  // 1 g is about 16384 counts: the axis that points up or down clips.
  const std::string input = dir.Write("in.csv", Joined(ScriptedLines(12, 6.0, 16200.0)));
  const int fd = open(input.c_str(), O_RDONLY);
  testing_util::WaitForExit(SpawnWithInput(RecordArgs(dir, "-"), fd, dir));
  close(fd);
  const std::vector<nlohmann::json> events = Events(dir);
  ASSERT_FALSE(events.empty());
  EXPECT_GE(CountKind(events, "saturation"), 1) << Slurp(dir / "stderr.txt");
  EXPECT_NE(Slurp(dir / "stderr.txt").find("saturat"), std::string::npos);
  ExpectValidLog(dir, events.back());
}

TEST(RecordCli, StallIsSaidAndTheSessionGoesOn) {
  ScratchDir dir;
  const std::vector<std::string> lines = ScriptedLines(13, 5.0);
  int p[2];
  ASSERT_EQ(pipe2(p, O_CLOEXEC), 0);
  const pid_t pid = SpawnWithInput(RecordArgs(dir, "-"), p[0], dir);
  close(p[0]);
  const std::string first = Joined({lines.begin(), lines.begin() + lines.size() / 2});
  const std::string second = Joined({lines.begin() + lines.size() / 2, lines.end()});
  ASSERT_EQ(write(p[1], first.data(), first.size()), static_cast<ssize_t>(first.size()));
  std::this_thread::sleep_for(std::chrono::milliseconds(3400));
  ASSERT_EQ(write(p[1], second.data(), second.size()), static_cast<ssize_t>(second.size()));
  close(p[1]);
  testing_util::WaitForExit(pid);
  const std::vector<nlohmann::json> events = Events(dir);
  ASSERT_FALSE(events.empty());
  EXPECT_NE(Slurp(dir / "stderr.txt").find("no data for 3 s"), std::string::npos);
  EXPECT_GE(CountKind(events, "stall"), 1);
  EXPECT_EQ(events.back()["reason"], "end_of_input");
  EXPECT_EQ(events.back()["samples"].get<size_t>(), lines.size() - 1);
  ExpectValidLog(dir, events.back());
}

TEST(RecordCli, TcpDisconnectEndsCleanlyWithWhatWasRecorded) {
  ScratchDir dir;
  const int server = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(server, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  ASSERT_EQ(bind(server, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
  ASSERT_EQ(listen(server, 1), 0);
  socklen_t length = sizeof(address);
  getsockname(server, reinterpret_cast<sockaddr*>(&address), &length);
  const std::string source = "tcp://127.0.0.1:" + std::to_string(ntohs(address.sin_port));
  const int null = open("/dev/null", O_RDONLY);
  const pid_t pid = SpawnWithInput(RecordArgs(dir, source), null, dir);
  close(null);
  const int peer = accept(server, nullptr, nullptr);
  ASSERT_GE(peer, 0);
  const std::vector<std::string> lines = ScriptedLines(14, 5.0);
  // Cut mid-session, mid-line: the device goes away.
  std::string text = Joined({lines.begin(), lines.begin() + 2000});
  text += "12.3,45";
  ASSERT_EQ(write(peer, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  close(peer);
  close(server);
  testing_util::WaitForExit(pid);
  const std::vector<nlohmann::json> events = Events(dir);
  ASSERT_FALSE(events.empty()) << Slurp(dir / "stderr.txt");
  EXPECT_EQ(events.back()["reason"], "end_of_input");
  // The cut line is garbage, every whole row is recorded.
  EXPECT_EQ(events.back()["garbage_lines"].get<int>(), 1);
  EXPECT_EQ(events.back()["samples"].get<size_t>(), 1999u);
  ExpectValidLog(dir, events.back());
}

TEST(RecordCli, UdpDatagramsAreLinesAndMaxTimeEndsTheSession) {
  ScratchDir dir;
  // A free port: bound, read, released.
  int probe = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(probe, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
  socklen_t length = sizeof(address);
  getsockname(probe, reinterpret_cast<sockaddr*>(&address), &length);
  close(probe);
  std::vector<std::string> args =
      RecordArgs(dir, "udp://127.0.0.1:" + std::to_string(ntohs(address.sin_port)));
  args.insert(args.end(), {"--max-time", "15"});
  const int null = open("/dev/null", O_RDONLY);
  const pid_t pid = SpawnWithInput(args, null, dir);
  close(null);
  // Until the recorder listens, datagrams are refused or lost: the header
  // goes again until it answers with a file of events.
  const int out = socket(AF_INET, SOCK_DGRAM, 0);
  const std::vector<std::string> lines = ScriptedLines(16, 5.0);
  for (int i = 0; i < 100 && !testing_util::FileExists(dir / "events.jsonl"); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  // Twenty lines a datagram.
  for (size_t i = 0; i < lines.size() && i < 2000; i += 20) {
    const std::string text =
        Joined({lines.begin() + i, lines.begin() + std::min(i + 20, lines.size())});
    sendto(out, text.data(), text.size(), 0, reinterpret_cast<sockaddr*>(&address),
           sizeof(address));
    if (i % 400 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  close(out);
  // Lost datagrams would leave it waiting: interrupted after 5 s (and the
  // reason below fails).
  int status = 0;
  for (int i = 0; i < 250 && waitpid(pid, &status, WNOHANG) == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (waitpid(pid, &status, WNOHANG) == 0) {
    kill(pid, SIGINT);
    testing_util::WaitForExit(pid);
  }
  const std::vector<nlohmann::json> events = Events(dir);
  ASSERT_FALSE(events.empty()) << Slurp(dir / "stderr.txt");
  EXPECT_EQ(events.back()["reason"], "max_time");
  EXPECT_EQ(events.back()["garbage_lines"].get<int>(), 0);
  ExpectValidLog(dir, events.back());
}

TEST(RecordCli, CtrlCWritesWhatWasRecorded) {
  ScratchDir dir;
  int p[2];
  ASSERT_EQ(pipe2(p, O_CLOEXEC), 0);
  const pid_t pid = SpawnWithInput(RecordArgs(dir, "-"), p[0], dir);
  close(p[0]);
  const std::vector<std::string> lines = ScriptedLines(15, 5.0);
  const std::string text = Joined({lines.begin(), lines.begin() + 1500});
  ASSERT_EQ(write(p[1], text.data(), text.size()), static_cast<ssize_t>(text.size()));
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  kill(pid, SIGINT);
  testing_util::WaitForExit(pid);
  close(p[1]);
  const std::vector<nlohmann::json> events = Events(dir);
  ASSERT_FALSE(events.empty()) << Slurp(dir / "stderr.txt");
  EXPECT_EQ(events.back()["reason"], "interrupted");
  EXPECT_EQ(events.back()["samples"].get<size_t>(), 1499u);
  ExpectValidLog(dir, events.back());
}

TEST(RecordCli, BadInvocationsSayWhy) {
  ScratchDir dir;
  CliResult r = RunCli(
      {"record", "--input", "-", "--config", RecordConfigPath(), "--output-dir", dir / "out"}, dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--target"), std::string::npos) << r.err;
  r = RunCli({"record", "--input", "udp://nonsense", "--config", RecordConfigPath(), "--target",
              kRecordTargets, "--output-dir", dir / "out"},
             dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("udp://:PORT"), std::string::npos) << r.err;
  r = RunCli({"record", "--input", dir / "missing", "--config", RecordConfigPath(), "--target",
              kRecordTargets, "--output-dir", dir / "out"},
             dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("cannot open"), std::string::npos) << r.err;
}

// The terminal UI as a person sees it: record in a tmux pane, stopped by
// --max-time midway, the pane captured.
TEST(RecordCli, TerminalUiUnderTmuxShowsHemispheresBarsAndSuggestion) {
  if (std::system("command -v tmux >/dev/null 2>&1") != 0) GTEST_SKIP() << "tmux is absent";
  ScratchDir dir;
  const std::string cli = GRAVCAL_CLI_PATH;
  const std::string server = "gravcal_record_" + std::to_string(getpid());
  std::string command = cli + " simulate --stream - --follow-events " + (dir / "events.jsonl") +
                        " --config " + RecordConfigPath() + " --seed 6 | " + cli;
  for (const std::string& a : RecordArgs(dir, "-")) command += " '" + a + "'";
  command += " --max-time 80; touch " + (dir / "finished") + "; sleep 60";
  const std::string start =
      "tmux -L " + server + " new-session -d -x 110 -y 48 \"" + command + "\"";
  ASSERT_EQ(std::system(start.c_str()), 0);
  for (int i = 0; i < 200 && !testing_util::FileExists(dir / "finished"); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const std::string capture = "tmux -L " + server + " capture-pane -p -t 0 > " + (dir / "pane.txt");
  EXPECT_EQ(std::system(capture.c_str()), 0);
  std::system(("tmux -L " + server + " kill-server").c_str());
  const std::string pane = Slurp(dir / "pane.txt");
  EXPECT_NE(pane.find("z >= 0 (seen from +z)"), std::string::npos) << pane;
  EXPECT_NE(pane.find("sigma / target"), std::string::npos) << pane;
  EXPECT_NE(pane.find("bias_x  ["), std::string::npos) << pane;
  EXPECT_NE(pane.find("next: "), std::string::npos) << pane;
  EXPECT_NE(pane.find(" up"), std::string::npos) << pane;
  EXPECT_NE(pane.find("DONE (max_time)"), std::string::npos) << pane;
}

}  // namespace
}  // namespace gravcal
