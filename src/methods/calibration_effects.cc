// The effect fit applied to a calibration (FitCalibrationEffects): the
// static intervals of the log become observations, the effects are fitted
// from the calibrated model, and the result is copied into the calibration
// with its residuals.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/noise_flicker.h"
#include "core/warnings.h"
#include "gravcal/methods/effect_fit.h"
#include "util/statistics.h"

namespace gravcal {

using internal::ChiSquareUpperTail;

namespace {

// The references (mean time, mean temperature) and the starting gyroscope
// bias (mean reading) of the positions; true when all have a temperature.
// The reference temperature is NaN without one.
bool StartParameters(const std::vector<StaticObservation>& observations, EffectParameters* start,
                     GyroModel* gyro) {
  const int n = static_cast<int>(observations.size());
  bool has_temperature = n > 0;
  double temperature_sum = 0.0, time_sum = 0.0;
  for (const StaticObservation& o : observations) {
    has_temperature = has_temperature && std::isfinite(o.temperature());
    temperature_sum += o.temperature();
    time_sum += o.time();
    gyro->bias += o.gyro_mean / n;
  }
  start->reference_time = n > 0 ? time_sum / n : 0.0;
  start->reference_temperature = has_temperature ? temperature_sum / n : NAN;
  return has_temperature;
}

// The accelerometer and gyroscope models and uncertainties of the fit.
void CopyEffectFit(const EffectFitResult& fit, Calibration* calibration) {
  Calibration& c = *calibration;
  c.accel.model.bias = fit.accel.bias;
  c.accel.model.upper = fit.accel.upper;
  c.accel.model.parameterization = fit.accel.parameterization;
  c.accel.bias_std = fit.accel_bias_std;
  // The accelerometer's parameters only: the gyroscope's nuisance
  // parameters of the rotations between poses (rotation_gyro_*) are left
  // out (the marginal covariance drops their rows and columns).
  std::vector<int> kept;
  c.accel.covariance_names.clear();
  for (size_t i = 0; i < fit.accel_fit.parameter_names.size(); ++i) {
    const std::string& name = fit.accel_fit.parameter_names[i];
    if (name.rfind("rotation_gyro_", 0) == 0) continue;
    kept.push_back(static_cast<int>(i));
    c.accel.covariance_names.push_back(name);
  }
  const int n = static_cast<int>(kept.size());
  c.accel.covariance.resize(fit.accel_fit.covariance.size() > 0 ? n : 0,
                            fit.accel_fit.covariance.size() > 0 ? n : 0);
  for (int r = 0; r < c.accel.covariance.rows(); ++r) {
    for (int col = 0; col < n; ++col) {
      c.accel.covariance(r, col) = fit.accel_fit.covariance(kept[r], kept[col]);
    }
  }
  const bool rotated = !c.accel.model.rotation.isIdentity(0.0);
  static const char* kUpperNames[3][3] = {
      {"u_xx", "u_xy", "u_xz"}, {"", "u_yy", "u_yz"}, {"", "", "u_zz"}};
  for (int r = 0; r < 3; ++r) {
    for (int col = r; col < 3; ++col) {
      if (!rotated) c.accel.matrix_std(r, col) = fit.accel_fit.Std(kUpperNames[r][col]);
    }
  }
  if (rotated) {
    internal::AddWarning(WarningCode::kParameterSource,
                         "effects: accel.std.matrix is from the fit without effects (the housing "
                         "rotation's uncertainty is not propagated through the effect fit)",
                         &c.warnings, &c.warning_codes);
  }
  if (fit.gyro_fit.fitted) {
    c.gyro.estimated = true;
    c.gyro.model.bias = fit.gyro.bias;
    c.gyro.model.matrix.setIdentity();
    c.gyro.bias_std = fit.gyro_bias_std;
    c.gyro.matrix_std.setConstant(NAN);
    c.gyro.covariance = fit.gyro_fit.covariance;
    c.gyro.covariance_names = fit.gyro_fit.parameter_names;
    internal::AddWarning(WarningCode::kMethodScope,
                         "gyro: static positions determine the gyroscope bias and the effects "
                         "only; gyro.matrix is the identity (not determined)",
                         &c.warnings, &c.warning_codes);
  }
}

// The residuals after the fit with effects, and the chi2 warning in place
// of the base fit's.
void SetEffectResiduals(const EffectFitResult& fit, Calibration* calibration) {
  Calibration& c = *calibration;
  const int n = static_cast<int>(fit.accel_residuals.size());
  double s = 0.0, m = 0.0;
  for (double r : fit.accel_residuals) {
    s += r * r;
    m = std::max(m, std::fabs(r));
  }
  c.residual_refined = {n > 0 ? std::sqrt(s / n) : 0.0, m};
  if (static_cast<int>(c.positions.size()) == n) {
    for (int k = 0; k < n; ++k) c.positions[k].residual_after = fit.accel_residuals[k];
  }
  // The base fit's verdict on its residuals no longer applies.
  std::vector<std::string> kept;
  std::vector<WarningCode> kept_codes;
  for (size_t i = 0; i < c.warnings.size(); ++i) {
    const WarningCode code =
        i < c.warning_codes.size() ? c.warning_codes[i] : WarningCode::kUnclassified;
    if (c.warnings[i].find("times the noise level (chi2") == std::string::npos) {
      internal::AddWarning(code, c.warnings[i], &kept, &kept_codes);
    }
  }
  c.warnings.swap(kept);
  c.warning_codes.swap(kept_codes);
  if (fit.accel_fit.dof() > 0 &&
      ChiSquareUpperTail(fit.accel_fit.chi2, fit.accel_fit.dof()) < 1e-3) {
    std::ostringstream w;
    w.precision(3);
    w << "with effects the residuals are still "
      << std::sqrt(fit.accel_fit.chi2 / fit.accel_fit.dof())
      << " times the noise level (chi2 = " << fit.accel_fit.chi2 << " on " << fit.accel_fit.dof()
      << " dof): gravcal discover can look for what the model still misses";
    internal::AddWarning(WarningCode::kResidualsAboveNoise, w.str(), &c.warnings, &c.warning_codes);
  }
}

// The variance of the gyroscope's bias about its session value from the
// noise model, (rad/s)^2: B^2 + K^2 T / 6 (the random walk's mean square
// about its mean over T s; B^2 the flicker's alone, as in
// methods/gyro_bias_wander.cc), the largest over the axes; 0 without a
// model.
double GyroBiasWanderVariance(const ImuNoiseModel* model,
                              const std::vector<StaticObservation>& observations) {
  if (model == nullptr || observations.empty()) return 0.0;
  const double seconds = observations.back().accel.t_end - observations.front().accel.t_begin;
  double largest = 0.0;
  for (const AxisNoiseModel& axis : model->gyro) {
    double v = 0.0;
    v += internal::FlickerAllanVariance(axis) / kFlickerAllanFactor;
    if (axis.random_walk.visible()) {
      v += axis.random_walk.value * axis.random_walk.value * std::max(0.0, seconds) / 6.0;
    }
    if (std::isfinite(v)) largest = std::max(largest, v);
  }
  return largest;
}

}  // namespace

bool FitCalibrationEffects(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                           const CalibrationOptions& options, const std::vector<Effect>& effects,
                           Calibration* calibration) {
  Calibration& c = *calibration;
  auto fail = [&](const std::string& what) {
    c.success = false;
    c.message = (log.source.empty() ? "" : log.source + ": ") + what;
    return false;
  };
  // The trends along gravity of poses held 10 s or more, as discover reads
  // them.
  std::vector<StaticObservation> observations =
      ObservationsFromIntervals(log, intervals, GravityTrendOptions());
  // Issue 21: with a gyroscope, the turns between the poses link their
  // directions (use_between_pose_rotations).
  const int turns = AddBetweenPoseTurns(log, intervals, &observations);
  EffectParameters start;
  GyroModel gyro;
  const bool has_temperature = StartParameters(observations, &start, &gyro);
  for (Effect e : effects) {
    const EffectInfo& info = Info(e);
    if (info.regressor == EffectRegressor::kTemperature && !has_temperature) {
      return fail(std::string("effect ") + info.name + " needs a temperature column");
    }
    if (info.sensor == EffectSensor::kGyroscope && !log.has_gyro()) {
      return fail(std::string("effect ") + info.name + " needs a gyroscope");
    }
  }
  if (!has_temperature) start.reference_temperature = 0.0;
  // The model and solver sections hold for the fit with effects as for the
  // one without: the refinement's shared settings (fit_settings.h: the
  // parameterization, the robust loss, the covariance, the pose variance with
  // its prior) pass whole, and the iteration limit. The tolerances stay the
  // effect fit's own. (The Newton solver has no effect fit: the config
  // refuses solver newton with effects.)
  EffectFitOptions fit_options;
  static_cast<AccelFitSettings&>(fit_options) = options.refinement;
  fit_options.effects = effects;
  fit_options.solver.max_iterations = options.refinement.solver.max_iterations;
  fit_options.use_between_pose_rotations = turns > 0;
  fit_options.rotation_gyro_bias_variance =
      GyroBiasWanderVariance(options.pose_noise.model, observations);
  fit_options.fit_gyro = std::any_of(effects.begin(), effects.end(), [](Effect e) {
    return Info(e).sensor == EffectSensor::kGyroscope;
  });
  EffectFitResult fit;
  if (!FitEffects(observations, c.accel.model, gyro, start, c.gravity, fit_options, &fit)) {
    return fail("fit with effects: " + fit.message);
  }
  if (fit.accel_fit.rotation_residuals > 0 &&
      ChiSquareUpperTail(fit.accel_fit.rotation_chi2, fit.accel_fit.rotation_residuals - 12) <
          1e-3) {
    // The turns carry something they do not model: the effects from the
    // poses alone, saying why.
    const std::vector<std::string> why = fit.warnings;
    fit_options.use_between_pose_rotations = false;
    if (!FitEffects(observations, c.accel.model, gyro, start, c.gravity, fit_options, &fit)) {
      return fail("fit with effects: " + fit.message);
    }
    for (const std::string& w : why) fit.warnings.push_back(w + "; not used");
  }
  std::string undetermined;
  for (const SensorFitSummary* s : {&fit.accel_fit, &fit.gyro_fit}) {
    for (const std::string& name : s->undetermined) {
      undetermined += (undetermined.empty() ? "" : ", ") + name;
    }
  }
  if (!undetermined.empty() && !options.allow_undetermined) {
    return fail("the positions do not determine " + undetermined +
                " of the model with effects: record more poses (at several temperatures for "
                "temperature effects), or set allow_undetermined: true");
  }
  if (!fit.accel_fit.converged || (fit.gyro_fit.fitted && !fit.gyro_fit.converged)) {
    c.not_converged = true;
    return fail("the fit with effects did not converge");
  }

  CopyEffectFit(fit, &c);
  SetEffectResiduals(fit, &c);
  c.effects.estimates = fit.estimates;
  c.effects.reference_temperature = has_temperature ? start.reference_temperature : NAN;
  c.effects.reference_time = start.reference_time;
  if (!undetermined.empty()) {
    internal::AddWarning(WarningCode::kUndetermined,
                         "the positions do not determine " + undetermined +
                             " of the model with effects; reported without a number",
                         &c.warnings, &c.warning_codes);
  }
  std::ostringstream msg;
  msg << c.message << "; with effects";
  for (Effect e : effects) msg << " " << ToString(e);
  msg.precision(3);
  msg << " (accelerometer chi2 " << fit.accel_fit.chi2 << " on " << fit.accel_fit.dof()
      << " dof from " << fit.accel_fit.information << ")";
  for (const std::string& w : fit.warnings) {
    internal::AddWarning(WarningCode::kMethodScope, "effects: " + w, &c.warnings, &c.warning_codes);
  }
  c.message = msg.str();
  return true;
}

}  // namespace gravcal
