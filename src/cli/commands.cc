#include "cli/commands.h"

#include <sys/stat.h>

#include <cmath>
#include <cstdio>

#include "cli/read_long_log.h"
#include "gravcal/io/attitude_fixture.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/files.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/io/long_log.h"
#include "gravcal/io/plan_io.h"
#include "gravcal/methods/twelve_position.h"
#include "gravcal/simulation/handheld_simulator.h"
#include "gravcal/simulation/simulated_attitudes.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/method_registry.h"
#include "gravcal/workflows/multi_imu_log.h"
#include "gravcal/workflows/pipeline.h"
#include "gravcal/workflows/report.h"
#include "gravcal/workflows/simulation_workflow.h"

namespace gravcal {
namespace cli {

int Fail(const std::string& message, int code) {
  std::fprintf(stderr, "gravcal: error: %s\n", message.c_str());
  return code;
}

bool ReadLongLog(const std::string& path, const LogReaderOptions& input, ImuLog* log,
                 std::string* error) {
  LongLogReading reading;
  reading.max_samples = static_cast<size_t>(input.max_log_entries);
  if (!ReadImuLogBounded(path, input, &reading, log, nullptr, error)) return false;
  const std::string said = reading.Describe();
  if (!said.empty()) std::fprintf(stderr, "gravcal: warning: %s\n", said.c_str());
  return true;
}

namespace {

bool CheckConfig(const Config& config, std::string* error) { return config.IsValid(error); }

void PrintWarnings(const Calibration& c) {
  for (const std::string& w : c.warnings) std::fprintf(stderr, "gravcal: warning: %s\n", w.c_str());
}

// "1.234 +- 0.005" or "1.234 (not determined)".
std::string WithStd(double value, double std, const char* format) {
  char buffer[128];
  char v[48];
  std::snprintf(v, sizeof(v), format, value);
  if (std::isfinite(std)) {
    char s[48];
    std::snprintf(s, sizeof(s), format, std);
    std::snprintf(buffer, sizeof(buffer), "%s +- %s", v, s);
  } else {
    std::snprintf(buffer, sizeof(buffer), "%s (fixed or not determined)", v);
  }
  return buffer;
}

}  // namespace

int RunDemo(const DemoArgs& args) {
  std::string error;
  if (!CheckConfig(args.config, &error)) return Fail(error);
  SimulatedSession session;
  if (!Simulate(args.config.simulation, args.seed, &session, &error)) return Fail(error);
  CalibrationOptions options = args.config.calibration;
  if (options.gravity.gravity <= 0.0 && std::isnan(options.gravity.latitude)) {
    options.gravity.gravity = session.gravity;
  }
  options.nominal_scale = 1.0 / session.accel_units_per_si;
  Calibration c;
  const bool ok = CalibrateAccelerometer(session.log, options, &c);
  std::printf("gravcal demo: simulated '%s' session, seed %llu, %zu samples at %.0f Hz, raw %s\n",
              ToString(args.config.simulation.scheme).c_str(),
              static_cast<unsigned long long>(args.seed), session.log.size(),
              args.config.simulation.sample_rate,
              args.config.simulation.raw_counts ? "counts" : "m/s^2");
  std::printf("detected %zu static positions; %s\n\n", c.positions.size(), c.message.c_str());
  PrintWarnings(c);
  if (!ok) return Fail(c.message, 2);
  // The magnitude determines b and U; compare those with the truth's.
  const AccelModel& est = c.accel.model;
  const AccelModel& truth = session.accel_truth;
  std::printf("%-8s %16s %34s %10s\n", "param", "truth", "estimate +- std", "err/std");
  auto row = [](const char* name, double t, double e, double s, const char* fmt) {
    char tb[32];
    std::snprintf(tb, sizeof(tb), fmt, t);
    std::printf("%-8s %16s %34s %10.2f\n", name, tb, WithStd(e, s, fmt).c_str(),
                std::isfinite(s) && s > 0 ? (e - t) / s : NAN);
  };
  const char* axes = "xyz";
  for (int i = 0; i < 3; ++i) {
    const std::string name = std::string("bias_") + axes[i];
    row(name.c_str(), truth.bias(i), est.bias(i), c.accel.bias_std(i), "%.3f");
  }
  for (int r = 0; r < 3; ++r) {
    for (int col = r; col < 3; ++col) {
      if (est.parameterization == AccelParameterization::kScale && r != col) continue;
      const std::string name = std::string("u_") + axes[r] + axes[col];
      // matrix_std of M = U (R = I) is the std of U.
      row(name.c_str(), truth.upper(r, col), est.upper(r, col), c.accel.matrix_std(r, col), "%.6e");
    }
  }
  std::printf(
      "\n|a| - g over positions, m/s^2: before (nominal scale) rms %.4f max %.4f; "
      "coarse rms %.5f; after rms %.5f max %.5f\n",
      c.residual_nominal.rms, c.residual_nominal.max, c.residual_coarse.rms, c.residual_refined.rms,
      c.residual_refined.max);
  std::printf("solver: %s, %d iterations, %s, %.1f us; chi2 %.2f on %d dof\n",
              c.solver_name.c_str(), c.refinement.iterations, c.refinement.termination.c_str(),
              c.refinement.solve_seconds * 1e6, c.refinement.chi2, c.refinement.dof);
  return 0;
}

int RunCalibrate(const CalibrateArgs& args) {
  if (args.input.empty()) return Fail("calibrate needs --input <raw log>");
  if (!args.output_dir.empty()) {
    return Fail(
        "--output-dir is for a multi-IMU config (one with 'imus:', configs/multi_imu.yaml); "
        "one IMU writes --output <calib.json>");
  }
  if (args.output.empty()) return Fail("calibrate needs --output <calib.json>");
  std::string error;
  if (!CheckConfig(args.config, &error)) return Fail(error);
  // The limits are read once, before the work.
  AcceptanceLimits limits;
  if (!args.limits.empty() && !ReadAcceptanceLimits(args.limits, &limits, &error)) {
    return Fail(error);
  }
  // --history only for a method that keeps one, said before the work.
  const CalibrationMethod* method = FindCalibrationMethod(args.config.method);
  if (!args.history.empty() && method != nullptr && !method->keeps_history) {
    return Fail("--history: method '" + method->name +
                "' keeps no estimate history (handheld_kalman does)");
  }
  // The log is read once: its provenance hash comes from the same bytes.
  // In bounded memory: a long log is read as block means (io/long_log.h).
  Session session;
  CalibrationProvenance provenance;
  LongLogReading reading;
  reading.max_samples = static_cast<size_t>(args.config.input.max_log_entries);
  if (!ReadImuLogBounded(args.input, args.config.input, &reading, &session.log, &provenance,
                         &error)) {
    return Fail(error);
  }
  SessionFiles files;
  files.attitudes_path = args.attitudes;
  files.segments_path = args.segments;
  files.noise_path = args.noise;
  Calibration c;
  const bool ok = RunCalibration(args.config, files, &session, &c);
  c.provenance = provenance;
  AddLongLogWarning(reading, &c);
  PrintWarnings(c);
  // The report also for a failed calibration: it says why. For a session of
  // static poses it shows what the detector rejected too (the detection the
  // method used).
  const ImuLog& log = session.log;
  if (!args.report.empty() &&
      !WriteFileAtomically(args.report,
                           !c.positions.empty() && session.detection_ok
                               ? CalibrationToHtml(c, log, args.input, session.detection)
                               : CalibrationToHtml(c, log, args.input),
                           &error)) {
    return Fail(error);
  }
  // 2 only for a solver that ran and did not converge; 1 for the data.
  if (!ok) return Fail(c.message, c.not_converged ? 2 : 1);
  // The history and the calibration are put in place together (the report,
  // written above, also says why a calibration failed).
  std::vector<FileContents> outputs;
  if (!args.history.empty()) {
    outputs.push_back({args.history, ""});
    if (!HistoryToCsv(c, &outputs.back().contents, &error))
      return Fail(args.history + ": " + error);
  }
  const VarianceComponent& scatter = c.accel.pose_variance;
  const std::string json =
      CalibrationToJson(c, args.config.output_covariance,
                        CalibrationCheckSections(
                            args, session, scatter.absorbed ? std::sqrt(scatter.variance) : 0.0));
  if (args.output != "-") outputs.push_back({args.output, json});
  if (!WriteFilesAtomically(outputs, &error) ||
      (args.output == "-" && !WriteOutput(args.output, json, &error))) {
    return Fail(error);
  }
  std::fprintf(stderr, "gravcal: %s; wrote %s\n", c.BriefReport().c_str(),
               args.output == "-" ? "standard output" : args.output.c_str());
  return FinishAcceptance(args, c, args.limits.empty() ? nullptr : &limits);
}

int RunSimulate(const SimulateArgs& args) {
  if (IsMultiImuConfigFile(args.config_path)) return RunPlateSimulate(args);
  if (!args.stream.empty()) return RunSimulateStream(args);
  if (args.rate != 0.0 || !args.follow_events.empty()) {
    return Fail("--rate and --follow-events go with simulate --stream");
  }
  if (args.output_dir.empty()) return Fail("simulate needs --output-dir <folder>");
  std::string error;
  SimulationRequest request;
  request.plan_path = args.plan;
  request.seed = args.seed;
  SimulationFiles files;
  if (!SimulateFromConfig(args.config, request, &files, &error)) return Fail(error);
  const SimulatedSession& session = files.session;
  if (!MakeFolders(args.output_dir, &error)) return Fail(error);
  const std::string raw = args.output_dir + "/raw.csv";
  const std::string truth = args.output_dir + "/truth.json";
  const std::string attitudes = args.output_dir + "/attitudes.csv";
  const std::string segments_path = args.output_dir + "/segments.csv";
  const bool segments = !files.segments_csv.empty();
  std::string raw_csv;
  if (!ImuLogToCsv(session.log, &raw_csv, &error)) return Fail(raw + ": " + error);
  // All four files or none.
  if (!WriteFilesAtomically({{raw, std::move(raw_csv)},
                             {truth, files.truth_json},
                             {attitudes, files.attitudes_csv},
                             {segments ? segments_path : "", files.segments_csv}},
                            &error)) {
    return Fail(error);
  }
  std::fprintf(stderr, "gravcal: wrote %s (%zu samples), %s and %s%s%s\n", raw.c_str(),
               session.log.size(), truth.c_str(), attitudes.c_str(), segments ? " and " : "",
               segments ? segments_path.c_str() : "");
  return 0;
}

}  // namespace cli
}  // namespace gravcal
