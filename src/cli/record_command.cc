// gravcal record (issue 37): a live text stream into the Recorder
// (workflows/recorder.h), its events on stderr (or the terminal UI) and as
// JSON lines (--events), and at the end the recorded log, the calibration
// and the report, written together.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/record_tui.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/files.h"
#include "gravcal/io/noise_io.h"
#include "gravcal/workflows/recorder.h"
#include "io/line_source.h"
#include "io/log_text.h"

namespace gravcal {
namespace cli {

namespace {

// Seconds without a line after which the stream is said to stall.
constexpr double kStallSeconds = 3.0;
// Garbage lines whose message is shown (the rest are counted).
constexpr size_t kShownGarbage = 5;

volatile sig_atomic_t g_interrupted = 0;

void OnInterrupt(int) { g_interrupted = 1; }

// Ctrl-C (and SIGTERM) interrupt the read instead of killing the process,
// so that what was recorded is written.
void CatchInterrupts() {
  struct sigaction action {};
  action.sa_handler = OnInterrupt;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: poll returns EINTR
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  signal(SIGPIPE, SIG_IGN);
}

// The events: JSON lines to a file or standard output, flushed per event;
// a sentence on stderr unless the terminal UI shows them.
class EventSink {
 public:
  bool Open(const std::string& path, std::string* error) {
    if (path.empty()) return true;
    if (path == "-") {
      file_ = stdout;
      return true;
    }
    file_ = std::fopen(path.c_str(), "w");
    owned_ = true;
    if (file_ == nullptr) *error = path + ": cannot write the events";
    return file_ != nullptr;
  }
  ~EventSink() {
    if (owned_ && file_) std::fclose(file_);
  }
  void Put(const RecorderEvent& e, RecordTui* tui) {
    if (file_) {
      std::fprintf(file_, "%s\n", e.json.c_str());
      std::fflush(file_);
    }
    if (tui->active()) {
      tui->Log(e.text);
    } else {
      std::fprintf(stderr, "gravcal record: %s\n", e.text.c_str());
    }
  }

 private:
  std::FILE* file_ = nullptr;
  bool owned_ = false;
};

}  // namespace

int RunRecord(const RecordArgs& args) {
  if (args.input.empty()) {
    return Fail("record needs --input (-, a serial device, udp://:PORT or tcp://HOST:PORT)");
  }
  if (args.output_dir.empty()) return Fail("record needs --output-dir <folder>");
  std::string error;
  if (!args.config.IsValid(&error)) return Fail(error);
  if (!args.config.input.IsValid(&error)) return Fail("input: " + error);
  if (args.config.input.format != LogFormat::kCsv &&
      args.config.input.format != LogFormat::kWhitespace) {
    return Fail(
        "record reads text lines (format csv or whitespace); binary protocols are not "
        "read");
  }
  RecorderOptions options;
  options.request = args.request;
  options.max_time_seconds = args.request.max_time_seconds;
  options.request.max_time_seconds = 0.0;
  ImuNoise noise;
  if (!args.noise.empty()) {
    if (!ReadNoiseJson(args.noise, &noise, &error)) return Fail(error);
    options.request.noise_model = &noise.model;
  }
  Recorder recorder;
  if (!recorder.Start(args.config, options, &error)) return Fail(error);
  if (!MakeFolders(args.output_dir, &error)) return Fail(error);
  internal::LineSource source;
  if (!source.Open(args.input, args.baud, &error)) return Fail(error);
  EventSink sink;
  if (!sink.Open(args.events, &error)) return Fail(error);
  CatchInterrupts();
  RecordTui tui;
  tui.Begin(isatty(STDERR_FILENO) == 1 && args.events != "-");

  internal::LogRowParser parser(source.name(), args.config.input, false);
  using Clock = std::chrono::steady_clock;
  Clock::time_point last_data = Clock::now();
  bool stalled = false;
  size_t line_number = 0;
  std::string reason;
  std::vector<std::string> lines;
  while (reason.empty()) {
    if (g_interrupted) {
      reason = "interrupted";
      break;
    }
    lines.clear();
    std::string read_error;
    const internal::LineSource::Status status = source.Read(250, &lines, &read_error);
    if (status == internal::LineSource::Status::kError) {
      sink.Put(recorder.Warn("source", read_error), &tui);
      reason = "source_error";
    }
    if (!lines.empty()) {
      last_data = Clock::now();
      if (stalled) sink.Put(recorder.Warn("stall", "data again"), &tui);
      stalled = false;
    } else if (!stalled &&
               std::chrono::duration<double>(Clock::now() - last_data).count() >= kStallSeconds) {
      stalled = true;
      sink.Put(recorder.Warn("stall", "no data for " + std::to_string(int(kStallSeconds)) +
                                          " s from " + source.name()),
               &tui);
    }
    for (const std::string& line : lines) {
      ++line_number;
      bool row = false;
      std::string line_error;
      if (!parser.Line(line, line_number, &row, &line_error)) {
        recorder.CountGarbage();
        if (recorder.status().garbage_lines <= kShownGarbage) {
          sink.Put(recorder.Warn("garbage", line_error + " (line skipped)"), &tui);
        }
        continue;
      }
      if (!row) continue;
      using internal::LogSlot;
      const Eigen::Vector3d accel(parser.value(LogSlot::kAx), parser.value(LogSlot::kAy),
                                  parser.value(LogSlot::kAz));
      const bool gyro =
          parser.has(LogSlot::kGx) && parser.has(LogSlot::kGy) && parser.has(LogSlot::kGz);
      const Eigen::Vector3d rate =
          gyro ? Eigen::Vector3d(parser.value(LogSlot::kGx), parser.value(LogSlot::kGy),
                                 parser.value(LogSlot::kGz))
               : Eigen::Vector3d::Zero();
      const double temperature = parser.has(LogSlot::kTemp) ? parser.value(LogSlot::kTemp) : NAN;
      for (const RecorderEvent& e :
           recorder.Feed(parser.value(LogSlot::kT), accel, rate, temperature, gyro)) {
        sink.Put(e, &tui);
      }
      if (recorder.done()) {
        reason = recorder.status().done_reason;
        break;
      }
    }
    tui.Draw(recorder.status(), stalled);
    if (reason.empty() && status == internal::LineSource::Status::kEnd) {
      if (!read_error.empty()) sink.Put(recorder.Warn("disconnect", read_error), &tui);
      reason = "end_of_input";
    }
  }
  tui.End();

  const std::string log_path = args.output_dir + "/record.csv";
  const std::string json_path = args.output_dir + "/calibration.json";
  const std::string report_path = args.output_dir + "/report.html";
  RecorderResult result;
  // The files named in the done event are decided after the calibration.
  if (!recorder.Finish(reason, {}, &result, &error)) return Fail(error);
  std::vector<FileContents> files = {{log_path, result.log_csv}, {report_path, result.report_html}};
  if (result.ok) {
    files.push_back(
        {json_path, CalibrationToJson(result.calibration, args.config.output_covariance, {})});
  }
  if (!WriteFilesAtomically(files, &error)) return Fail(error);
  std::vector<std::string> names;
  for (const FileContents& f : files) names.push_back(f.path);
  sink.Put(recorder.DoneEvent(names), &tui);
  if (!result.ok) return Fail("calibration: " + result.calibration.message, 2);
  std::fprintf(stderr, "gravcal record: %s; wrote %s, %s and %s\n",
               result.calibration.BriefReport().c_str(), log_path.c_str(), json_path.c_str(),
               report_path.c_str());
  return 0;
}

}  // namespace cli
}  // namespace gravcal
