// gravcal compare a.json b.json and gravcal verify (issue 36): is it the same
// unit, unchanged? Exit codes: 0 consistent, 3 changed, 1 bad input or a
// calibration that cannot be tested (no covariance), nothing written then.
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/commands.h"
#include "gravcal/estimation/calibration_comparison.h"
#include "gravcal/estimation/check_session.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/calibration_uncertainty_io.h"
#include "gravcal/io/comparison_io.h"
#include "gravcal/io/files.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/workflows/compare.h"

namespace gravcal {
namespace cli {
namespace {

constexpr int kChanged = 3;

// The parameter table and the verdict, on standard output.
void PrintComparison(const ComparisonResult& r, const char* difference_label) {
  std::printf("%-24s %14s %12s %8s %10s\n", "parameter", difference_label, "std", "z", "mdc");
  for (size_t i = 0; i < r.parameters.size(); ++i) {
    const ParameterDifference& p = r.parameters[i];
    std::printf("%-24s %14.6g %12.4g %8.2f %10.4g\n", p.name.c_str(), p.difference, p.std, p.z,
                i < r.minimal_detectable_change.size() ? r.minimal_detectable_change[i] : NAN);
  }
  for (const std::string& n : r.undetermined) {
    std::printf("%-24s not determined by a calibration: left out of the test\n", n.c_str());
  }
  for (const std::string& n : r.not_compared) {
    std::printf("%-24s in one calibration only (or fixed): not compared\n", n.c_str());
  }
  std::printf("mdc: the smallest change of the parameter alone this test detects with power %g\n",
              r.power);
  std::printf("%s\n", r.message.c_str());
}

bool ComparisonOptionsFromLevel(double level, ComparisonOptions* options, std::string* error) {
  options->level = level;
  if (!options->IsValid(error)) {
    *error = "--level: " + *error;
    return false;
  }
  return true;
}

}  // namespace

int RunCompare(const CompareArgs& args) {
  if (args.positional.size() != 2) {
    return Fail("compare needs two calibration files: gravcal compare a.json b.json");
  }
  std::string error;
  ComparisonOptions options;
  if (!ComparisonOptionsFromLevel(args.level, &options, &error)) return Fail(error);
  const ComparisonSpace space = args.space;
  Calibration cal[2];
  LoadedCalibration loaded[2];
  ParameterVector params[2];
  for (int i = 0; i < 2; ++i) {
    if (!ReadCalibrationUncertainty(args.positional[i], &cal[i], &loaded[i], &error)) {
      return Fail(error);
    }
    if (!CalibrationParameters(cal[i], space, &params[i], &error)) {
      return Fail(args.positional[i] + ": cannot be tested: " + error);
    }
  }
  if (!SameRawUnits(cal[0], cal[1], &error)) {
    return Fail(args.positional[0] + ", " + args.positional[1] + ": " + error);
  }
  if (cal[0].gravity != cal[1].gravity) {
    std::fprintf(stderr,
                 "gravcal: warning: the calibrations used different gravity (%.6f, %.6f m/s^2): "
                 "the scale factors differ by their ratio\n",
                 cal[0].gravity, cal[1].gravity);
  }
  ComparisonResult result;
  if (!CompareParameters(params[0], params[1], options, &result)) return Fail(result.message);
  if (!result.tested) return Fail("cannot be tested: " + result.message);
  JsonSections sections = {{"space", std::string("\"") + ToString(space) + "\""}};
  if (!args.input.empty()) {
    ImuLog log;
    if (!ReadImuLog(args.input, args.config.input, &log, &error)) return Fail(error);
    const OutputDifference d =
        CorrectedOutputDifference(loaded[0].corrector, loaded[1].corrector, log);
    sections.emplace_back("output_difference", OutputDifferenceToJson(d));
    std::printf(
        "corrected output over %s (%zu samples): accelerometer difference rms %.6g, "
        "worst %.6g m/s^2",
        args.input.c_str(), d.samples, d.accel_rms, d.accel_max);
    if (d.gyro) std::printf("; gyroscope rms %.6g, worst %.6g rad/s", d.gyro_rms, d.gyro_max);
    std::printf("\n");
  }
  if (!args.output.empty() &&
      !WriteOutput(args.output, ComparisonToJson(result, sections), &error)) {
    return Fail(error);
  }
  if (args.output != "-") {
    std::printf("compare %s -> %s in %s parameters\n", args.positional[0].c_str(),
                args.positional[1].c_str(), ToString(space));
    PrintComparison(result, "b - a");
  }
  return result.consistent ? 0 : kChanged;
}

int RunVerify(const VerifyArgs& args) {
  if (args.calibration.empty()) return Fail("verify needs --calibration (the stored calibration)");
  if (args.input.empty()) return Fail("verify needs --input (the check session's log)");
  std::string error;
  ComparisonOptions options;
  if (!ComparisonOptionsFromLevel(args.level, &options, &error)) return Fail(error);
  Calibration stored;
  if (!ReadCalibrationUncertainty(args.calibration, &stored, nullptr, &error)) return Fail(error);
  // The thermal model (issue 35): verify takes the poses to T_ref with it.
  LoadedCalibration loaded;
  if (!ReadCalibrationJson(args.calibration, &loaded, &error)) return Fail(error);
  stored.thermal = loaded.corrector.thermal;
  ImuLog log;
  if (!ReadImuLog(args.input, args.config.input, &log, &error)) return Fail(error);
  CheckSessionResult result;
  if (!VerifyCheckLog(log, stored, args.config.calibration, options, &result, &error)) {
    return Fail(error);
  }
  for (const std::string& w : result.warnings) {
    std::fprintf(stderr, "gravcal: warning: %s\n", w.c_str());
  }
  if (!result.comparison.tested) return Fail(args.input + ": cannot be tested: nothing to test");
  if (!args.output.empty() &&
      !WriteOutput(args.output,
                   ComparisonToJson(result.comparison, {{"poses", CheckPosesToJson(result)}}),
                   &error)) {
    return Fail(error);
  }
  if (args.output != "-") {
    std::printf("verify %s against %s: %zu poses\n", args.input.c_str(), args.calibration.c_str(),
                result.poses.size());
    for (const CheckPose& p : result.poses) {
      std::printf("  pose %.2f-%.2f s: |a| - g = %+.6f m/s^2 (sigma %.3g, of which noise %.3g)\n",
                  p.t_begin, p.t_end, p.residual, p.sigma, p.noise_sigma);
    }
    PrintComparison(result.comparison, "change");
  }
  return result.comparison.consistent ? 0 : kChanged;
}

int RunPlanVerify(const PlanArgs& args) {
  std::string error;
  CheckDesignOptions options;
  if (!ComparisonOptionsFromLevel(args.level, &options.comparison, &error)) return Fail(error);
  options.noise_density = args.request.accel_noise_density;
  if (!(options.noise_density > 0.0)) {
    return Fail("plan --verify needs --accel-noise-density (m/s^2/sqrt(Hz))");
  }
  Calibration stored;
  if (!ReadCalibrationUncertainty(args.verify_calibration, &stored, nullptr, &error)) {
    return Fail(error);
  }
  CheckDesign design;
  if (!DesignCheckSession(stored, options, &design)) {
    return Fail(args.verify_calibration + ": " + design.message);
  }
  nlohmann::ordered_json j;
  j["met"] = design.met;
  j["poses"] = 4;
  j["hold_seconds"] = design.hold_seconds;
  j["target_sigmas"] = options.target_sigmas;
  j["power"] = options.comparison.power;
  j["level"] = options.comparison.level;
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (size_t i = 0; i < design.names.size(); ++i) {
    rows.push_back(
        {{"name", design.names[i]},
         {"minimal_detectable_change_sigmas", std::isfinite(design.mdc_sigmas[i])
                                                  ? nlohmann::ordered_json(design.mdc_sigmas[i])
                                                  : nlohmann::ordered_json(nullptr)}});
  }
  j["parameters"] = rows;
  j["short_of_target"] = design.short_of_target;
  j["message"] = design.message;
  if (!args.output.empty() && !WriteOutput(args.output, j.dump(2) + "\n", &error)) {
    return Fail(error);
  }
  if (args.output != "-") {
    std::printf("check session for %s: %s\n", args.verify_calibration.c_str(),
                design.message.c_str());
    for (size_t i = 0; i < design.names.size(); ++i) {
      std::printf("  %-20s smallest change detected: %.3g stored sigmas\n", design.names[i].c_str(),
                  design.mdc_sigmas[i]);
    }
  }
  return 0;
}

}  // namespace cli
}  // namespace gravcal
