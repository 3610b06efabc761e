// gravcal/methods/thermal_calibration.h: the thermal calibration (issue 35):
// bias, scale and misalignment of the accelerometer and the gyroscope bias
// as polynomials in temperature (core/thermal_model.h), from a log with a
// temperature column.
//
// Windows. The static intervals are cut into windows of at most
// window_seconds and at most max_window_temperature_change degrees C, so a
// pose held through a warm-up gives several windows, each with its own mean
// temperature T_k and the temperature's rate r_k (slope of T against t over
// rate_seconds around the window). Each window's raw means v_k, u_k and the
// covariance of those means (linearly detrended sample covariance / n)
// enter one Ceres problem with, per window k,
//
//   x_k = T_k - tau r_k - T_ref
//   s_k = (I + D(x_k))^-1 U (v_k - b - db(x_k))
//   e_a = (|s_k| - g) / sigma_k,   sigma_k^2 = n_k^T U C_v U^T n_k, n_k = s_k / |s_k|
//   e_g = (u_k - b_g - db_g(x_k)) / sqrt(diag C_u)     (3 residuals, when the
//                                                       log has a gyroscope)
//
// (thermal_calibration residual in src/methods/thermal_residual.h). b, U are
// the base model at T_ref (the magnitude fit's gauge: U upper triangular);
// Earth rotation is neglected in e_g (7.3e-5 rad/s).
//
// Order. Each term's order is chosen from 0 to its maximum (or held at a
// given order) by a greedy search on the information criterion (BIC: chi^2
// + p ln N, or AICc), one order step at a time; the lag tau is one more
// candidate. Orders above what the temperature span supports
// (ThermalMinimumSpan) are not tried.
//
// What the session determines. Before each solve, the columns of the
// whitened Jacobian, each scaled by a plausible size of its parameter
// (a prior range: the base bias, scale, and per power k a slope bound over
// a 30 degree characteristic range), are taken in order of priority (base
// before thermal, lower power before higher, bias before scale before
// misalignment, within a group the most sensitive first) and a parameter
// whose column, less its projection on the columns kept before it, carries
// less than min_information (squared norm: the data would shrink its prior
// range by less than sqrt(1 + min_information)) is undetermined: held at 0
// (thermal) or its starting value (base), reported as null. A single pose
// through a ramp thus determines only the bias change along gravity (which
// holds the scale change along that axis too). Every remaining parameter
// has a finite covariance, (J^T J)^-1 scaled by max(1, chi^2 / dof).
#ifndef GRAVCAL_METHODS_THERMAL_CALIBRATION_H_
#define GRAVCAL_METHODS_THERMAL_CALIBRATION_H_

#include <cmath>
#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/thermal_model.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/methods/session.h"

namespace gravcal {

// How a term's order is chosen.
enum class ThermalOrderSelection { kBic, kAicc };
// "bic", "aicc".
const char* ToString(ThermalOrderSelection selection);
bool FromString(const std::string& name, ThermalOrderSelection* selection);
std::string AcceptedNames(ThermalOrderSelection);

// The smallest temperature span (degrees C) gravcal asks for before it tries
// a polynomial of `order`: 0 for order 0, then 5, 15, 25, 35, 45. A rule
// of thumb stated once: each power needs about 10 degrees more swing for
// its shape to stand apart from the lower powers' above the pose noise of
// a MEMS part (ArduPilot refuses a TCAL over less than 10 degrees).
double ThermalMinimumSpan(int order);
// The largest order a span supports by that rule (0..kMaxThermalOrder).
int ThermalMaxOrderForSpan(double span);

struct ThermalCalibrationOptions {
  // The largest order searched per term (0 = the term is off), and a fixed
  // order per term (-1 = chosen from the data up to the maximum).
  int accel_bias_max_order = 3;
  int accel_scale_max_order = 2;
  int accel_misalignment_max_order = 1;
  int gyro_bias_max_order = 3;
  // The gyroscope's scale(T), from the turns between poses
  // (methods/thermal_turns.h); 0 = off (the gyroscope matrix is then not
  // estimated either).
  int gyro_scale_max_order = 2;
  // The gyroscope's misalignment(T), from the turns too (with the scale).
  int gyro_misalignment_max_order = 1;
  int accel_bias_order = -1;
  int accel_scale_order = -1;
  int accel_misalignment_order = -1;
  int gyro_bias_order = -1;
  int gyro_scale_order = -1;
  int gyro_misalignment_order = -1;
  // Try the first-order lag tau as one more term.
  bool fit_lag = true;
  ThermalOrderSelection selection = ThermalOrderSelection::kBic;
  // T_ref, degrees C; NaN = the middle of the session's range.
  double reference_temperature = NAN;
  // Windows (see above).
  double window_seconds = 20.0;
  double max_window_temperature_change = 0.5;
  double rate_seconds = 60.0;
  // Shortest window kept, samples.
  int min_window_samples = 20;
  // The determination threshold (see above).
  double min_information = 25.0;
  // g, m/s^2, and the raw units' nominal scales (SI per raw unit), the
  // starting U and the gyroscope's M_g (which static windows do not
  // determine).
  double gravity = 9.80665;
  double accel_nominal_scale = 1.0;
  double gyro_nominal_scale = 1.0;
  // The static detector; its level checks are off by default, since a pose
  // held through a warm-up drifts.
  StaticDetectorOptions detector = DefaultThermalDetector();
  int max_iterations = 100;

  static StaticDetectorOptions DefaultThermalDetector();
  bool IsValid(std::string* error) const;
};

// One window of the fit (see above).
struct ThermalWindow {
  size_t begin = 0;
  size_t end = 0;
  // The static interval it belongs to.
  int interval = 0;
  // Mean time, first and last sample's times (s).
  double time = 0.0;
  double t_begin = 0.0;
  double t_end = 0.0;
  double temperature = 0.0;
  // The recorded temperature's rate, degrees C per s.
  double rate = 0.0;
  Eigen::Vector3d accel_mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d accel_mean_cov = Eigen::Matrix3d::Identity();
  Eigen::Vector3d gyro_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_mean_var = Eigen::Vector3d::Ones();
  // Quantised temperature readings (TemperatureColumn): the variance of the
  // error of `temperature` the rounding leaves (degC^2; 0 = none) and the
  // group of windows that share that error (one plateau of a single
  // reading; -1 = its own).
  double temperature_variance = 0.0;
  int temperature_group = -1;
};

// The windows of `log` in the static intervals `intervals`. The log must
// have a temperature column.
std::vector<ThermalWindow> ThermalWindows(const ImuLog& log,
                                          const std::vector<StaticInterval>& intervals,
                                          const ThermalCalibrationOptions& options);

// What the temperature column looks like (issue 35): its range and
// whether its readings are quantised (whole degrees, or a register's
// least significant bit).
struct TemperatureColumn {
  double min = NAN;
  double max = NAN;
  // The quantisation step, degC; 0 = not quantised (or too few readings
  // to tell): at least 20 readings per distinct value, every distinct value
  // a multiple of the smallest gap between them, and that gap >= 0.05 degC
  // (a finer step's error, step / sqrt(12), is below a MEMS part's
  // temperature noise).
  double step = 0.0;
  size_t distinct = 0;
  // Readings outside [-80, 200] degC: not degrees (raw register counts?).
  bool implausible = false;
  // One sentence each, for check, plan and the calibration's warnings.
  std::vector<std::string> warnings;
};
TemperatureColumn InspectTemperatureColumn(const ImuLog& log);

// For quantised readings (step > 0), sets each window's
// temperature_variance and temperature_group: a window whose readings are
// one value has the rounding's error, uniform over a step (variance
// step^2 / 12), shared by the consecutive windows of that value; a window
// whose readings cross n steps averages it down to step^2 / (12 (n+1)^2),
// its own. The fit's covariance then carries these errors (thermal_fitter.h).
//
// `interpolation_std` (DequantiseTemperature; empty = none): samples with a
// value >= 0 carry an interpolated temperature of that standard deviation
// instead of a reading; a window made of them gets the mean of those
// deviations (its own error, no group), a window that mixes both kinds the
// two errors weighted by the fractions of its samples.
void SetTemperatureQuantisation(const ImuLog& log, double step,
                                const std::vector<double>& interpolation_std,
                                std::vector<ThermalWindow>* windows);

// Quantised readings (step > 0) on a steady ramp: the reading changes when
// the temperature crosses a rounding boundary (half-way between two
// readings), so a change of one step dates that boundary. Readings that
// flicker across one boundary (the sensor's noise) date it at the middle
// of the flicker. In a monotone pass whose level crossings come at regular
// intervals (each within a factor 2 of its neighbours'), the temperature is
// interpolated linearly between the dated boundaries; elsewhere (plateaus,
// turning points, the first and last levels, jumps of several steps) the
// readings stay. `temperature` is rewritten in place; `interpolation_std`
// gets, per sample, the interpolated value's standard deviation (the
// dating's spread times the slope, and the curvature the neighbouring
// intervals show, h^2 |T''| / 8 at mid-interval), or -1 for a kept reading.
void DequantiseTemperature(const std::vector<double>& t, double step,
                           std::vector<double>* temperature,
                           std::vector<double>* interpolation_std);

// What a session's temperature span allows, in sentences for check and
// plan: for each fixed order above ThermalMaxOrderForSpan ("your session
// spans 6.0 degC; the cubic accel bias term needs at least 25 degC, or
// give order 1"), and when the span is below the linear term's minimum.
// Empty when the span supports every order asked for.
std::vector<std::string> ThermalSpanMessages(double span, const ThermalCalibrationOptions& options);

// Extra results of the fit, beside Calibration.
struct ThermalFitReport {
  std::vector<ThermalWindow> windows;
  // The information criterion of each accepted search step, "bic" or
  // "aicc", and the orders in the order they were raised ("accel.bias" ...,
  // "lag").
  std::vector<double> scores;
  std::vector<std::string> steps;
  double chi2 = NAN;
  int dof = 0;
  // The parameters held because the session does not determine them.
  std::vector<std::string> undetermined;
};

// The thermal calibration of the session's log (which must have a
// temperature column). Fills calibration->thermal, the base accelerometer
// model and, with a gyroscope, its bias (gyro matrix = nominal scale, not
// determined here). `report` may be null.
bool CalibrateThermal(const Session& session, const ThermalCalibrationOptions& options,
                      Calibration* calibration, ThermalFitReport* report = nullptr);

}  // namespace gravcal

#endif  // GRAVCAL_METHODS_THERMAL_CALIBRATION_H_
