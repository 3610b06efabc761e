// gravcal plan and gravcal check (workflows/plan.h).
#include <cstdio>

#include "cli/commands.h"
#include "cli/read_long_log.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/files.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/io/noise_io.h"
#include "gravcal/io/plan_io.h"
#include "gravcal/workflows/plan.h"
#include "gravcal/workflows/report.h"

namespace gravcal {
namespace cli {

namespace {

// The request from the flags with the noise model of `noise_path` (--noise)
// read into *noise (kept alive by the caller). False with *error on an
// unreadable noise file.
bool RequestWithNoise(const PlanRequest& flags, const std::string& noise_path, ImuNoise* noise,
                      PlanRequest* request, std::string* error) {
  *request = flags;
  if (!noise_path.empty()) {
    if (!ReadNoiseJson(noise_path, noise, error)) return false;
    request->noise_model = &noise->model;
  }
  return true;
}

}  // namespace

int RunPlan(const PlanArgs& args) {
  if (!args.verify_calibration.empty()) return RunPlanVerify(args);
  if (args.output.empty()) return Fail("plan needs --output <plan.json>");
  std::string error;
  ImuNoise noise;
  PlanRequest request;
  if (!RequestWithNoise(args.request, args.noise, &noise, &request, &error)) return Fail(error);
  RecordingPlan plan;
  if (!MakeRecordingPlan(args.config, request, &plan, &error)) return Fail(error);
  if (!WriteFilesAtomically({{args.output, PlanToJson(plan)},
                             {args.report, args.report.empty() ? "" : PlanToHtml(plan)}},
                            &error)) {
    return Fail(error);
  }
  std::fprintf(stderr, "gravcal: wrote %s: %s\n", args.output.c_str(), plan.message.c_str());
  return 0;
}

int RunCheck(const PlanArgs& args) {
  if (args.input.empty()) return Fail("check needs --input <session.csv>");
  std::string error;
  ImuNoise noise;
  PlanRequest request;
  if (!RequestWithNoise(args.request, args.noise, &noise, &request, &error)) return Fail(error);
  if (!args.config.input.IsValid(&error)) return Fail("input: " + error);
  ImuLog log;
  if (!ReadLongLog(args.input, args.config.input, &log, &error)) return Fail(error);
  CoverageReport report;
  if (!CheckRecording(log, args.config, request, &report, &error)) return Fail(error);
  std::printf("%s", CoverageReportText(report).c_str());
  return 0;
}

JsonSections CalibrationCheckSections(const CalibrateArgs& args, const Session& session,
                                      double pose_disturbance) {
  // Issue 35: the thermal method's check adds what the temperature span
  // allows (CoverageReport::temperature).
  if (!args.check ||
      (args.config.method != Method::kTwelvePosition && args.config.method != Method::kThermal)) {
    return {};
  }
  // The session's noise model (read with the log), its poses (detected once).
  PlanRequest request;
  request.noise_model = session.noise_model();
  request.pose_disturbance = pose_disturbance;
  CoverageReport report;
  std::string error;
  if (!CheckRecording(session, args.config, request, &report, &error)) return {};
  std::fprintf(stderr, "check: %s", CoverageReportText(report).c_str());
  return {{"check", CoverageToJson(report)}};
}

}  // namespace cli
}  // namespace gravcal
