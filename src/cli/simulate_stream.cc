// gravcal simulate --stream (issue 37): a virtual hand's session
// (simulation/virtual_hand.h) as contract CSV lines on standard output or a
// pseudo-terminal, at --rate times real time or as fast as it can, placing
// the unit where gravcal record's suggest events (--follow-events) say.
//
// Following: the hand holds each pose until a new suggest event comes. As
// fast as it can, it would run ahead of the recorder by what the pipe
// holds; so once a hold has lasted the suggested hold plus kAheadSeconds it
// stops and waits up to kWaitMs for a new event, then streams kStepSeconds
// more and waits again (the recorder wants a longer hold). The moves thus
// depend on the events, not on how fast either side runs, unless the
// recorder needs more than kWaitMs to read kAheadSeconds of samples.
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "cli/commands.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/simulation/virtual_hand.h"

namespace gravcal {
namespace cli {

namespace {

constexpr double kAheadSeconds = 1.0;
constexpr double kStepSeconds = 1.0;
constexpr int kWaitMs = 300;
constexpr int kPollMs = 2;
// A stream without an end (following, no done event) stops here.
constexpr double kMaxStreamSeconds = 3600.0;

// The new complete lines of a file another process appends to.
class FollowedFile {
 public:
  explicit FollowedFile(std::string path) : path_(std::move(path)) {}
  ~FollowedFile() {
    if (file_) std::fclose(file_);
  }
  std::vector<std::string> Lines() {
    std::vector<std::string> out;
    if (!file_) file_ = std::fopen(path_.c_str(), "r");
    if (!file_) return out;
    char buffer[4096];
    while (std::fgets(buffer, sizeof(buffer), file_)) {
      partial_ += buffer;
      if (!partial_.empty() && partial_.back() == '\n') {
        partial_.pop_back();
        out.push_back(partial_);
        partial_.clear();
      }
    }
    std::clearerr(file_);
    return out;
  }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  std::string partial_;
};

VirtualHandOptions HandOptions(const SimulatorOptions& sim) {
  VirtualHandOptions h;
  h.sample_rate = sim.sample_rate;
  h.gravity = sim.gravity;
  h.accel_counts_per_g = sim.accel_counts_per_g;
  h.gyro_counts_per_dps = sim.gyro_counts_per_dps;
  h.accel_noise = sim.accel_noise;
  h.gyro_noise = sim.gyro_noise;
  if (sim.tremor > 0.0) h.tremor = sim.tremor;
  h.placement_error_deg = sim.placement_error_deg;
  h.accel_bias_std = sim.accel_bias_std;
  h.accel_scale_std = sim.accel_scale_std;
  h.accel_misalignment_std = sim.accel_misalignment_std;
  h.gyro_bias_std = sim.gyro_bias_std;
  h.gyro_scale_std = sim.gyro_scale_std;
  h.gyro_misalignment_std = sim.gyro_misalignment_std;
  return h;
}

}  // namespace

int RunSimulateStream(const SimulateArgs& args) {
  if (!args.output_dir.empty() || !args.plan.empty()) {
    return Fail("simulate --stream writes lines, not --output-dir or --plan");
  }
  if (!(args.rate >= 0.0)) return Fail("--rate must not be negative");
  const bool pty = args.stream == "pty";
  if (!pty && args.stream != "-") return Fail("--stream takes - (standard output) or pty");
  const SimulatorOptions& sim = args.config.simulation;
  const VirtualHandOptions options = HandOptions(sim);
  std::string error;
  if (!options.IsValid(&error)) return Fail(error);
  // Without --follow-events: the config's scheme, each pose held sim_hold.
  std::vector<Eigen::Vector3d> script;
  if (args.follow_events.empty()) {
    std::vector<Eigen::Quaterniond> attitudes;
    std::vector<int> nominal;
    if (!SchemeAttitudes(sim.scheme, args.seed, &attitudes, &nominal, &error)) return Fail(error);
    for (const Eigen::Quaterniond& q : attitudes)
      script.push_back(q.conjugate() * Eigen::Vector3d::UnitZ());
  }
  int fd = STDOUT_FILENO;
  if (pty) {
    fd = posix_openpt(O_RDWR | O_NOCTTY);
    if (fd < 0 || grantpt(fd) != 0 || unlockpt(fd) != 0)
      return Fail("cannot open a pseudo-terminal");
    std::fprintf(stderr, "gravcal simulate: streaming on %s\n", ptsname(fd));
    std::fflush(stderr);
  }
  signal(SIGPIPE, SIG_IGN);
  VirtualHand hand(options, args.seed);
  FollowedFile events(args.follow_events);
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  auto put = [&](const std::string& text) {
    size_t at = 0;
    while (at < text.size()) {
      const ssize_t n = write(fd, text.data() + at, text.size() - at);
      if (n <= 0) return false;
      at += static_cast<size_t>(n);
    }
    return true;
  };
  if (!put("t,ax,ay,az,gx,gy,gz\n")) return 0;
  double suggested_hold = sim.hold_seconds;
  double hold_start = 0.0;
  double next_step = 0.0;
  bool was_moving = false;
  size_t script_index = 0;
  bool done = false;
  std::string line;
  while (!done) {
    const ImuSample s = hand.Next();
    if (s.t > kMaxStreamSeconds) break;
    if (was_moving && !hand.moving()) hold_start = s.t;
    was_moving = hand.moving();
    if (args.follow_events.empty()) {
      // The script: the next pose once this one was held sim_hold.
      if (!hand.moving() && s.t - hold_start >= sim.hold_seconds) {
        if (script_index >= script.size()) break;
        hand.MoveTo(script[script_index++]);
        was_moving = true;
      }
    } else {
      int waited_ms = 0;
      for (;;) {
        for (const std::string& e : events.Lines()) {
          const nlohmann::json j = nlohmann::json::parse(e, nullptr, false);
          if (j.is_discarded() || !j.is_object()) continue;
          const std::string type = j.value("event", "");
          if (type == "done") done = true;
          if (type == "suggest" && j["up"].is_array() && j["up"].size() == 3) {
            hand.MoveTo(Eigen::Vector3d(j["up"][0].get<double>(), j["up"][1].get<double>(),
                                        j["up"][2].get<double>()));
            suggested_hold = j.value("hold_seconds", sim.hold_seconds);
            was_moving = true;
            next_step = 0.0;
          }
        }
        const bool ahead = !hand.moving() && s.t - hold_start > suggested_hold + kAheadSeconds;
        if (done || !ahead || args.rate > 0.0 || s.t < next_step) break;
        if (waited_ms >= kWaitMs) {
          next_step = s.t + kStepSeconds;
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(kPollMs));
        waited_ms += kPollMs;
      }
    }
    if (args.rate > 0.0) {
      std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(s.t / args.rate)));
    }
    char buffer[256];
    std::snprintf(buffer, sizeof(buffer), "%.6f,%.0f,%.0f,%.0f,%.0f,%.0f,%.0f\n", s.t, s.accel(0),
                  s.accel(1), s.accel(2), s.gyro(0), s.gyro(1), s.gyro(2));
    if (!put(buffer)) break;  // the reader has gone
  }
  if (pty) close(fd);
  return 0;
}

}  // namespace cli
}  // namespace gravcal
