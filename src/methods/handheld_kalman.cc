#include "gravcal/methods/handheld_kalman.h"

#include <glog/logging.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>

#include "core/calibration_gravity.h"
#include "core/warnings.h"
#include "methods/handheld_filter.h"
#include "methods/handheld_report.h"

namespace gravcal {

using internal::ResolveCalibrationGravity;

namespace internal {
namespace {

using Vec3 = Eigen::Vector3d;

// Still-period checks: rms deviation from the mean above these is not still.
constexpr double kStillAccelRms = 0.5;  // m/s^2
constexpr double kStillGyroRms = 0.1;   // rad/s
// A sample interval longer than this many nominal intervals is a gap.
constexpr double kGapFactor = 20.0;

// The log after the nominal scales, and where its still window ends.
struct HandheldInput {
  const ImuLog* log = nullptr;
  double accel_scale = 1.0;
  double gyro_scale = 1.0;
  double duration = 0.0;
  // Mean specific force of the still window, m/s^2.
  Vec3 f_mean = Vec3::Zero();
};

// Checks the log, finds the still window (with enough log after it for a
// few updates) and its mean specific force; warns when it does not look
// still. False with c->message.
bool ReadStillWindow(const ImuLog& log, const HandheldKalmanOptions& options, Calibration* c,
                     HandheldInput* input) {
  const size_t count = log.size();
  const double duration = count > 1 ? log.t.back() - log.t.front() : 0.0;
  size_t still_end = 0;
  while (still_end < count && log.t[still_end] - log.t.front() <= options.still_seconds) {
    ++still_end;
  }
  if (still_end < 10 || duration < options.still_seconds + 2.0 * options.update_interval) {
    std::ostringstream s;
    s << log.source << ": " << count << " samples over " << duration
      << " s is too short for the handheld_kalman method: it needs the still period ("
      << options.still_seconds << " s, at least 10 samples) and the turns after it";
    c->message = s.str();
    return false;
  }
  const double sa = options.accel_nominal_scale;
  const double sg = options.gyro_nominal_scale;
  Vec3 f_mean = Vec3::Zero();
  Vec3 w_mean = Vec3::Zero();
  for (size_t i = 0; i < still_end; ++i) {
    f_mean += sa * log.accel[i];
    w_mean += sg * log.gyro[i];
  }
  f_mean /= static_cast<double>(still_end);
  w_mean /= static_cast<double>(still_end);
  double f_dev = 0.0;
  double w_dev = 0.0;
  for (size_t i = 0; i < still_end; ++i) {
    f_dev += (sa * log.accel[i] - f_mean).squaredNorm();
    w_dev += (sg * log.gyro[i] - w_mean).squaredNorm();
  }
  f_dev = std::sqrt(f_dev / static_cast<double>(still_end));
  w_dev = std::sqrt(w_dev / static_cast<double>(still_end));
  if (!(f_mean.norm() > 0.3 * c->gravity && f_mean.norm() < 3.0 * c->gravity)) {
    std::ostringstream s;
    s << log.source << ": the mean specific force over the first " << options.still_seconds
      << " s is " << f_mean.norm() << " m/s^2 after nominal_scale, far from gravity " << c->gravity
      << ": check nominal_scale (m/s^2 per raw unit)";
    c->message = s.str();
    return false;
  }
  if (f_dev > kStillAccelRms || w_dev > kStillGyroRms) {
    std::ostringstream s;
    s << "the first " << options.still_seconds << " s do not look still (accelerometer rms "
      << FormatShort(f_dev) << " m/s^2, gyroscope rms " << FormatShort(w_dev)
      << " rad/s): the initial roll and pitch may be off; start with the unit held still";
    AddWarning(WarningCode::kNotStillAtStart, s.str(), &c->warnings, &c->warning_codes);
  }
  input->log = &log;
  input->accel_scale = sa;
  input->gyro_scale = sg;
  input->duration = duration;
  input->f_mean = f_mean;
  return true;
}

// Warns about the largest gap between samples when it is far above the
// nominal sample interval.
void WarnGap(const ImuLog& log, double duration, Calibration* c) {
  const size_t count = log.size();
  const double nominal_dt = duration / static_cast<double>(count - 1);
  double largest_gap = 0.0;
  double gap_time = 0.0;
  for (size_t i = 1; i < count; ++i) {
    const double dt = log.t[i] - log.t[i - 1];
    if (dt > largest_gap) {
      largest_gap = dt;
      gap_time = log.t[i - 1] - log.t.front();
    }
  }
  if (largest_gap > kGapFactor * nominal_dt) {
    std::ostringstream s;
    s << "the log has a gap of " << FormatShort(largest_gap)
      << " s at t = " << FormatShort(gap_time)
      << " s: the navigation runs blind across it and the estimates may be off";
    AddWarning(WarningCode::kLogGap, s.str(), &c->warnings, &c->warning_codes);
  }
}

// One pass of the filter over the log from the given sensor estimates; the
// first pass records the history of the sensor states in c->history.
// Returns false with c->message when the filter diverges.
bool RunPass(const HandheldInput& in, const HandheldKalmanOptions& options,
             const ErrorStateLayout& layout, const HandheldSensorEstimate& accel,
             const HandheldSensorEstimate& gyro, bool record_history, HandheldFilter* filter,
             double* nis_sum, int* epochs, Calibration* c) {
  const ImuLog& log = *in.log;
  const size_t count = log.size();
  const double sa = in.accel_scale;
  const double sg = in.gyro_scale;
  const int n = layout.size();
  const int first_sensor = layout.offset(StateBlock::kAccelBias);
  EstimateHistory& history = c->history;
  filter->Initialize(in.f_mean, accel, gyro);
  *nis_sum = 0.0;
  *epochs = 0;
  auto record = [&](double t) {
    if (!record_history) return;
    history.values.push_back(t - log.t.front());
    const Eigen::MatrixXd& p = filter->covariance();
    for (int j = first_sensor; j < n; ++j) {
      history.values.push_back(filter->SensorValue(j));
      history.values.push_back(std::sqrt(std::max(p(j, j), 0.0)));
    }
  };
  record(log.t.front());
  for (size_t i = 1; i < count; ++i) {
    filter->Step(log.t[i] - log.t[i - 1], sa * log.accel[i - 1], sg * log.gyro[i - 1],
                 sa * log.accel[i], sg * log.gyro[i]);
    if (filter->elapsed() >= options.update_interval * (1.0 - 1e-9) || i + 1 == count) {
      filter->Propagate();
      *nis_sum += filter->Update();
      ++*epochs;
      if (!filter->Healthy()) {
        std::ostringstream s;
        s << log.source << ": the filter diverged at t = " << log.t[i] - log.t.front()
          << " s: check nominal_scale, gyro_nominal_scale and the noise settings";
        c->message = s.str();
        c->not_converged = true;
        return false;
      }
      record(log.t[i]);
    }
  }
  return true;
}

// Warns when the innovations are far above their expected size.
void WarnInnovations(double chi2_per_dof, const HandheldKalmanOptions& options, Calibration* c) {
  if (chi2_per_dof > 3.0) {
    std::ostringstream s;
    // Two causes give the same symptom: motion beyond the pseudo-measurement
    // noise, or sensor errors outside the model (cross-axis terms above all:
    // on a 0.005 rad misaligned simulated IMU the diagonal model is 10-40
    // sigma off and this statistic is 7-24). Either way the standard
    // deviations assume a model the data reject, so say both.
    s << "the innovations are " << FormatShort(chi2_per_dof)
      << " times their expected size (chi2 per degree of freedom), so the standard deviations "
         "are too small: either the unit moved more than the pseudo-measurements allow (keep it "
         "in place, or raise hk_velocity_noise and hk_position_noise) or the sensor has errors "
         "outside the model ("
      << (options.gyro_terms.matrix_entries.size() > 3 ? "" : "try hk_cross_axis: true; ")
      << (options.estimate_lever_arm ? "" : "try hk_lever_arm: true; ")
      << "gravcal discover on a multi-position session names other effects)";
    AddWarning(WarningCode::kResidualsAboveNoise, s.str(), &c->warnings, &c->warning_codes);
  }
}

// The sensor models and their uncertainty from the final filter. False with
// c->message when the accelerometer matrix is singular.
bool FillSensorModels(const HandheldFilter& filter, const ErrorStateLayout& layout,
                      const HandheldInput& in, Calibration* calibration) {
  Calibration& c = *calibration;
  const ImuLog& log = *in.log;
  const double sa = in.accel_scale;
  const double sg = in.gyro_scale;
  const Eigen::MatrixXd& p = filter.covariance();
  const SensorResult accel =
      ToCalibrationModel(filter.accel(), sa, layout.offset(StateBlock::kAccelBias),
                         layout.offset(StateBlock::kAccelMatrix), layout.accel(), p);
  c.accel.bias_std = accel.bias_std;
  c.accel.matrix_std = accel.matrix_std;
  c.accel.covariance = accel.covariance;
  c.accel.covariance_names = accel.names;
  const Vec3& accel_bias = accel.bias;
  const Eigen::Matrix3d& accel_matrix = accel.matrix;
  // Diagonal E: the `scale` model; upper-triangular E (the accelerometer
  // axes define the body frame): `scale_misalignment`; otherwise `affine`.
  const bool accel_upper =
      accel_matrix.isUpperTriangular(0.0) && accel_matrix.diagonal().minCoeff() > 0.0;
  if (accel_upper) {
    c.accel.model.parameterization = accel_matrix.isDiagonal(0.0)
                                         ? AccelParameterization::kScale
                                         : AccelParameterization::kScaleMisalignment;
    c.accel.model.bias = accel_bias;
    c.accel.model.upper = accel_matrix;
    c.accel.model.rotation.setIdentity();
  } else if (!AccelModel::FromMatrix(accel_bias, accel_matrix, AccelParameterization::kAffine,
                                     &c.accel.model)) {
    c.message = log.source + ": the estimated accelerometer matrix is singular";
    return false;
  }
  const SensorResult gyro =
      ToCalibrationModel(filter.gyro(), sg, layout.offset(StateBlock::kGyroBias),
                         layout.offset(StateBlock::kGyroMatrix), layout.gyro(), p);
  c.gyro.estimated = true;
  c.gyro.model.bias = gyro.bias;
  c.gyro.model.matrix = gyro.matrix;
  c.gyro.bias_std = gyro.bias_std;
  c.gyro.matrix_std = gyro.matrix_std;
  c.gyro.covariance = gyro.covariance;
  c.gyro.covariance_names = gyro.names;
  return true;
}

// The residuals over the still period, the filter's summary in
// c->refinement and the message.
void FillSummary(const HandheldFilter& filter, const ErrorStateLayout& layout,
                 const HandheldInput& in, double nis_sum, int epochs,
                 const std::vector<std::string>& unexcited,
                 std::chrono::steady_clock::time_point clock_start, Calibration* calibration) {
  Calibration& c = *calibration;
  const Eigen::Vector3d& f_mean = in.f_mean;
  const int n = layout.size();
  const int sensor_count =
      layout.offset(StateBlock::kLeverArm) - layout.offset(StateBlock::kAccelBias);
  // |a| - g over the initial still period, before (nominal scale) and after.
  const double before = f_mean.norm() - c.gravity;
  const double after = filter.accel().Correct(f_mean).norm() - c.gravity;
  c.residual_nominal = {std::fabs(before), std::fabs(before)};
  c.residual_refined = {std::fabs(after), std::fabs(after)};
  c.residual_coarse = c.residual_nominal;

  RefinementResult& summary = c.refinement;
  summary.iterations = epochs;
  summary.converged = unexcited.empty();
  summary.termination = "end of log";
  summary.chi2 = nis_sum;
  summary.dof = 6 * epochs;
  summary.num_parameters = sensor_count;
  summary.solve_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  std::ostringstream m;
  m << "handheld Kalman filter: " << n << " states, " << epochs << " updates over "
    << FormatShort(in.duration) << " s; ";
  if (unexcited.empty()) {
    m << "all " << sensor_count << " sensor errors determined";
  } else {
    m << unexcited.size() << " of " << sensor_count
      << " sensor errors not determined by the motion (see warnings)";
  }
  summary.message = m.str();
  c.solver_name = "error-state Kalman filter";
  c.message = m.str();
}

}  // namespace
}  // namespace internal

bool HandheldKalmanOptions::IsValid(std::string* error) const {
  auto positive = [&](const char* key, double v) {
    if (std::isfinite(v) && v > 0.0) return true;
    *error = std::string("key '") + key + "': must be positive";
    return false;
  };
  auto non_negative = [&](const char* key, double v) {
    if (std::isfinite(v) && v >= 0.0) return true;
    *error = std::string("key '") + key + "': must be zero or positive";
    return false;
  };
  if (!positive("nominal_scale", accel_nominal_scale) ||
      !positive("gyro_nominal_scale", gyro_nominal_scale) ||
      !positive("hk_still_seconds", still_seconds) ||
      !positive("hk_update_interval", update_interval) ||
      !positive("hk_velocity_noise", velocity_noise) ||
      !positive("hk_position_noise", position_noise) ||
      !positive("hk_accel_noise_density", accel_noise_density) ||
      !positive("hk_gyro_noise_density", gyro_noise_density) ||
      !non_negative("hk_accel_bias_walk", accel_bias_walk) ||
      !non_negative("hk_gyro_bias_walk", gyro_bias_walk) ||
      !positive("hk_accel_bias_std", accel_bias_std) ||
      !positive("hk_accel_scale_std", accel_scale_std) ||
      !positive("hk_gyro_bias_std", gyro_bias_std) ||
      !positive("hk_gyro_scale_std", gyro_scale_std) ||
      !positive("hk_cross_axis_std", cross_axis_std) ||
      !positive("hk_initial_attitude_std", initial_attitude_std) ||
      !positive("hk_lever_arm_std", lever_arm_std) ||
      !positive("hk_convergence_fraction", convergence_fraction)) {
    return false;
  }
  if (passes < 1 || passes > 5) {
    *error = "key 'hk_passes': must be from 1 to 5";
    return false;
  }
  if (convergence_fraction >= 1.0) {
    *error = "key 'hk_convergence_fraction': must be below 1";
    return false;
  }
  if (!gravity.IsValid(error) || !accel_terms.IsValid(error) || !gyro_terms.IsValid(error)) {
    return false;
  }
  if (earth_rate && !std::isfinite(gravity.latitude)) {
    *error = "key 'hk_earth_rate': the Earth rate needs the key 'latitude'";
    return false;
  }
  return true;
}

bool CalibrateHandheld(const ImuLog& log, const HandheldKalmanOptions& options,
                       Calibration* calibration) {
  CHECK(calibration != nullptr);
  const auto clock_start = std::chrono::steady_clock::now();
  *calibration = Calibration();
  Calibration& c = *calibration;
  std::string error;
  if (!options.IsValid(&error)) {
    c.message = error;
    return false;
  }
  if (!log.Validate(&error)) {
    c.message = error;
    return false;
  }
  if (!log.has_gyro()) {
    c.message = log.source +
                ": the handheld_kalman method needs a gyroscope (columns gx, gy, gz, or "
                "gyro_path)";
    return false;
  }
  if (!ResolveCalibrationGravity(options.gravity, calibration)) return false;
  internal::HandheldInput in;
  if (!internal::ReadStillWindow(log, options, &c, &in)) return false;

  const ErrorStateLayout layout(options.accel_terms, options.gyro_terms,
                                options.estimate_lever_arm);
  // History: t, then value and std of each sensor state.
  c.history.columns.push_back("t");
  for (int j = layout.offset(StateBlock::kAccelBias); j < layout.size(); ++j) {
    c.history.columns.push_back(layout.names()[j]);
    c.history.columns.push_back(layout.names()[j] + "_std");
  }

  // Later passes start from the previous pass's sensor estimates (the prior
  // covariance is the same, centred there): the levelling and the error
  // model are then linearised close to the truth. The levelling's tilt
  // error b_h / g otherwise leaves a second-order error |b_h|^2 / (2 g) in
  // the vertical channel during the still period that the first pass
  // attributes to the vertical accelerometer bias and scale.
  std::unique_ptr<internal::HandheldFilter> filter;
  internal::HandheldSensorEstimate accel_start;
  internal::HandheldSensorEstimate gyro_start;
  double nis_sum = 0.0;
  int epochs = 0;
  for (int pass = 0; pass < options.passes; ++pass) {
    auto next = std::make_unique<internal::HandheldFilter>(options, c.gravity, layout);
    if (!internal::RunPass(in, options, layout, accel_start, gyro_start, pass == 0, next.get(),
                           &nis_sum, &epochs, &c)) {
      return false;
    }
    filter = std::move(next);
    accel_start = filter->accel();
    gyro_start = filter->gyro();
  }
  internal::WarnGap(log, in.duration, &c);
  internal::WarnInnovations(nis_sum / (6.0 * epochs), options, &c);

  const std::vector<std::string> unexcited =
      internal::ReportConvergence(*filter, layout, options, &c);
  if (!internal::FillSensorModels(*filter, layout, in, &c)) {
    // A singular estimated matrix: the filter ran away.
    c.message +=
        ": the filter diverged: check gyro_nominal_scale (a gyroscope in deg/s read as "
        "rad/s?), nominal_scale and the noise settings";
    c.not_converged = true;
    return false;
  }

  internal::FillSummary(*filter, layout, in, nis_sum, epochs, unexcited, clock_start, &c);
  // A filter that ran away (a gyroscope in deg/s read as rad/s, a wrong
  // nominal scale) ends with a calibration that misses gravity in the still
  // window by far more than the nominal scales did: refused, as diverged.
  const double before = c.residual_nominal.rms;
  const double after = c.residual_refined.rms;
  if (!(after <= 0.1 * c.gravity || after <= 3.0 * before)) {
    std::ostringstream s;
    s.precision(3);
    s << log.source << ": the filter diverged: calibrated, the still window's |a| - g is " << after
      << " m/s^2 (" << before
      << " m/s^2 with the nominal scales): check gyro_nominal_scale (a gyroscope in deg/s "
         "read as rad/s?), nominal_scale and the noise settings";
    c.message = s.str();
    c.not_converged = true;
    return false;
  }
  c.success = true;
  return true;
}

}  // namespace gravcal
