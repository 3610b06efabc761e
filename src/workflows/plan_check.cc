// gravcal check: what a recorded session determines (workflows/plan.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "gravcal/estimation/coarse_fit.h"
#include "gravcal/estimation/refinement.h"
#include "gravcal/workflows/plan.h"
#include "methods/static_positions.h"
#include "util/numbers.h"
#include "util/statistics.h"
#include "workflows/plan_start.h"

namespace gravcal {

namespace {

using internal::kFaceSnapDeg;
using internal::kInf;

// The parameters DeterminedStd held (infinite standard deviation).
std::vector<std::string> Undetermined(const std::vector<std::string>& names,
                                      const Eigen::VectorXd& std) {
  std::vector<std::string> out;
  for (size_t i = 0; i < names.size(); ++i) {
    if (!std::isfinite(std(i))) out.push_back(names[i]);
  }
  return out;
}

// How much a set of standard deviations falls short: the number of
// undetermined parameters first, then the worst ratio to target.
std::pair<int, double> Shortfall(const Eigen::VectorXd& std, const Eigen::VectorXd& targets) {
  int undetermined = 0;
  double worst = 0.0;
  for (Eigen::Index i = 0; i < std.size(); ++i) {
    if (!std::isfinite(std(i))) {
      ++undetermined;
      continue;
    }
    worst = std::max(worst, std(i) / targets(i));
  }
  return {undetermined, worst};
}

using internal::Median;

}  // namespace

bool CheckRecording(const ImuLog& log, const Config& config, const PlanRequest& request,
                    CoverageReport* report, std::string* error) {
  Session session;
  session.log = log;
  return CheckRecording(session, config, request, report, error);
}

bool CheckRecording(const Session& session, const Config& config, const PlanRequest& request,
                    CoverageReport* report, std::string* error) {
  const ImuLog& log = session.log;
  internal::PlanStart start;
  if (!internal::StartPlan(config, request, &start, error)) return false;
  const DesignModel& model = start.model;
  const std::vector<std::string>& names = start.names;

  // The poses, by the calibration's own front end.
  CalibrationOptions options = config.calibration;
  if (request.noise_model != nullptr) options.pose_noise.model = request.noise_model;
  Calibration calibration;
  std::vector<StaticInterval> intervals;
  std::vector<Position> positions;
  if (!internal::DetectStaticPositions(session, options, &calibration, &intervals, &positions)) {
    *error = calibration.message;
    return false;
  }
  if (positions.empty()) {
    *error = log.source + ": no static pose found";
    return false;
  }
  // The data's own scale (m/s^2 per raw unit) and each pose's direction,
  // from the coarse fit when the poses allow one: it separates an offset
  // (unsigned counts around 32768, volts around 1.65) from gravity, as the
  // --noise path does (ScaleFromPoses). Else g over the median |raw mean|
  // and the raw directions, which assume no offset.
  std::vector<double> norms, holds;
  for (const Position& p : positions) {
    norms.push_back(p.raw_mean.norm());
    holds.push_back(p.t_end - p.t_begin);
  }
  CoarseFitResult coarse;
  double scale = CoarseFit(positions, model.gravity, AccelParameterization::kScale,
                           CoarseFitOptions(), &coarse)
                     ? std::cbrt(std::abs(coarse.model.matrix().determinant()))
                     : 0.0;
  const bool fitted = std::isfinite(scale) && scale > 0.0;
  if (!fitted) scale = model.gravity / Median(norms);
  // The nominal sensor sees each pose along its measured direction; a pose
  // within kFaceSnapDeg of a face counts as that face: the placement error
  // of a few degrees (and the bias, which tilts opposite faces alike) carries
  // only weak, unreliable information on the cross terms, which the
  // refinement could not separate from its undetermined directions either.
  std::vector<Position> scaled = positions;
  for (Position& p : scaled) {
    Eigen::Vector3d up = (fitted ? coarse.model.Apply(p.raw_mean) : p.raw_mean).normalized();
    Eigen::Index axis = 0;
    up.cwiseAbs().maxCoeff(&axis);
    if (std::fabs(up(axis)) > std::cos(kFaceSnapDeg * M_PI / 180.0)) {
      up = Eigen::Vector3d::Unit(axis) * (up(axis) > 0.0 ? 1.0 : -1.0);
    }
    p.raw_mean = model.gravity * up;
    p.raw_mean_cov *= scale * scale;
  }
  AccelModel nominal;
  nominal.parameterization = model.parameterization;
  std::vector<double> sigmas = MagnitudeSigmas(scaled, nominal);
  for (double& s : sigmas) {
    s = std::sqrt(s * s + request.pose_disturbance * request.pose_disturbance);
  }
  const Eigen::MatrixXd j = MagnitudeJacobian(scaled, nominal, sigmas);
  Eigen::MatrixXd fisher = j.transpose() * j;

  CoverageReport out;
  out.positions = static_cast<int>(positions.size());
  const Eigen::VectorXd& limit = start.limits;
  out.accel = internal::Prediction(names, DeterminedStd(fisher, limit), start.targets,
                                   start.targeted, scale);
  const SensorPrediction& accel = out.accel;
  for (size_t i = 0; i < names.size(); ++i) {
    if (accel.targeted[i] && !(accel.predicted_std_scale_free(i) <= accel.targets_scale_free(i))) {
      out.short_of_target.push_back(names[i]);
    }
  }
  out.undetermined = Undetermined(names, accel.predicted_std_scale_free);
  // Proposals are ranked against the stated targets, else the yardstick.
  Eigen::VectorXd yardstick = accel.targets_scale_free;
  for (size_t i = 0; i < names.size(); ++i) {
    if (!accel.targeted[i]) yardstick(i) = ReferenceStd(names[i]);
  }

  // Extra poses: the request's noise when given, else white noise of the
  // density the recorded poses show (variance of the mean times duration).
  DesignNoise noise;
  std::string source;
  if (request.noise_model != nullptr || request.accel_noise_density > 0.0) {
    if (!PlanDesignNoise(request, &noise, &source, error)) return false;
  } else {
    std::vector<double> density[3];
    for (size_t k = 0; k < scaled.size(); ++k) {
      for (int a = 0; a < 3; ++a) density[a].push_back(scaled[k].raw_mean_cov(a, a) * holds[k]);
    }
    for (int a = 0; a < 3; ++a) noise.accel[a].white_noise.value = std::sqrt(Median(density[a]));
    noise.pose_disturbance = request.pose_disturbance;
  }
  const double hold = std::max(Median(holds) + model.trimmed_seconds, request.min_hold_seconds);
  std::vector<Eigen::Vector3d> candidates;
  CandidateDirections(request.pose_set, request.free_candidates, &candidates);
  std::vector<DesignPose> candidate_poses;
  for (const Eigen::Vector3d& c : candidates) candidate_poses.push_back({c, hold});
  const Eigen::MatrixXd rows = DesignJacobian(candidate_poses, model, noise);
  // One or two poses, or as many as there are undetermined parameters
  // (each pose adds one row to the information: one direction at most).
  const int count = std::max(request.extra_poses, static_cast<int>(out.undetermined.size()));
  Eigen::VectorXd current = accel.predicted_std_scale_free;
  for (int step = 0; step < count; ++step) {
    int best = -1;
    std::pair<int, double> best_shortfall = {static_cast<int>(names.size()) + 1, kInf};
    Eigen::VectorXd best_std;
    for (Eigen::Index c = 0; c < rows.rows(); ++c) {
      const Eigen::MatrixXd with = fisher + rows.row(c).transpose() * rows.row(c);
      const Eigen::VectorXd std = DeterminedStd(with, limit);
      const std::pair<int, double> s = Shortfall(std, yardstick);
      if (s < best_shortfall) {
        best_shortfall = s;
        best = static_cast<int>(c);
        best_std = std;
      }
    }
    if (best < 0) break;
    // Stop once every parameter is determined and another pose helps by
    // less than 1 %.
    const std::pair<int, double> now = Shortfall(current, yardstick);
    if (step >= 1 && now.first == 0 && best_shortfall.second > 0.99 * now.second) break;
    fisher += rows.row(best).transpose() * rows.row(best);
    current = best_std;
    out.proposed.push_back({candidates[best], hold, PoseInstruction(candidates[best])});
  }
  out.predicted_std_with_proposed = current;
  out.undetermined_with_proposed = Undetermined(names, current);
  // Issue 35: the temperature span the static poses cover, against the
  // orders the thermal method would fit.
  if (log.has_temperature() && config.method == Method::kThermal) {
    double lo = INFINITY, hi = -INFINITY;
    for (const Position& p : positions) {
      lo = std::min(lo, p.temperature);
      hi = std::max(hi, p.temperature);
    }
    out.temperature_span = hi - lo;
    out.temperature = ThermalSpanMessages(out.temperature_span, config.thermal);
    for (const std::string& m : InspectTemperatureColumn(log).warnings)
      out.temperature.push_back(m);
    if (positions.size() == 1 || out.positions == 1) {
      out.temperature.push_back(
          "one static pose: a ramp determines only the bias change along gravity; turn the unit "
          "through its poses while it warms (configs/thermal_warmup.yaml) for the other axes, "
          "scale and misalignment");
    }
  }
  std::ostringstream s;
  s << positions.size() << " poses; " << out.undetermined.size() << " parameter(s) undetermined, "
    << out.short_of_target.size() << " short of target; " << out.proposed.size()
    << " extra pose(s) proposed";
  out.message = s.str();
  *report = out;
  return true;
}

std::string CoverageReportText(const CoverageReport& r) {
  std::ostringstream s;
  s.precision(3);
  s << "poses recorded: " << r.positions << "\n";
  s << "parameter  predicted sigma      target          verdict\n";
  const SensorPrediction& accel = r.accel;
  for (size_t i = 0; i < accel.parameter_names.size(); ++i) {
    const std::string& name = accel.parameter_names[i];
    const ReadableUnit unit = ReadableUnitOf(name);
    const bool undetermined =
        std::find(r.undetermined.begin(), r.undetermined.end(), name) != r.undetermined.end();
    const bool short_of = std::find(r.short_of_target.begin(), r.short_of_target.end(), name) !=
                          r.short_of_target.end();
    std::ostringstream sigma, target;
    sigma.precision(3);
    target.precision(3);
    if (std::isfinite(accel.predicted_std_scale_free(i))) {
      sigma << accel.predicted_std_scale_free(i) * unit.factor << " " << unit.unit;
    } else {
      sigma << "-";
    }
    if (accel.targeted[i]) {
      target << accel.targets_scale_free(i) * unit.factor << " " << unit.unit;
    } else {
      target << "-";
    }
    char line[160];
    std::snprintf(line, sizeof(line), "%-10s %-20s %-15s %s\n", name.c_str(), sigma.str().c_str(),
                  target.str().c_str(),
                  undetermined ? "UNDETERMINED" : (short_of ? "short of target" : "ok"));
    s << line;
  }
  if (std::isfinite(r.temperature_span)) {
    s << "temperature span of the poses: " << r.temperature_span << " degC\n";
  }
  for (const std::string& t : r.temperature) s << "temperature: " << t << "\n";
  if (!r.undetermined.empty()) {
    s << "undetermined: ";
    for (size_t i = 0; i < r.undetermined.size(); ++i) s << (i ? ", " : "") << r.undetermined[i];
    s << "\n";
  }
  s << "extra poses that reduce the worst sigma most:\n";
  for (size_t k = 0; k < r.proposed.size(); ++k) {
    const PlannedPose& p = r.proposed[k];
    s << "  " << k + 1 << ". up = (" << p.up(0) << ", " << p.up(1) << ", " << p.up(2)
      << "): " << p.instruction << ", hold " << p.hold_seconds << " s\n";
  }
  if (!r.proposed.empty()) {
    s << "with them: ";
    if (r.undetermined_with_proposed.empty()) {
      s << "every parameter determined";
    } else {
      s << "still undetermined: ";
      for (size_t i = 0; i < r.undetermined_with_proposed.size(); ++i) {
        s << (i ? ", " : "") << r.undetermined_with_proposed[i];
      }
    }
    s << "\n";
  }
  return s.str();
}

}  // namespace gravcal
