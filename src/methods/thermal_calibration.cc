#include "gravcal/methods/thermal_calibration.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "core/enum_names.h"
#include "gravcal/core/imu_corrector.h"
#include "methods/thermal_fitter.h"
#include "methods/thermal_residual.h"
#include "methods/thermal_turns.h"

namespace gravcal {

namespace {
const internal::EnumName<ThermalOrderSelection> kOrderSelections[] = {
    {ThermalOrderSelection::kBic, "bic"}, {ThermalOrderSelection::kAicc, "aicc"}};
}  // namespace

GRAVCAL_ENUM_STRINGS(ThermalOrderSelection, kOrderSelections)

double ThermalMinimumSpan(int order) { return order <= 0 ? 0.0 : 10.0 * order - 5.0; }

int ThermalMaxOrderForSpan(double span) {
  int order = 0;
  while (order < kMaxThermalOrder && ThermalMinimumSpan(order + 1) <= span) ++order;
  return order;
}

StaticDetectorOptions ThermalCalibrationOptions::DefaultThermalDetector() {
  StaticDetectorOptions d;
  // A pose held through a warm-up drifts: its level changes slowly, which
  // the level checks would cut.
  d.trend_factor = 0.0;
  d.spread_factor = 0.0;
  return d;
}

bool ThermalCalibrationOptions::IsValid(std::string* error) const {
  auto fail = [error](const std::string& what) {
    if (error != nullptr) *error = what;
    return false;
  };
  const std::pair<const char*, int> maxima[] = {
      {"thermal_accel_bias_max_order", accel_bias_max_order},
      {"thermal_accel_scale_max_order", accel_scale_max_order},
      {"thermal_accel_misalignment_max_order", accel_misalignment_max_order},
      {"thermal_gyro_bias_max_order", gyro_bias_max_order},
      {"thermal_gyro_scale_max_order", gyro_scale_max_order},
      {"thermal_gyro_misalignment_max_order", gyro_misalignment_max_order}};
  for (const auto& [key, v] : maxima) {
    if (v < 0 || v > kMaxThermalOrder) {
      return fail(std::string(key) + " must be between 0 and " + std::to_string(kMaxThermalOrder));
    }
  }
  const std::pair<const char*, int> fixed[] = {
      {"thermal_accel_bias_order", accel_bias_order},
      {"thermal_accel_scale_order", accel_scale_order},
      {"thermal_accel_misalignment_order", accel_misalignment_order},
      {"thermal_gyro_bias_order", gyro_bias_order},
      {"thermal_gyro_scale_order", gyro_scale_order},
      {"thermal_gyro_misalignment_order", gyro_misalignment_order}};
  for (const auto& [key, v] : fixed) {
    if (v < -1 || v > kMaxThermalOrder) {
      return fail(std::string(key) + " must be -1 (chosen from the data) or between 0 and " +
                  std::to_string(kMaxThermalOrder));
    }
  }
  if (!(window_seconds > 0.0)) return fail("thermal_window_seconds must be positive");
  if (!(max_window_temperature_change > 0.0)) {
    return fail("thermal_max_window_temperature_change must be positive");
  }
  if (!(rate_seconds > 0.0)) return fail("thermal_rate_seconds must be positive");
  if (min_window_samples < 3) return fail("thermal min_window_samples must be at least 3");
  if (!(min_information > 0.0)) return fail("thermal_min_information must be positive");
  if (!(gravity > 0.0)) return fail("gravity must be positive");
  if (!(accel_nominal_scale > 0.0) || !(gyro_nominal_scale > 0.0)) {
    return fail("nominal_scale and gyro_nominal_scale must be positive");
  }
  if (max_iterations < 1) return fail("max_iterations must be at least 1");
  return detector.IsValid(error);
}

namespace internal {

ThermalLayout::ThermalLayout(const ThermalOrders& o, bool gyro) : orders(o), has_gyro(gyro) {
  auto add = [this](const std::string& name, int grp, Slot slot) {
    names.push_back(name);
    group.push_back(grp);
    slots.push_back(slot);
    return static_cast<int>(names.size()) - 1;
  };
  const char* axes[3] = {"x", "y", "z"};
  bias = 0;
  for (int i = 0; i < 3; ++i) {
    add(std::string("accel.bias.") + axes[i] + ".c0", 0,
        {false, ThermalSensor::kAccel, ThermalQuantity::kBias, i, 0});
  }
  upper = 3;
  const char* upper_names[6] = {"u00", "u01", "u02", "u11", "u12", "u22"};
  for (int i = 0; i < 6; ++i) {
    add(std::string("accel.upper.") + upper_names[i], 1,
        {false, ThermalSensor::kAccel, ThermalQuantity::kScale, i, 0});
  }
  if (has_gyro) {
    gyro_bias = 9;
    for (int i = 0; i < 3; ++i) {
      add(std::string("gyro.bias.") + axes[i] + ".c0", 2,
          {false, ThermalSensor::kGyro, ThermalQuantity::kBias, i, 0});
    }
  }
  if (o.lag)
    lag = add("lag.tau", 1000, {false, ThermalSensor::kAccel, ThermalQuantity::kBias, 3, 0});
  // A thermal term: components x order, row-major; priority by power.
  auto term = [&](ThermalSensor s, ThermalQuantity q, int order, int rank) {
    if (order <= 0) return -1;
    const int start = static_cast<int>(names.size());
    const std::vector<std::string> comps = ThermalComponentNames(s, q);
    for (size_t i = 0; i < comps.size(); ++i) {
      for (int k = 1; k <= order; ++k) {
        add(std::string(ToString(s)) + "." + ToString(q) + "." + comps[i] + ".c" +
                std::to_string(k),
            10 * k + rank, {true, s, q, static_cast<int>(i), k});
      }
    }
    return start;
  };
  accel_bias = term(ThermalSensor::kAccel, ThermalQuantity::kBias, o.accel_bias, 0);
  accel_scale = term(ThermalSensor::kAccel, ThermalQuantity::kScale, o.accel_scale, 2);
  accel_misalignment =
      term(ThermalSensor::kAccel, ThermalQuantity::kMisalignment, o.accel_misalignment, 3);
  if (has_gyro) {
    gyro_thermal_bias = term(ThermalSensor::kGyro, ThermalQuantity::kBias, o.gyro_bias, 1);
  }
  size = static_cast<int>(names.size());
}

}  // namespace internal

namespace {

const char* OrderName(int order) {
  static const char* names[] = {"constant", "linear", "quadratic", "cubic", "quartic", "quintic"};
  return order >= 0 && order <= 5 ? names[order] : "high-order";
}

std::string Degrees(double v) {
  std::ostringstream s;
  s.precision(1);
  s << std::fixed << v << " degC";
  return s.str();
}

}  // namespace

std::vector<std::string> ThermalSpanMessages(double span, const ThermalCalibrationOptions& o) {
  std::vector<std::string> out;
  const int supported = ThermalMaxOrderForSpan(span);
  const std::pair<const char*, int> fixed[] = {{"accel bias", o.accel_bias_order},
                                               {"accel scale", o.accel_scale_order},
                                               {"accel misalignment", o.accel_misalignment_order},
                                               {"gyro bias", o.gyro_bias_order},
                                               {"gyro scale", o.gyro_scale_order},
                                               {"gyro misalignment", o.gyro_misalignment_order}};
  for (const auto& [name, order] : fixed) {
    if (order <= supported) continue;
    out.push_back("your session spans " + Degrees(span) + "; the " + OrderName(order) + " " + name +
                  " term needs at least " + Degrees(ThermalMinimumSpan(order)) +
                  (supported > 0 ? ", or give order " + std::to_string(supported)
                                 : ": record a wider swing, or give order 0"));
  }
  if (supported == 0) {
    out.push_back("your session spans " + Degrees(span) + "; a temperature term needs at least " +
                  Degrees(ThermalMinimumSpan(1)) +
                  " of swing (warm the unit up, or soak it at two temperatures)");
  }
  return out;
}

namespace {

using internal::ThermalElementSeries;
using internal::ThermalFit;
using internal::ThermalFitter;
using internal::ThermalLayout;
using internal::ThermalOrders;
using internal::ThermalWindowResidual;

std::map<std::string, double> Named(const ThermalOrders& orders, bool has_gyro,
                                    const ThermalFit& fit) {
  const ThermalLayout layout(orders, has_gyro);
  std::map<std::string, double> out;
  for (int j = 0; j < layout.size; ++j) {
    if (!fit.fixed[j]) out[layout.names[j]] = fit.theta[j];
  }
  return out;
}

// The greedy search (header): raise one term's order (or switch the lag on)
// at a time while the criterion improves.
struct SearchTerm {
  const char* name;
  int ThermalOrders::*order;
  int max_order;
  int fixed;
};

// Fills one thermal term from the fit.
void FillTerm(const ThermalLayout& layout, const ThermalFit& fit, ThermalSensor sensor,
              ThermalQuantity q, int start, int order, int max_order, const std::string& selection,
              ThermalPolynomial* p) {
  const int n = ThermalComponents(sensor, q);
  p->Resize(n, order);
  p->max_order = max_order;
  p->selection = selection;
  // Order 0 keeps the covariance of the bias's constant (a band at every T).
  if (order == 0 && q != ThermalQuantity::kBias) return;
  for (int i = 0; i < n; ++i) {
    // [c_i0, c_i1 .. c_in]: c_i0 the base parameter when the term is a
    // bias (the scale and misalignment terms' constant is in U / M_g, whose
    // parameterisation differs: their c_i0 row is left zero).
    std::vector<int> index(order + 1, -1);
    if (q == ThermalQuantity::kBias) {
      index[0] = (sensor == ThermalSensor::kAccel ? layout.bias : layout.gyro_bias) + i;
    }
    for (int k = 1; k <= order; ++k) index[k] = start + i * order + k - 1;
    Eigen::MatrixXd c = Eigen::MatrixXd::Zero(order + 1, order + 1);
    for (int a = 0; a <= order; ++a) {
      for (int b = 0; b <= order; ++b) {
        if (index[a] >= 0 && index[b] >= 0) c(a, b) = fit.covariance(index[a], index[b]);
      }
    }
    p->covariance.push_back(c);
    for (int k = 1; k <= order; ++k) {
      const int j = index[k];
      const bool known = !fit.fixed[j];
      p->determined(i, k - 1) = known;
      p->coefficients(i, k - 1) = known ? fit.theta[j] : 0.0;
    }
  }
}

// "x, y" of the components of `p` with an undetermined coefficient.
std::string UndeterminedComponents(ThermalSensor s, ThermalQuantity q, const ThermalPolynomial& p) {
  const std::vector<std::string> names = ThermalComponentNames(s, q);
  std::string out;
  for (int i = 0; i < p.coefficients.rows(); ++i) {
    bool any = false;
    for (int k = 1; k <= p.order; ++k) any = any || !p.Determined(i, k);
    if (any) out += (out.empty() ? "" : ", ") + names[i];
  }
  return out;
}

// The number of distinct pose directions among the windows (10 degrees
// apart).
int DistinctPoses(const std::vector<ThermalWindow>& windows) {
  std::vector<Eigen::Vector3d> seen;
  for (const ThermalWindow& w : windows) {
    const Eigen::Vector3d d = w.accel_mean.normalized();
    bool known = false;
    for (const Eigen::Vector3d& s : seen) known = known || s.dot(d) > std::cos(10.0 * M_PI / 180.0);
    if (!known) seen.push_back(d);
  }
  return static_cast<int>(seen.size());
}

}  // namespace

bool CalibrateThermal(const Session& session, const ThermalCalibrationOptions& options,
                      Calibration* calibration, ThermalFitReport* report) {
  Calibration out;
  out.method = ToString(Method::kThermal);
  out.gravity = options.gravity;
  out.gravity_source = "config";
  std::string error;
  auto fail = [&](const std::string& message) {
    out.success = false;
    out.message = message;
    *calibration = out;
    return false;
  };
  if (!options.IsValid(&error)) return fail(error);
  const ImuLog& log = session.log;
  if (!log.Validate(&error)) return fail(error);
  if (!log.has_temperature()) {
    return fail(log.source +
                ": the thermal calibration needs a temperature column (degrees C); the log has "
                "none");
  }
  StaticDetection detection;
  if (!DetectStaticIntervals(log, options.detector, &detection)) return fail(detection.message);
  const TemperatureColumn column = InspectTemperatureColumn(log);
  if (column.implausible) return fail(log.source + ": " + column.warnings.front());
  // Quantised readings: the fit reads the temperature interpolated across
  // the rounding boundaries of steady ramps (DequantiseTemperature).
  ImuLog dequantised;
  std::vector<double> interpolation_std;
  if (column.step > 0.0) {
    dequantised = log;
    DequantiseTemperature(log.t, column.step, &dequantised.temperature, &interpolation_std);
  }
  const ImuLog& fit_log = column.step > 0.0 ? dequantised : log;
  std::vector<ThermalWindow> windows = ThermalWindows(fit_log, detection.intervals, options);
  SetTemperatureQuantisation(log, column.step, interpolation_std, &windows);
  if (windows.size() < 3) {
    return fail(log.source + ": " + std::to_string(windows.size()) +
                " static windows; the thermal calibration needs at least 3");
  }
  double lo = INFINITY, hi = -INFINITY;
  for (const ThermalWindow& w : windows) {
    lo = std::min(lo, w.temperature);
    hi = std::max(hi, w.temperature);
  }
  const double span = hi - lo;
  const double reference = std::isfinite(options.reference_temperature)
                               ? options.reference_temperature
                               : std::round(5.0 * (lo + hi)) / 10.0;
  const bool has_gyro = log.has_gyro();
  // The element temperature's grid: 1 s, or the sample period when longer.
  const internal::ThermalElementSeries element(
      fit_log, std::max(1.0, (log.t.back() - log.t.front()) / std::max<size_t>(1, log.size() - 1)));
  ThermalFitter fitter(windows, element, options, has_gyro, reference, span);
  const int poses = DistinctPoses(windows);
  // A pose within 10 degrees of a face counts as that face (as check does).
  bool faces_only = true;
  for (const ThermalWindow& w : windows) {
    const Eigen::Vector3d d = w.accel_mean.normalized();
    faces_only = faces_only && d.cwiseAbs().maxCoeff() > std::cos(10.0 * M_PI / 180.0);
  }
  fitter.SetFacesOnly(faces_only);
  if (poses == 1) {
    Eigen::Index axis = 0;
    windows.front().accel_mean.cwiseAbs().maxCoeff(&axis);
    fitter.SetSinglePose(static_cast<int>(axis));
  }
  const int supported = ThermalMaxOrderForSpan(span);
  const SearchTerm terms[] = {
      {"accel.bias", &ThermalOrders::accel_bias, options.accel_bias_max_order,
       options.accel_bias_order},
      {"accel.scale", &ThermalOrders::accel_scale, options.accel_scale_max_order,
       options.accel_scale_order},
      {"accel.misalignment", &ThermalOrders::accel_misalignment,
       options.accel_misalignment_max_order, options.accel_misalignment_order},
      {"gyro.bias", &ThermalOrders::gyro_bias, has_gyro ? options.gyro_bias_max_order : 0,
       has_gyro ? options.gyro_bias_order : 0}};
  ThermalOrders orders;
  for (const SearchTerm& t : terms) {
    if (t.fixed >= 0) orders.*(t.order) = t.fixed;
  }
  ThermalFit best = fitter.Run(orders, {});
  if (!best.ok) return fail(log.source + ": the thermal fit failed (" + best.message + ")");
  double best_score = fitter.Score(best);
  ThermalFitReport rep;
  rep.scores.push_back(best_score);
  rep.steps.push_back("start");
  while (true) {
    ThermalOrders chosen = orders;
    ThermalFit chosen_fit;
    double chosen_score = best_score;
    std::string chosen_name;
    auto consider = [&](const ThermalOrders& candidate, const std::string& name) {
      ThermalFit f = fitter.Run(candidate, Named(orders, has_gyro, best));
      // A step whose new coefficients are all undetermined adds nothing; an
      // unconverged fit's criterion says nothing.
      if (!f.ok || !f.converged || f.free <= best.free) return;
      const double s = fitter.Score(f);
      if (s < chosen_score) {
        chosen_score = s;
        chosen = candidate;
        chosen_fit = std::move(f);
        chosen_name = name;
      }
    };
    for (const SearchTerm& t : terms) {
      if (t.fixed >= 0) continue;
      const int limit = std::min(t.max_order, supported);
      if (orders.*(t.order) >= limit) continue;
      ThermalOrders candidate = orders;
      ++(candidate.*(t.order));
      consider(candidate, t.name);
    }
    if (options.fit_lag && !orders.lag) {
      ThermalOrders candidate = orders;
      candidate.lag = true;
      consider(candidate, "lag");
    }
    if (chosen_name.empty()) break;
    orders = chosen;
    best = std::move(chosen_fit);
    best_score = chosen_score;
    rep.scores.push_back(best_score);
    rep.steps.push_back(chosen_name);
  }

  // The calibration.
  const ThermalLayout layout(orders, has_gyro);
  ThermalModel& model = out.thermal;
  model.reference_temperature = reference;
  // The valid range: every sample of the windows (their means lie inside
  // it, the temperature sensor's noise around them does not).
  model.min_temperature = lo;
  model.max_temperature = hi;
  for (const ThermalWindow& w : windows) {
    for (size_t i = w.begin; i < w.end; ++i) {
      model.min_temperature = std::min(model.min_temperature, log.temperature[i]);
      model.max_temperature = std::max(model.max_temperature, log.temperature[i]);
    }
  }
  const std::string selection = ToString(options.selection);
  auto how = [&](int fixed) { return fixed >= 0 ? std::string("given") : selection; };
  FillTerm(layout, best, ThermalSensor::kAccel, ThermalQuantity::kBias, layout.accel_bias,
           orders.accel_bias, std::max(options.accel_bias_max_order, orders.accel_bias),
           how(options.accel_bias_order), &model.accel.bias);
  FillTerm(layout, best, ThermalSensor::kAccel, ThermalQuantity::kScale, layout.accel_scale,
           orders.accel_scale, std::max(options.accel_scale_max_order, orders.accel_scale),
           how(options.accel_scale_order), &model.accel.scale);
  FillTerm(layout, best, ThermalSensor::kAccel, ThermalQuantity::kMisalignment,
           layout.accel_misalignment, orders.accel_misalignment,
           std::max(options.accel_misalignment_max_order, orders.accel_misalignment),
           how(options.accel_misalignment_order), &model.accel.misalignment);
  if (has_gyro) {
    FillTerm(layout, best, ThermalSensor::kGyro, ThermalQuantity::kBias, layout.gyro_thermal_bias,
             orders.gyro_bias, std::max(options.gyro_bias_max_order, orders.gyro_bias),
             how(options.gyro_bias_order), &model.gyro.bias);
  }
  if (orders.lag && !best.fixed[layout.lag]) {
    model.lag_time_constant = best.theta[layout.lag];
    model.lag_time_constant_std = std::sqrt(best.covariance(layout.lag, layout.lag));
    model.lag_estimated = true;
  }
  // Base models and their standard deviations.
  AccelModel& accel = out.accel.model;
  accel.parameterization = AccelParameterization::kScaleMisalignment;
  accel.bias = Eigen::Vector3d(best.theta[0], best.theta[1], best.theta[2]);
  accel.SetUpper(best.theta.data() + layout.upper);
  accel.rotation.setIdentity();
  const int upper_row[6] = {0, 0, 0, 1, 1, 2}, upper_col[6] = {0, 1, 2, 1, 2, 2};
  out.accel.matrix_std = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) {
    out.accel.bias_std(i) = best.fixed[i] ? NAN : std::sqrt(best.covariance(i, i));
  }
  for (int i = 0; i < 6; ++i) {
    const int j = layout.upper + i;
    out.accel.matrix_std(upper_row[i], upper_col[i]) =
        best.fixed[j] ? NAN : std::sqrt(best.covariance(j, j));
  }
  // The base model's covariance at T_ref (the determined b and U entries,
  // marginal over the thermal terms), for compare and verify.
  {
    const char* names[9] = {"bias_x", "bias_y", "bias_z", "u_xx", "u_xy",
                            "u_xz",   "u_yy",   "u_yz",   "u_zz"};
    std::vector<int> kept;
    for (int j = 0; j < 9; ++j) {
      if (best.fixed[j]) continue;
      kept.push_back(j);
      out.accel.covariance_names.push_back(names[j]);
    }
    out.accel.covariance.resize(kept.size(), kept.size());
    for (size_t r = 0; r < kept.size(); ++r) {
      for (size_t c = 0; c < kept.size(); ++c) {
        out.accel.covariance(r, c) = best.covariance(kept[r], kept[c]);
      }
    }
  }
  for (int j = 0; j < layout.size; ++j) {
    if (!best.fixed[j]) continue;
    rep.undetermined.push_back(layout.names[j]);
  }
  if (has_gyro) {
    out.gyro.estimated = true;
    out.gyro.model.bias =
        Eigen::Vector3d(best.theta[layout.gyro_bias], best.theta[layout.gyro_bias + 1],
                        best.theta[layout.gyro_bias + 2]);
    out.gyro.model.matrix = options.gyro_nominal_scale * Eigen::Matrix3d::Identity();
    for (int i = 0; i < 3; ++i) {
      const int j = layout.gyro_bias + i;
      out.gyro.bias_std(i) = best.fixed[j] ? NAN : std::sqrt(best.covariance(j, j));
    }
  }
  // What the session determined, plainly.
  if (poses == 1) {
    model.notes.push_back(
        "one static pose: of the accelerometer only the bias change along gravity is determined "
        "(it also holds that axis's scale change times g); the other axes' bias terms, every "
        "scale and misalignment term and the base scale are undetermined (the gyroscope's bias "
        "at rest is seen in any pose)");
  }
  for (ThermalSensor s : {ThermalSensor::kAccel, ThermalSensor::kGyro}) {
    for (ThermalQuantity q :
         {ThermalQuantity::kBias, ThermalQuantity::kScale, ThermalQuantity::kMisalignment}) {
      const ThermalPolynomial& p = model.Sensor(s).Term(q);
      const std::string which = UndeterminedComponents(s, q, p);
      if (!which.empty()) {
        model.notes.push_back(std::string(ToString(s)) + " " + ToString(q) + ": " + which +
                              " undetermined by this session (reported as null, applied as 0)");
      }
    }
  }
  if (has_gyro && (options.gyro_scale_max_order > 0 || options.gyro_scale_order > 0)) {
    internal::AddThermalTurns(fit_log, detection.intervals, windows, options, &out);
  }
  if (model.lag_estimated) {
    std::ostringstream s;
    s.precision(3);
    s << "the heating and cooling branches disagree: the element lags the temperature sensor by "
      << model.lag_time_constant << " s (std " << model.lag_time_constant_std << " s)";
    model.notes.push_back(s.str());
  }
  for (const std::string& m : column.warnings) {
    out.warnings.push_back(m);
    out.warning_codes.push_back(WarningCode::kSensorData);
  }
  for (const std::string& m : ThermalSpanMessages(span, options)) {
    out.warnings.push_back(m);
    out.warning_codes.push_back(WarningCode::kUndetermined);
  }
  if (!fitter.scale_note().empty()) {
    out.warnings.push_back(fitter.scale_note());
    out.warning_codes.push_back(WarningCode::kUnclassified);
  }
  // Positions: one per static interval, with the residual after the model.
  ImuCorrector corrector;
  corrector.accel = accel;
  corrector.thermal = model;
  std::vector<double> before, after;
  for (const StaticInterval& in : detection.intervals) {
    PositionReport r;
    r.position.raw_mean = in.accel_mean;
    r.position.raw_mean_cov = in.accel_cov / std::max<size_t>(1, in.count());
    r.position.t_begin = in.t_begin;
    r.position.t_end = in.t_end;
    r.position.sample_count = in.count();
    r.position.temperature = in.temperature_mean;
    Eigen::Vector3d a;
    corrector.CorrectAccel(in.accel_mean, in.temperature_mean, 0.0, &a);
    r.residual_after = a.norm() - options.gravity;
    r.residual_before = (accel.Apply(in.accel_mean)).norm() - options.gravity;
    before.push_back(r.residual_before);
    after.push_back(r.residual_after);
    out.positions.push_back(r);
  }
  out.residual_nominal = SummarizeResiduals(before);
  out.residual_coarse = out.residual_nominal;
  out.residual_refined = SummarizeResiduals(after);
  out.solver_name = "ceres";
  out.refinement.converged = true;
  out.refinement.final_cost = 0.5 * best.chi2;
  out.refinement.chi2 = best.chi2;
  out.refinement.dof = best.residuals - best.free;
  out.refinement.message = best.message;
  out.success = true;
  std::ostringstream msg;
  msg << "thermal calibration over " << windows.size() << " windows in "
      << detection.intervals.size() << " static intervals (" << poses << " pose directions), "
      << Degrees(lo) << " to " << Degrees(hi) << "; orders: accel bias " << orders.accel_bias
      << ", scale " << orders.accel_scale << ", misalignment " << orders.accel_misalignment;
  if (has_gyro) msg << ", gyro bias " << orders.gyro_bias;
  msg << (model.lag_estimated ? ", lag on" : "") << " (" << selection << ")";
  out.message = msg.str();
  rep.windows = windows;
  rep.chi2 = best.chi2;
  rep.dof = best.residuals - best.free;
  if (report != nullptr) *report = std::move(rep);
  *calibration = std::move(out);
  return true;
}

}  // namespace gravcal
