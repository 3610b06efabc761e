// Issue 17: every HTML report (calibrate, batch, noise, discover, plan --report)
// opened in a real browser. Headless Chromium, driven over its DevTools
// protocol, loads the file (file://, no network); a test fails on any
// console message or uncaught exception (the reports log nothing, so
// any message is an error or a warning), checks the sections in the DOM the
// browser built (for example one shaded interval per position of the
// calibration JSON), checks that every axis's tick labels are round numbers,
// and saves a full-page screenshot into <build>/report_screenshots/. Skipped
// with a message when no Chromium is installed (.ci/run installs the Debian
// package `chromium`).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/pipeline.h"
#include "gravcal/workflows/report.h"
#include "still_log.h"
#include "test_util.h"
#include "util/random_vector.h"

namespace gravcal {
namespace {

using testing_util::Count;
using testing_util::RunCli;
using testing_util::ScratchDir;
using testing_util::Slurp;

// The first Chromium on PATH; empty when there is none.
std::string Browser() {
  static const std::string path = [] {
    const char* env = std::getenv("PATH");
    std::string dirs = env ? env : "/usr/bin";
    for (const char* name : {"chromium", "chromium-browser", "google-chrome"}) {
      size_t start = 0;
      while (start <= dirs.size()) {
        const size_t end = std::min(dirs.find(':', start), dirs.size());
        const std::string candidate = dirs.substr(start, end - start) + "/" + name;
        if (access(candidate.c_str(), X_OK) == 0) return candidate;
        start = end + 1;
      }
    }
    return std::string();
  }();
  return path;
}

#define SKIP_WITHOUT_BROWSER()                                                             \
  if (Browser().empty()) {                                                                 \
    GTEST_SKIP() << "no Chromium on PATH (install the Debian package 'chromium'; .ci/run " \
                    "does): the reports are not opened in a browser";                      \
  }

// The value of attribute `name` of the first element after `from`.
std::string Attribute(const std::string& dom, const std::string& name, size_t from = 0) {
  const std::string key = name + "=\"";
  const size_t at = dom.find(key, from);
  if (at == std::string::npos) return "";
  const size_t begin = at + key.size();
  return dom.substr(begin, dom.find('"', begin) - begin);
}

// Bytes of base64 `text` (the DevTools protocol's encoding of a screenshot).
std::string DecodeBase64(const std::string& text) {
  std::string out;
  int bits = 0, value = 0;
  for (char ch : text) {
    int v = -1;
    if (ch >= 'A' && ch <= 'Z') v = ch - 'A';
    if (ch >= 'a' && ch <= 'z') v = ch - 'a' + 26;
    if (ch >= '0' && ch <= '9') v = ch - '0' + 52;
    if (ch == '+') v = 62;
    if (ch == '/') v = 63;
    if (v < 0) continue;
    value = (value << 6) | v;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<char>((value >> bits) & 0xff));
    }
  }
  return out;
}

// Headless Chromium driven over the DevTools protocol on a pipe
// (--remote-debugging-pipe: it reads commands on its fd 3 and writes replies
// and events on its fd 4, each a JSON text ended by a NUL), so one start of
// the browser loads a page, reads its DOM and takes the screenshot (two
// starts with --dump-dom and --screenshot took twice as long). Every console
// message and uncaught exception of the page is collected.
class DevToolsBrowser {
 public:
  // Starts the browser on about:blank with a 1280-pixel-wide window and
  // attaches to its page; false with *error when that fails.
  bool Start(const std::string& log, std::string* error) {
    std::signal(SIGPIPE, SIG_IGN);  // a browser that died is a read error
    int commands[2], replies[2];
    if (pipe(commands) != 0 || pipe(replies) != 0) return Fail("pipe", error);
    pid_ = fork();
    if (pid_ == 0) {
      // Above the fds the child ends up with, then onto 3 and 4.
      const int in = fcntl(commands[0], F_DUPFD, 10);
      const int out = fcntl(replies[1], F_DUPFD, 10);
      const int null = open("/dev/null", O_RDWR);
      const int err = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(null, 0);
      dup2(null, 1);
      dup2(err, 2);
      dup2(in, 3);
      dup2(out, 4);
      for (int fd = 5; fd < 64; ++fd) close(fd);
      std::string program = Browser();
      std::vector<std::string> args = {program,
                                       "--headless",
                                       "--no-sandbox",
                                       "--disable-gpu",
                                       "--hide-scrollbars",
                                       "--remote-debugging-pipe",
                                       "--window-size=1280,800",
                                       "about:blank"};
      std::vector<char*> argv;
      for (std::string& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(program.c_str(), argv.data());
      _exit(127);
    }
    close(commands[0]);
    close(replies[1]);
    to_ = commands[1];
    from_ = replies[0];
    if (pid_ < 0) return Fail("fork", error);
    nlohmann::json targets;
    if (!Call("Target.getTargets", {}, false, &targets, error)) return false;
    std::string target;
    for (const auto& t : targets["targetInfos"]) {
      if (t.value("type", "") == "page") target = t.value("targetId", "");
    }
    if (target.empty()) return Fail("no page target", error);
    nlohmann::json attached;
    if (!Call("Target.attachToTarget", {{"targetId", target}, {"flatten", true}}, false, &attached,
              error)) {
      return false;
    }
    session_ = attached.value("sessionId", "");
    nlohmann::json ignored;
    return Call("Runtime.enable", {}, true, &ignored, error) &&
           Call("Page.enable", {}, true, &ignored, error);
  }

  ~DevToolsBrowser() {
    if (pid_ <= 0) return;
    std::string error;
    nlohmann::json ignored;
    if (from_ >= 0) Call("Browser.close", {}, false, &ignored, &error);
    if (to_ >= 0) close(to_);
    if (from_ >= 0) close(from_);
    // Up to 10 s to exit on its own.
    bool exited = false;
    for (int i = 0; i < 100 && !exited; ++i) {
      exited = waitpid(pid_, nullptr, WNOHANG) == pid_;
      if (!exited) usleep(100000);
    }
    if (!exited) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }

  // Sends `method` (to the page's session when `page`) and waits for its
  // reply; *result is the reply's result. Events that arrive meanwhile are
  // kept: console messages in console(), and whether the load event fired.
  bool Call(const std::string& method, const nlohmann::json& params, bool page,
            nlohmann::json* result, std::string* error) {
    nlohmann::json message = {{"id", ++id_}, {"method", method}, {"params", params}};
    if (page) message["sessionId"] = session_;
    const std::string text = message.dump() + std::string(1, '\0');
    for (size_t sent = 0; sent < text.size();) {
      const ssize_t n = write(to_, text.data() + sent, text.size() - sent);
      if (n <= 0) return Fail(method + ": the browser closed its pipe", error);
      sent += static_cast<size_t>(n);
    }
    nlohmann::json reply;
    while (true) {
      if (!Next(&reply, error)) return Fail(method + ": " + *error, error);
      if (reply.value("id", -1) == id_) break;
    }
    if (reply.contains("error")) return Fail(method + ": " + reply["error"].dump(), error);
    *result = reply.value("result", nlohmann::json::object());
    return true;
  }

  // Waits for the page's load event (events since the last navigation).
  bool WaitForLoad(std::string* error) {
    nlohmann::json event;
    while (!loaded_) {
      if (!Next(&event, error)) return Fail("waiting for the load event: " + *error, error);
    }
    return true;
  }

  void ExpectLoad() { loaded_ = false; }
  const std::vector<std::string>& console() const { return console_; }

 private:
  static bool Fail(const std::string& what, std::string* error) {
    *error = what;
    return false;
  }

  // The next message from the browser (within 60 s), noting events.
  bool Next(nlohmann::json* message, std::string* error) {
    while (true) {
      const size_t end = buffer_.find('\0');
      if (end != std::string::npos) {
        *message = nlohmann::json::parse(buffer_.substr(0, end), nullptr, false);
        buffer_.erase(0, end + 1);
        Note(*message);
        return true;
      }
      pollfd p = {from_, POLLIN, 0};
      if (poll(&p, 1, 60000) <= 0) return Fail("no reply from the browser in 60 s", error);
      char chunk[65536];
      const ssize_t n = read(from_, chunk, sizeof(chunk));
      if (n <= 0) return Fail("the browser closed its pipe", error);
      buffer_.append(chunk, static_cast<size_t>(n));
    }
  }

  void Note(const nlohmann::json& m) {
    const std::string method = m.is_object() ? m.value("method", "") : "";
    if (method == "Page.loadEventFired") loaded_ = true;
    if (method == "Runtime.consoleAPICalled") {
      std::string line = "console." + m["params"].value("type", "");
      for (const auto& a : m["params"].value("args", nlohmann::json::array())) {
        line += " " + (a.contains("value") ? a["value"].dump() : a.value("description", ""));
      }
      console_.push_back(line);
    }
    if (method == "Runtime.exceptionThrown") {
      const nlohmann::json& d = m["params"]["exceptionDetails"];
      console_.push_back("uncaught: " + d.value("text", "") + " " +
                         d.value("exception", nlohmann::json::object()).value("description", ""));
    }
  }

  pid_t pid_ = -1;
  int to_ = -1;
  int from_ = -1;
  int id_ = 0;
  std::string session_;
  std::string buffer_;
  bool loaded_ = false;
  std::vector<std::string> console_;
};

struct LoadedPage {
  // Empty when the browser loaded the page (and took the screenshot);
  // otherwise what failed.
  std::string error;
  std::string dom;
  // Every console message and uncaught exception of the page.
  std::vector<std::string> console;
};

std::string FileUrl(const std::string& path) {
  return "file://" + std::filesystem::absolute(path).string();
}

// Loads `html` in a 1280-pixel-wide window and returns the DOM once the
// load event has run; with `png`, also saves a screenshot of the whole page
// (its height from the page's data-height attribute, 600-16000 px).
LoadedPage Load(const std::string& html, const ScratchDir& dir, const std::string& png = "") {
  LoadedPage page;
  DevToolsBrowser browser;
  nlohmann::json r;
  std::string& error = page.error;
  if (!browser.Start(dir / "browser.log", &error)) return page;
  browser.ExpectLoad();
  if (!browser.Call("Page.navigate", {{"url", FileUrl(html)}}, true, &r, &error) ||
      !browser.WaitForLoad(&error)) {
    return page;
  }
  // After the tasks the load handlers queued.
  const std::string dom_after_load =
      "new Promise(done => setTimeout(() => done(document.documentElement.outerHTML), 0))";
  if (!browser.Call(
          "Runtime.evaluate",
          {{"expression", dom_after_load}, {"awaitPromise", true}, {"returnByValue", true}}, true,
          &r, &error)) {
    return page;
  }
  page.dom = r["result"].value("value", "");
  if (!png.empty()) {
    const int height =
        std::max(600, std::min(16000, std::atoi(Attribute(page.dom, "data-height").c_str())));
    if (!browser.Call(
            "Emulation.setDeviceMetricsOverride",
            {{"width", 1280}, {"height", height}, {"deviceScaleFactor", 1}, {"mobile", false}},
            true, &r, &error) ||
        !browser.Call("Page.captureScreenshot", {{"format", "png"}}, true, &r, &error)) {
      return page;
    }
    std::ofstream(png, std::ios::binary) << DecodeBase64(r.value("data", ""));
  }
  page.console = browser.console();
  return page;
}

struct AxisTicks {
  std::string scale;
  std::vector<std::string> labels;
};

// Every <g class="axis"> of the DOM with its tick labels.
std::vector<AxisTicks> Axes(const std::string& dom) {
  std::vector<AxisTicks> axes;
  const std::string open = "<g class=\"axis\"";
  for (size_t at = dom.find(open); at != std::string::npos; at = dom.find(open, at + 1)) {
    const size_t end = dom.find("</g>", at);
    const std::string g = dom.substr(at, end - at);
    AxisTicks a;
    a.scale = Attribute(g, "data-scale");
    const std::string tick = "class=\"tick\"";
    for (size_t t = g.find(tick); t != std::string::npos; t = g.find(tick, t + 1)) {
      const size_t begin = g.find('>', t) + 1;
      a.labels.push_back(g.substr(begin, g.find('<', begin) - begin));
    }
    axes.push_back(a);
  }
  return axes;
}

// 1, 2 or 5 times a power of ten (within rounding).
bool IsOneTwoFive(double v) {
  if (!(v > 0)) return false;
  const double m = v / std::pow(10.0, std::floor(std::log10(v) + 1e-9));
  for (double nice : {1.0, 2.0, 5.0, 10.0}) {
    if (std::fabs(m - nice) < 1e-6 * nice) return true;
  }
  return false;
}

// Empty when the labels are round: on a linear axis equally spaced at a
// step of 1, 2 or 5 times a power of ten, each a whole multiple of it; on a
// log axis each 1, 2 or 5 times a power of ten. Otherwise what is wrong.
std::string TickProblem(const AxisTicks& axis) {
  std::vector<double> v;
  for (const std::string& label : axis.labels) {
    char* end = nullptr;
    v.push_back(std::strtod(label.c_str(), &end));
    if (end == label.c_str() || *end != '\0') return "label '" + label + "' is not a number";
  }
  if (v.size() < 2) return "fewer than two ticks";
  if (axis.scale == "log") {
    for (size_t i = 0; i < v.size(); ++i) {
      if (!IsOneTwoFive(v[i])) return "log tick '" + axis.labels[i] + "' is not 1, 2 or 5 x 10^k";
    }
    return "";
  }
  // Ascending (axes) or descending (the heat map's colour bar).
  const double step = v[1] - v[0];
  if (!IsOneTwoFive(std::fabs(step))) {
    return "step " + std::to_string(step) + " is not 1, 2 or 5 x 10^k";
  }
  for (size_t i = 0; i < v.size(); ++i) {
    if (i > 0 && std::fabs(v[i] - v[i - 1] - step) > 1e-6 * std::fabs(step)) {
      return "ticks '" + axis.labels[i - 1] + "', '" + axis.labels[i] + "' not one step apart";
    }
    const double k = v[i] / step;
    if (std::fabs(k - std::round(k)) > 1e-6) {
      return "tick '" + axis.labels[i] + "' is not a multiple of the step";
    }
  }
  return "";
}

void ExpectRoundTicks(const std::string& dom, size_t min_axes) {
  const std::vector<AxisTicks> axes = Axes(dom);
  EXPECT_GE(axes.size(), min_axes);
  for (size_t i = 0; i < axes.size(); ++i) {
    std::string labels;
    for (const std::string& l : axes[i].labels) labels += l + " ";
    EXPECT_EQ(TickProblem(axes[i]), "") << "axis " << i << " (" << axes[i].scale << "): " << labels;
  }
}

// Empty when `html` fetches nothing: no src= or href= attribute, no CSS
// import or url(); otherwise the first such reference.
std::string ExternalReference(const std::string& html) {
  for (const char* needle : {"src=", "href=", "@import", "url("}) {
    const size_t at = html.find(needle);
    if (at != std::string::npos) return html.substr(at, 60);
  }
  return "";
}

std::string ScreenshotDir() {
  const std::string d =
      std::filesystem::path(GRAVCAL_CLI_PATH).parent_path().string() + "/report_screenshots";
  std::filesystem::create_directories(d);
  return d;
}

// Loads the report, fails on console messages, checks the ticks, saves a
// full-page screenshot <build>/report_screenshots/<name>.png; returns the DOM.
std::string OpenReport(const std::string& html, const std::string& name, const ScratchDir& dir,
                       size_t min_axes) {
  EXPECT_EQ(ExternalReference(Slurp(html)), "") << "the report is not self-contained";
  const std::string png = ScreenshotDir() + "/" + name + ".png";
  std::filesystem::remove(png);
  const LoadedPage page = Load(html, dir, png);
  EXPECT_EQ(page.error, "") << Slurp(dir / "browser.log");
  EXPECT_TRUE(page.console.empty()) << "console: " << page.console[0];
  EXPECT_NE(page.dom.find("data-load-ms"), std::string::npos) << "the load event did not run";
  ExpectRoundTicks(page.dom, min_axes);
  // Every warning has its explanation (report_warning_test.cc checks more).
  EXPECT_EQ(Count(page.dom, "warning unexplained"), 0u);
  // A PNG file: its signature.
  EXPECT_EQ(Slurp(png).substr(0, 8), "\x89PNG\r\n\x1a\n") << png;
  ::testing::Test::RecordProperty("screenshot", png);
  ::testing::Test::RecordProperty("load_ms", Attribute(page.dom, "data-load-ms"));
  const size_t bytes = Slurp(html).size();
  ::testing::Test::RecordProperty("bytes", std::to_string(bytes));
  std::printf("report %s: %zu bytes, load %s ms\n", name.c_str(), bytes,
              Attribute(page.dom, "data-load-ms").c_str());
  return page.dom;
}

std::string ConfigPath(const std::string& name) {
  return testing_util::SourceDir() + "/configs/" + name;
}

// Simulates a session with `config` and runs `command` (calibrate or
// discover) on it with --output <name>.json --report <name>.html; returns
// the report's path.
std::string SimulateAndReport(const std::string& command, const std::string& config, int seed,
                              const std::string& name, const ScratchDir& dir) {
  EXPECT_EQ(RunCli("simulate --config " + config + " --seed " + std::to_string(seed) +
                       " --output-dir " + (dir / "sim"),
                   dir)
                .exit_code,
            0);
  const std::string html = dir / (name + ".html");
  const testing_util::CliResult r =
      RunCli(command + " --input " + (dir / "sim/raw.csv") + " --config " + config + " --output " +
                 (dir / (name + ".json")) + " --report " + html,
             dir);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return html;
}

// The checkers themselves catch what they are for: a page that writes to
// the console, and axes labelled like the old discovery report's.
TEST(ReportBrowser, CheckersCatchPlantedMistakes) {
  AxisTicks bad{"linear", {"-0.5", "9", "18.5"}};
  EXPECT_NE(TickProblem(bad), "");
  bad.labels = {"8.72", "4.44", "0.151"};
  EXPECT_NE(TickProblem(bad), "");
  bad.labels = {"0", "0.3", "0.6"};
  EXPECT_NE(TickProblem(bad), "");
  EXPECT_NE(ExternalReference("<img src='https://example.org/a.png'>"), "");
  EXPECT_NE(ExternalReference("<style>@import 'a.css';</style>"), "");
  EXPECT_EQ(ExternalReference("<svg xmlns='http://www.w3.org/2000/svg'></svg>"), "");
  const AxisTicks good{"linear", {"-1", "-0.5", "0", "0.5", "1"}};
  EXPECT_EQ(TickProblem(good), "");
  EXPECT_EQ(TickProblem({"log", {"0.01", "0.1", "1", "10"}}), "");
  EXPECT_NE(TickProblem({"log", {"0.01", "0.03", "1"}}), "");
  SKIP_WITHOUT_BROWSER();
  ScratchDir dir;
  const std::string html =
      dir.Write("planted.html",
                "<html><body><p>x</p><script>console.error('planted');</script></body></html>");
  const LoadedPage page = Load(html, dir);
  ASSERT_EQ(page.console.size(), 1u);
  EXPECT_NE(page.console[0].find("planted"), std::string::npos) << page.console[0];
}

// calibrate --report on a simulated twelve-position session with the
// gyroscope: one shaded interval per position of calib.json in each raw
// plot, one dot on the sphere and one refined residual per position, and
// every section.
TEST(ReportBrowser, CalibrationReport) {
  SKIP_WITHOUT_BROWSER();
  ScratchDir dir;
  const std::string html =
      SimulateAndReport("calibrate", ConfigPath("twelve_position_gyro.yaml"), 4, "calib", dir);
  ASSERT_FALSE(HasFailure());
  const nlohmann::json calib = nlohmann::json::parse(Slurp(dir / "calib.json"));
  const size_t n = calib["positions"].size();
  ASSERT_GE(n, 12u);
  const std::string dom = OpenReport(html, "calibration", dir, 8);
  EXPECT_EQ(Count(dom, "class=\"plot plot-raw"), 2u);
  EXPECT_EQ(Count(dom, "class=\"static-interval\""), 2 * n);
  EXPECT_EQ(Count(dom, "class=\"pose-dot\""), n);
  EXPECT_EQ(Count(dom, "class=\"pose-residual\""), n);
  EXPECT_EQ(Count(dom, "class=\"rotation-residual\""),
            calib["gyro"]["rotation_residual_deg"].size());
  for (const char* id : {"verdict", "signals", "poses", "residuals", "parameters", "correlation",
                         "rotations", "warnings", "solver"}) {
    EXPECT_NE(dom.find(std::string("id=\"") + id + "\""), std::string::npos) << id;
  }
  EXPECT_NE(dom.find("+3 sigma"), std::string::npos);
  EXPECT_NE(dom.find("magnitude fit"), std::string::npos);
  // The stretches the detector rejected (with the config's detector
  // options, on the same log), shaded in each raw plot.
  Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigFile(ConfigPath("twelve_position_gyro.yaml"), &config, &error)) << error;
  ImuLog log;
  ASSERT_TRUE(ReadImuLog(dir / "sim/raw.csv", config.input, &log, &error)) << error;
  StaticDetection detection;
  ASSERT_TRUE(DetectStaticIntervals(log, config.calibration.detector, &detection));
  EXPECT_EQ(detection.intervals.size(), n);
  EXPECT_EQ(Count(dom, "class=\"rejected-stretch\""), 2 * detection.rejected.size());
}

// A session with two disturbed poses: one held with tremor, one cut short.
// The detector rejects both, and the report shades each stretch it rejected
// (as many as the detector reports, in each raw plot) with its reason in the
// legend, beside the numbered intervals it used.
TEST(ReportBrowser, RejectedStretchesAreShadedWithTheirReason) {
  SKIP_WITHOUT_BROWSER();
  Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigFile(ConfigPath("twelve_position.yaml"), &config, &error)) << error;
  SimulatedSession s;
  ASSERT_TRUE(Simulate(config.simulation, 8, &s, &error)) << error;
  StaticDetection clean;
  ASSERT_TRUE(DetectStaticIntervals(s.log, config.calibration.detector, &clean));
  ASSERT_GE(clean.intervals.size(), 12u);
  // Tremor of about 20 times the noise floor's variance over pose 4.
  ImuLog log = s.log;
  std::mt19937 rng(1);
  std::normal_distribution<double> tremor(0.0, std::sqrt(19.0 * clean.accel_noise_floor / 3.0));
  for (size_t i = clean.intervals[3].begin; i < clean.intervals[3].end; ++i) {
    log.accel[i] += internal::DrawVector3([&] { return tremor(rng); });
  }
  // Pose 8 cut to 1.5 s by a jolt after its first 1.5 s.
  const StaticInterval& cut = clean.intervals[7];
  const size_t jolt = cut.begin + static_cast<size_t>(1.5 * config.simulation.sample_rate);
  const double a = 30.0 * std::sqrt(clean.accel_noise_floor);
  for (size_t i = jolt; i < cut.end; ++i) {
    log.accel[i] += a * Eigen::Vector3d(std::sin(0.3 * i), std::cos(0.2 * i), 0.0);
  }
  StaticDetection detection;
  ASSERT_TRUE(DetectStaticIntervals(log, config.calibration.detector, &detection));
  std::set<RejectionReason> reasons;
  for (const RejectedStretch& r : detection.rejected) reasons.insert(r.reason);
  EXPECT_TRUE(reasons.count(RejectionReason::kTooMuchMotion)) << detection.message;
  EXPECT_TRUE(reasons.count(RejectionReason::kTooShort)) << detection.message;
  PipelineInput input;
  input.log = log;
  Calibration c;
  ASSERT_TRUE(RunCalibration(config, input, &c)) << c.message;
  ASSERT_EQ(c.positions.size(), detection.intervals.size());
  ScratchDir dir;
  const std::string html =
      dir.Write("rejected.html", CalibrationToHtml(c, log, "two disturbed poses", detection));
  const std::string dom = OpenReport(html, "calibration_rejected", dir, 8);
  EXPECT_EQ(Count(dom, "class=\"static-interval\""), 2 * c.positions.size());
  EXPECT_EQ(Count(dom, "class=\"rejected-stretch\""), 2 * detection.rejected.size());
  EXPECT_NE(dom.find("rejected: too much motion"), std::string::npos);
  EXPECT_NE(dom.find("rejected: too short"), std::string::npos);
  EXPECT_NE(dom.find("accelerometer variance was typically"), std::string::npos);
}

// A failed calibration still gets its report, and it says "record again".
TEST(ReportBrowser, FailedCalibrationSaysRecordAgain) {
  SKIP_WITHOUT_BROWSER();
  ScratchDir dir;
  ASSERT_EQ(RunCli("simulate --sim_scheme random:6 --seed 5 --output-dir " + (dir / "sim"), dir)
                .exit_code,
            0);
  const std::string html = dir / "failed.html";
  const testing_util::CliResult r =
      RunCli("calibrate --input " + (dir / "sim/raw.csv") + " --output " + (dir / "c.json") +
                 " --report " + html,
             dir);
  ASSERT_NE(r.exit_code, 0);
  const std::string dom = OpenReport(html, "calibration_failed", dir, 2);
  EXPECT_NE(dom.find("class=\"verdict again\""), std::string::npos);
  EXPECT_NE(dom.find("Record the session again"), std::string::npos);
}

// The handheld filter: one convergence plot per state of the report.
TEST(ReportBrowser, HandheldConvergence) {
  SKIP_WITHOUT_BROWSER();
  ScratchDir dir;
  ASSERT_EQ(RunCli("simulate --sim_motion handheld --sim_accel_misalignment 0 "
                   "--sim_gyro_misalignment 0 --seed 3 --output-dir " +
                       (dir / "sim"),
                   dir)
                .exit_code,
            0);
  const std::string html = dir / "handheld.html";
  const testing_util::CliResult r =
      RunCli("calibrate --input " + (dir / "sim/raw.csv") + " --config " +
                 ConfigPath("handheld_kalman.yaml") +
                 " --nominal_scale 0.00059855 --gyro_nominal_scale 0.000133231 --gravity 9.80665 "
                 "--output " +
                 (dir / "c.json") + " --report " + html,
             dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json calib = nlohmann::json::parse(Slurp(dir / "c.json"));
  const std::string dom = OpenReport(html, "calibration_handheld", dir, 4);
  EXPECT_NE(dom.find("id=\"convergence\""), std::string::npos);
  EXPECT_GE(Count(dom, "class=\"plot plot-convergence\""), 6u);
}

// batch --report: a histogram per varying parameter, the planted outlier
// marked and named, the failed units with their messages.
TEST(ReportBrowser, FleetReport) {
  SKIP_WITHOUT_BROWSER();
  ScratchDir dir;
  Config base;
  std::string error;
  ASSERT_TRUE(LoadConfigFile(ConfigPath("twelve_position.yaml"), &base, &error)) << error;
  SimulatorOptions sim = base.simulation;
  sim.hold_seconds = 4.0;
  sim.initial_still_seconds = 4.0;
  sim.rotation_seconds = 2.0;
  sim.accel_bias_std = 0.05;
  std::string manifest = "unit,path\n";
  for (int k = 0; k < 8; ++k) {
    SimulatedSession s;
    ASSERT_TRUE(Simulate(sim, 200 + k, &s, &error)) << error;
    if (k == 3) {
      for (Eigen::Vector3d& a : s.log.accel) a.x() += 1500.0;
    }
    const std::string name = "unit" + std::to_string(k);
    ASSERT_TRUE(WriteImuLogCsv(s.log, dir / (name + ".csv"), &error)) << error;
    manifest += name + "," + (dir / (name + ".csv")) + "\n";
  }
  manifest += "broken," + (dir / "missing.csv") + "\n";
  const std::string html = dir / "fleet.html";
  const testing_util::CliResult r =
      RunCli({"batch", "--manifest", dir.Write("units.csv", manifest), "--config",
              ConfigPath("twelve_position.yaml"), "--output-dir", dir / "out", "--threads", "2",
              "--report", html},
             dir);
  ASSERT_EQ(r.exit_code, 1) << r.err;  // the missing unit
  const std::string dom = OpenReport(html, "fleet", dir, 10);
  EXPECT_GE(Count(dom, "class=\"plot plot-histogram\""), 6u);
  EXPECT_GE(Count(dom, "class=\"outlier-mark\""), 1u);
  EXPECT_NE(dom.find("unit3"), std::string::npos);
  EXPECT_NE(dom.find("missing.csv"), std::string::npos);
  for (const char* id : {"throughput", "parameters", "outliers", "failures"}) {
    EXPECT_NE(dom.find(std::string("id=\"") + id + "\""), std::string::npos) << id;
  }
}

// noise --report on a simulated still log: six log-log plots with their
// points and the fitted terms as lines.
TEST(ReportBrowser, NoiseReport) {
  SKIP_WITHOUT_BROWSER();
  ScratchDir dir;
  NoiseProcessOptions accel;
  accel.rate_hz = 100.0;
  accel.white_noise = 2e-3;
  accel.random_walk = 1.2e-3;
  NoiseProcessOptions gyro = accel;
  gyro.white_noise = 2e-4;
  gyro.random_walk = 3.5e-4;
  std::string error;
  const std::string log = dir / "still.csv";
  ASSERT_TRUE(WriteImuLogCsv(testing_util::StillLog(accel, gyro, 1e-3, 6, 1200.0), log, &error))
      << error;
  const std::string html = dir / "noise.html";
  const testing_util::CliResult r =
      RunCli("noise --input " + log + " --gyro_nominal_scale 0.001 --output " +
                 (dir / "noise.json") + " --report " + html,
             dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string dom = OpenReport(html, "noise", dir, 12);
  EXPECT_EQ(Count(dom, "class=\"plot plot-allan\""), 6u);
  EXPECT_GE(Count(dom, "class=\"allan-point\""), 6u * 8);
  EXPECT_GE(Count(dom, "class=\"noise-term\""), 6u);
  EXPECT_EQ(Count(dom, "data-scale=\"log\""), 12u);
}

// discover --report goes through the same plotting module.
TEST(ReportBrowser, DiscoveryReport) {
  SKIP_WITHOUT_BROWSER();
  ScratchDir dir;
  const std::string html =
      SimulateAndReport("discover", ConfigPath("discovery.yaml"), 2, "discovery", dir);
  ASSERT_FALSE(HasFailure());
  OpenReport(html, "discovery", dir, 4);
}

// printf of one number (the report's FormatNumber).
std::string Printf(const char* format, double v) {
  char b[64];
  std::snprintf(b, sizeof(b), format, v);
  return b;
}

// Text as the browser serialises a text node (&, <, > escaped).
std::string DomText(const std::string& text) {
  std::string out;
  for (char c : text) {
    out += c == '&' ? "&amp;" : c == '<' ? "&lt;" : c == '>' ? "&gt;" : std::string(1, c);
  }
  return out;
}

// Empty when the plan report's DOM shows the plan of plan.json: every pose
// in order as a housing picture of its up direction (the picture's data-up)
// captioned with its instruction and hold (the gyroscope's extra poses
// marked), the turn between each two poses with its instruction, a dot per
// pose on the sphere, a row per parameter in the accelerometer's table (and
// the gyroscope's when planned) with its predicted sigma, and the fixed
// schemes' table; otherwise the first thing missing.
std::string PlanReportProblem(const std::string& dom, const nlohmann::json& plan) {
  const nlohmann::json& poses = plan["poses"];
  const nlohmann::json& turns = plan["rotations"];
  const size_t extra = plan.value("gyro_extra_poses", 0);
  if (Count(dom, "<figure class=\"pose") != poses.size()) return "not one figure per pose";
  if (Count(dom, "<svg class=\"housing\"") != poses.size()) return "not one picture per pose";
  if (Count(dom, "class=\"turn\"") != turns.size()) return "not one turn per pair of poses";
  if (Count(dom, "class=\"pose-dot\"") != poses.size()) return "not one sphere dot per pose";
  size_t at = 0;
  for (size_t k = 0; k < poses.size(); ++k) {
    const std::string pose = "pose " + std::to_string(k + 1);
    const size_t figure = dom.find("<figure class=\"pose", at);
    if (figure == std::string::npos) return pose + ": no figure";
    if (k > 0) {
      const size_t turn = dom.find("class=\"turn\"", at);
      const std::string instruction = DomText(turns[k - 1]["instruction"].get<std::string>());
      if (turn == std::string::npos || turn > figure ||
          dom.substr(turn, dom.find("</div>", turn) - turn).find(instruction) ==
              std::string::npos) {
        return "turn " + std::to_string(k) + " (" + instruction + ") not before " + pose;
      }
    }
    at = dom.find("</figure>", figure);
    const std::string f = dom.substr(figure, at - figure);
    const std::string caption = DomText(poses[k]["instruction"].get<std::string>()) + "; hold " +
                                Printf("%.1f", poses[k]["hold_s"].get<double>()) + " s";
    if (f.find("<svg class=\"housing\"") == std::string::npos) return pose + ": no picture";
    std::istringstream drawn(Attribute(f, "data-up"));
    Eigen::Vector3d up;
    for (int i = 0; i < 3; ++i) {
      if (!(drawn >> up(i)) || std::fabs(up(i) - poses[k]["up"][i].get<double>()) > 1e-3) {
        return pose + ": the picture is not of its up direction";
      }
    }
    if (f.find(caption) == std::string::npos) return pose + ": caption is not '" + caption + "'";
    if (f.find(">" + std::to_string(k + 1) + "</text>") == std::string::npos) {
      return pose + ": picture not numbered";
    }
    const bool gyro = k + extra >= poses.size();
    if ((f.find("pose-gyro") != std::string::npos) != gyro ||
        (f.find("(for the gyroscope)") != std::string::npos) != gyro) {
      return pose + (gyro ? ": not" : ": wrongly") + " marked as a gyroscope pose";
    }
  }
  // The tables: one per planned sensor, a row per parameter with its sigma.
  std::vector<std::string> sensors = {"predicted_std_readable"};
  if (plan.contains("gyro_predicted_std_readable"))
    sensors.push_back("gyro_predicted_std_readable");
  if (Count(dom, "<table class=\"sigma\">") != sensors.size()) return "not one table per sensor";
  size_t table = 0;
  for (const std::string& key : sensors) {
    table = dom.find("<table class=\"sigma\">", table + 1);
    const std::string t = dom.substr(table, dom.find("</table>", table) - table);
    if (Count(t, "<tr>") != plan[key].size() + 1) return key + ": not a row per parameter";
    for (const auto& [name, readable] : plan[key].items()) {
      const std::string row = "<td>" + name + "</td><td>" +
                              Printf("%.3g", readable["value"].get<double>()) + " " +
                              readable["unit"].get<std::string>() + "</td>";
      if (t.find(row) == std::string::npos) return key + ": no row '" + row + "'";
    }
  }
  const size_t schemes = dom.find("<table class=\"schemes\">");
  if (schemes == std::string::npos) return "no schemes table";
  const std::string t = dom.substr(schemes, dom.find("</table>", schemes) - schemes);
  if (t.find("<td>this plan</td><td>" + std::to_string(poses.size()) + "</td>") ==
      std::string::npos) {
    return "schemes table: no row for this plan";
  }
  for (const auto& [name, scheme] : plan["schemes"].items()) {
    if (t.find("<td>" + name + "</td><td>" + std::to_string(scheme["poses"].get<int>()) +
               "</td>") == std::string::npos) {
      return "schemes table: no row for " + name;
    }
  }
  return "";
}

// plan --report with the gyroscope (extra poses for it, timed turns): every
// planned pose drawn and every turn listed in order, the tables, nothing
// external loaded; then defects planted into the DOM, each of which the
// check must catch.
TEST(ReportBrowser, PlanReport) {
  SKIP_WITHOUT_BROWSER();
  ScratchDir dir;
  const std::string html = dir / "plan.html";
  const testing_util::CliResult r =
      RunCli({"plan", "--config", ConfigPath("twelve_position_gyro.yaml"), "--accel_noise_density",
              "2e-3", "--gyro_noise_density", "2e-4", "--target", "accel_bias=0.5mg gyro_bias=5dph",
              "--pose_set", "faces+45", "--output", dir / "plan.json", "--report", html},
             dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json plan = nlohmann::json::parse(Slurp(dir / "plan.json"));
  ASSERT_GT(plan["gyro_extra_poses"].get<int>(), 0) << "the plan should need extra poses";
  ASSERT_EQ(plan["rotations"].size() + 1, plan["poses"].size());
  const std::string dom = OpenReport(html, "plan", dir, 0);
  EXPECT_EQ(PlanReportProblem(dom, plan), "");

  // Planted: a turn left out, a pose left out, the gyroscope's table
  // dropped, two captions swapped, a picture of another direction, an extra
  // pose not marked.
  auto cut = [&](const std::string& open, const std::string& close, size_t nth) {
    size_t a = 0;
    for (size_t i = 0; i <= nth; ++i) a = dom.find(open, i ? a + 1 : 0);
    const size_t b = dom.find(close, a) + close.size();
    return dom.substr(0, a) + dom.substr(b);
  };
  EXPECT_NE(PlanReportProblem(cut("<div class=\"turn\"", "</div>", 3), plan), "");
  EXPECT_NE(PlanReportProblem(cut("<figure class=\"pose", "</figure>", 5), plan), "");
  EXPECT_NE(PlanReportProblem(cut("<table class=\"sigma\">", "</table>", 1), plan), "");
  std::string swapped = dom;
  const std::string first = DomText(plan["poses"][0]["instruction"].get<std::string>());
  const std::string second = DomText(plan["poses"][1]["instruction"].get<std::string>());
  ASSERT_NE(first, second);
  const size_t a = swapped.find("<figcaption>" + first);
  const size_t b = swapped.find("<figcaption>" + second, a);
  ASSERT_NE(b, std::string::npos);
  swapped.replace(b + 12, second.size(), first);
  swapped.replace(a + 12, first.size(), second);
  EXPECT_NE(PlanReportProblem(swapped, plan), "");
  std::string turned = dom;
  const size_t drawn = turned.find("data-up=\"", turned.find("<figure class=\"pose", 0) + 1);
  turned.replace(drawn + 9, turned.find('"', drawn + 9) - drawn - 9, "0.0000 0.0000 -1.0000");
  EXPECT_NE(PlanReportProblem(turned, plan), "");
  std::string unmarked = dom;
  unmarked.replace(unmarked.rfind("pose pose-gyro"), 14, "pose");
  EXPECT_NE(PlanReportProblem(unmarked, plan), "");
}

// A one-hour 200 Hz session: the report stays under 2 MB (min/max
// envelopes), and the browser's load time is recorded (no wall-clock
// assertion: benchmarks/RESULTS.md has the measurement).
TEST(ReportBrowser, HourLongSessionStaysSmall) {
  Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigFile(ConfigPath("twelve_position_gyro.yaml"), &config, &error)) << error;
  SimulatorOptions sim = config.simulation;
  sim.sample_rate = 200.0;
  sim.hold_seconds = 300.0;
  sim.initial_still_seconds = 20.0;
  PipelineInput input;
  SimulatedSession s;
  ASSERT_TRUE(Simulate(sim, 7, &s, &error)) << error;
  input.log = s.log;
  ASSERT_GE(input.log.t.back() - input.log.t.front(), 3600.0);
  Calibration c;
  ASSERT_TRUE(RunCalibration(config, input, &c)) << c.message;
  StaticDetection detection;
  ASSERT_TRUE(DetectStaticIntervals(input.log, config.calibration.detector, &detection));
  const std::string html = CalibrationToHtml(c, input.log, "one hour at 200 Hz", detection);
  EXPECT_LT(html.size(), 2u << 20);
  ::testing::Test::RecordProperty("bytes", std::to_string(html.size()));
  SKIP_WITHOUT_BROWSER();
  ScratchDir dir;
  const std::string dom = OpenReport(dir.Write("hour.html", html), "calibration_hour", dir, 8);
  EXPECT_EQ(Count(dom, "class=\"static-interval\""), 2 * c.positions.size());
  std::printf("one-hour report: %zu bytes, load %s ms in Chromium\n", html.size(),
              Attribute(dom, "data-load-ms").c_str());
}

}  // namespace
}  // namespace gravcal
