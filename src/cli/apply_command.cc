// gravcal apply: every term of a calibration applied to a raw log, sample by
// sample (io/imu_stream.h: the log reader's layouts, rules and messages; text
// in constant memory), "-" for standard input and output. Exit 0 written; 1
// bad input (no output file; on standard output nothing is written when the
// problem shows before the first sample).
//
// A two-stage pipeline (issue 39 part 3): this thread reads and parses the
// log into blocks of rows (and the temperature's rate, which runs in order);
// worker threads (one per core) correct and format whole blocks into text;
// this thread writes the blocks in their order. The output is the same
// bytes as one thread's, and an error is the first one in row order.
#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "cli/commands.h"
#include "gravcal/core/thermal_rate.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/imu_stream.h"
#include "gravcal/io/log_reader.h"

namespace gravcal {
namespace cli {

namespace {

// The comment lines above the header: what was applied and the units.
std::vector<std::string> OutputComment(const std::string& calibration_path,
                                       const LoadedCalibration& c, bool gyro) {
  std::vector<std::string> lines = {
      "gravcal apply: corrected with " + calibration_path +
          (c.provenance.log_file.empty() ? "" : " (from " + c.provenance.log_file + ")"),
      std::string("units: t s (as read), ax ay az m/s^2 (housing frame)") +
          (gyro ? (c.corrector.has_gyro ? ", gx gy gz rad/s"
                                        : ", gx gy gz raw (the calibration has no gyroscope)")
                : "") +
          ", temp degC (as read)"};
  return lines;
}

// Samples further than this outside a thermal model's valid range are
// counted in apply's warning, degrees C.
constexpr double kClampWarningDegrees = 0.5;

// Rows per block handed to a worker.
constexpr size_t kApplyBlockRows = 8192;

// A block of rows: read here, corrected and formatted by a worker.
struct ApplyBlock {
  size_t rows = 0;
  std::vector<double> t = std::vector<double>(kApplyBlockRows);
  std::vector<Eigen::Vector3d> accel = std::vector<Eigen::Vector3d>(kApplyBlockRows);
  std::vector<Eigen::Vector3d> gyro = std::vector<Eigen::Vector3d>(kApplyBlockRows);
  std::vector<double> temperature = std::vector<double>(kApplyBlockRows);
  std::vector<double> rates = std::vector<double>(kApplyBlockRows);
  // The reader's position() of each row, for messages.
  std::vector<size_t> positions = std::vector<size_t>(kApplyBlockRows);
  std::unique_ptr<bool[]> clamped = std::make_unique<bool[]>(kApplyBlockRows);
  std::unique_ptr<char[]> text =
      std::make_unique<char[]>(kApplyBlockRows * ImuCsvStreamWriter::kMaxRowBytes);
  size_t text_size = 0;
  // The first row that failed (rows when none), and how.
  size_t failed_row = 0;
  bool no_root = false;
  // Samples clamped by more than kClampWarningDegrees, and their range.
  size_t clamped_count = 0;
  double lowest = INFINITY, highest = -INFINITY;
  bool done = true;  // Guarded by ApplyWorkers::mutex_.

  void Put(size_t i, const ImuSample& s) {
    t[i] = s.t;
    accel[i] = s.accel;
    gyro[i] = s.gyro;
    temperature[i] = s.temperature;
  }
};

// Corrects and formats a block's rows, up to the first row that fails
// (ImuCorrector::CorrectRows, then the finite check, row by row as one
// thread would).
void CorrectBlock(const ImuCorrector& corrector, bool gyro, bool temperature, ApplyBlock* b) {
  const size_t corrected =
      corrector.CorrectRows(b->rows, b->temperature.data(), b->rates.data(), b->t.data(),
                            b->accel.data(), gyro ? b->gyro.data() : nullptr, b->clamped.get());
  b->failed_row = b->rows;
  b->no_root = false;
  // Finite readings and a checked calibration can still overflow (a
  // reading of 1e300 counts): nothing that is not a number is written.
  for (size_t i = 0; i < corrected; ++i) {
    if (!b->accel[i].allFinite() || !b->gyro[i].allFinite()) {
      b->failed_row = i;
      break;
    }
  }
  if (corrected < b->failed_row) {
    b->failed_row = corrected;
    b->no_root = true;
  }
  b->clamped_count = 0;
  b->lowest = INFINITY;
  b->highest = -INFINITY;
  char* p = b->text.get();
  const ThermalModel& th = corrector.thermal;
  ImuSample sample;
  for (size_t i = 0; i < b->failed_row; ++i) {
    sample.t = b->t[i];
    sample.accel = b->accel[i];
    sample.gyro = b->gyro[i];
    sample.temperature = b->temperature[i];
    p = ImuCsvStreamWriter::FormatRow(sample, gyro, temperature, p);
    // Clamped by more than the temperature sensor's noise: counted.
    if (b->clamped[i] && (sample.temperature < th.min_temperature - kClampWarningDegrees ||
                          sample.temperature > th.max_temperature + kClampWarningDegrees)) {
      ++b->clamped_count;
      b->lowest = std::min(b->lowest, sample.temperature);
      b->highest = std::max(b->highest, sample.temperature);
    }
  }
  b->text_size = static_cast<size_t>(p - b->text.get());
}

// Worker threads running CorrectBlock on the blocks submitted, in any
// order; Wait(b) returns when b is done. Without threads, Submit runs it.
class ApplyWorkers {
 public:
  ApplyWorkers(int threads, const ImuCorrector& corrector, bool gyro, bool temperature)
      : corrector_(corrector), gyro_(gyro), temperature_(temperature) {
    // A thread that cannot be started (a process limit) leaves fewer, or
    // none: then Submit corrects on the calling thread.
    try {
      for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { Run(); });
    } catch (const std::system_error&) {
    }
  }
  ~ApplyWorkers() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    work_.notify_all();
    for (std::thread& t : threads_) t.join();
  }
  void Submit(ApplyBlock* b) {
    if (threads_.empty()) return CorrectBlock(corrector_, gyro_, temperature_, b);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      b->done = false;
      queue_.push_back(b);
    }
    work_.notify_one();
  }
  void Wait(ApplyBlock* b) {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [b] { return b->done; });
  }

 private:
  void Run() {
    for (;;) {
      ApplyBlock* b = nullptr;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        work_.wait(lock, [this] { return stop_ || !queue_.empty(); });
        if (queue_.empty()) return;
        b = queue_.front();
        queue_.pop_front();
      }
      CorrectBlock(corrector_, gyro_, temperature_, b);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        b->done = true;
      }
      done_.notify_all();
    }
  }

  const ImuCorrector& corrector_;
  const bool gyro_, temperature_;
  std::mutex mutex_;
  std::condition_variable work_, done_;
  std::deque<ApplyBlock*> queue_;
  bool stop_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace

int RunApply(const ApplyArgs& args) {
  std::string calibration_path, error;
  if (!ResolveCalibrationPath(args.calibration, args.stored, &calibration_path, &error)) {
    return Fail(error);
  }
  if (calibration_path.empty()) {
    return Fail("apply needs --calibration <calib.json> (or --store DIR --unit SN)");
  }
  if (args.input.empty()) return Fail("apply needs --input <raw log, or - for standard input>");
  if (args.output.empty())
    return Fail("apply needs --output <corrected.csv, or - for standard output>");
  LoadedCalibration calibration;
  if (!ReadCalibrationJson(calibration_path, &calibration, &error)) return Fail(error);
  for (const std::string& key : calibration.undetermined) {
    std::fprintf(stderr,
                 "gravcal: warning: %s: %s is undetermined in the calibration; applied as 0\n",
                 calibration_path.c_str(), key.c_str());
  }
  const ImuCorrector& corrector = calibration.corrector;
  if (!args.config.IsValid(&error)) return Fail(error);
  // Every layout through the one checked reader (io/imu_stream.h): text in
  // constant memory, the same rules and messages as calibrate.
  ImuCsvStreamReader reader;
  if (!reader.Open(args.input, args.config.input, &error)) return Fail(error);
  if (corrector.RequiresTemperature() && !reader.has_temperature()) {
    return Fail(reader.name() +
                ": the calibration has temperature effects and needs a 'temp' column");
  }
  if (corrector.HasThermal() && !reader.has_temperature()) {
    return Fail(reader.name() +
                ": the calibration has a thermal model (key 'thermal') and needs a 'temp' column");
  }
  if (corrector.has_gyro && !reader.has_gyro()) {
    std::fprintf(stderr,
                 "gravcal: warning: %s has no gx, gy, gz: only the accelerometer is corrected\n",
                 reader.name().c_str());
  }
  // The first sample is read before the output is opened, so that a bad
  // first row writes nothing (a log without one is an error).
  const bool gyro = reader.has_gyro(), temperature = reader.has_temperature();
  const int threads = static_cast<int>(std::min(8u, std::thread::hardware_concurrency()));
  std::vector<ApplyBlock> ring(2 * static_cast<size_t>(std::max(threads, 1)) + 2);
  ImuSample sample;
  if (!reader.Next(&sample, &error)) return Fail(error);
  ImuCsvStreamWriter writer;
  if (!writer.Open(args.output, gyro, temperature,
                   OutputComment(calibration_path, calibration, gyro), &error)) {
    return Fail(error);
  }
  ApplyWorkers workers(threads, corrector, gyro, temperature);
  size_t count = 0, submitted = 0, written = 0;
  size_t clamped_count = 0;
  double lowest = INFINITY, highest = -INFINITY;
  // Writes the oldest block submitted; false with `error` set when one of
  // its rows failed (nothing after it is written).
  auto write_oldest = [&]() {
    ApplyBlock& b = ring[written++ % ring.size()];
    workers.Wait(&b);
    if (b.failed_row < b.rows) {
      error = reader.where(b.positions[b.failed_row]) +
              (b.no_root ? ": the quadratic term has no real root (reading outside the "
                           "calibrated range)"
                         : ": the corrected sample is not finite (the reading times the "
                           "calibration overflows)");
      return false;
    }
    count += b.rows;
    clamped_count += b.clamped_count;
    lowest = std::min(lowest, b.lowest);
    highest = std::max(highest, b.highest);
    return writer.WriteRows(b.text.get(), b.text_size, &error);
  };
  // Issue 35: the thermal model's lag needs the element temperature's rate,
  // which runs through the rows in order (here); its range is clamped (and
  // counted for one warning).
  ThermalElementRate rate(corrector.thermal.lag_time_constant);
  std::string read_error;
  for (bool more = true; more;) {
    if (submitted - written == ring.size() && !write_oldest()) {
      writer.Abort();
      return Fail(error);
    }
    ApplyBlock& b = ring[submitted % ring.size()];
    b.rows = 0;
    // The first sample was read above.
    for (bool have = submitted == 0; b.rows < kApplyBlockRows; have = false) {
      if (!have && !reader.Next(&sample, &read_error)) {
        more = false;
        break;
      }
      b.Put(b.rows, sample);
      b.rates[b.rows] = rate.Add(sample.t, sample.temperature);
      b.positions[b.rows] = reader.position();
      ++b.rows;
    }
    if (b.rows > 0) {
      workers.Submit(&b);
      ++submitted;
    }
  }
  // Errors in row order: a row that failed to correct comes before a row
  // that failed to read (which is after every row read).
  while (written < submitted) {
    if (!write_oldest()) {
      writer.Abort();
      return Fail(error);
    }
  }
  if (!read_error.empty()) {
    writer.Abort();
    return Fail(read_error);
  }
  if (!writer.Commit(&error)) return Fail(error);
  if (clamped_count > 0) {
    std::fprintf(stderr,
                 "gravcal: warning: %zu samples (temperatures %.1f to %.1f degC) lie more than "
                 "0.5 degC outside the thermal model's range [%.1f, %.1f] degC; the correction "
                 "there is clamped at the range's ends, as PX4 does\n",
                 clamped_count, lowest, highest, corrector.thermal.min_temperature,
                 corrector.thermal.max_temperature);
  }
  if (args.output != "-") {
    std::fprintf(stderr, "gravcal: corrected %zu samples; wrote %s\n", count, args.output.c_str());
  }
  return 0;
}

}  // namespace cli
}  // namespace gravcal
