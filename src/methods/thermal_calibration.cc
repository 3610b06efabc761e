#include "gravcal/methods/thermal_calibration.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "gravcal/core/imu_corrector.h"
#include "methods/thermal_residual.h"

namespace gravcal {

const char* ToString(ThermalOrderSelection selection) {
  return selection == ThermalOrderSelection::kAicc ? "aicc" : "bic";
}

bool FromString(const std::string& name, ThermalOrderSelection* selection) {
  if (selection == nullptr) return false;
  if (name == "bic") {
    *selection = ThermalOrderSelection::kBic;
  } else if (name == "aicc") {
    *selection = ThermalOrderSelection::kAicc;
  } else {
    return false;
  }
  return true;
}

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
      {"thermal_gyro_bias_max_order", gyro_bias_max_order}};
  for (const auto& [key, v] : maxima) {
    if (v < 0 || v > kMaxThermalOrder) {
      return fail(std::string(key) + " must be between 0 and " + std::to_string(kMaxThermalOrder));
    }
  }
  const std::pair<const char*, int> fixed[] = {
      {"thermal_accel_bias_order", accel_bias_order},
      {"thermal_accel_scale_order", accel_scale_order},
      {"thermal_accel_misalignment_order", accel_misalignment_order},
      {"thermal_gyro_bias_order", gyro_bias_order}};
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

using internal::ThermalElementSeries;
using internal::ThermalLayout;
using internal::ThermalOrders;
using internal::ThermalWindowResidual;

// Slope of the temperature against time over samples [a, b), degrees C/s.
double TemperatureSlope(const ImuLog& log, size_t a, size_t b) {
  if (b <= a + 1) return 0.0;
  double st = 0.0, sy = 0.0;
  for (size_t i = a; i < b; ++i) {
    st += log.t[i];
    sy += log.temperature[i];
  }
  const double n = static_cast<double>(b - a);
  const double mt = st / n, my = sy / n;
  double num = 0.0, den = 0.0;
  for (size_t i = a; i < b; ++i) {
    num += (log.t[i] - mt) * (log.temperature[i] - my);
    den += (log.t[i] - mt) * (log.t[i] - mt);
  }
  return den > 0.0 ? num / den : 0.0;
}

// Mean and covariance of the mean of samples [a, b) of `v`, the covariance
// from the residuals of a straight line in time (a slow drift is not noise).
void DetrendedMean(const std::vector<double>& t, const std::vector<Eigen::Vector3d>& v, size_t a,
                   size_t b, Eigen::Vector3d* mean, Eigen::Matrix3d* mean_cov) {
  const double n = static_cast<double>(b - a);
  double mt = 0.0;
  Eigen::Vector3d mv = Eigen::Vector3d::Zero();
  for (size_t i = a; i < b; ++i) {
    mt += t[i];
    mv += v[i];
  }
  mt /= n;
  mv /= n;
  double stt = 0.0;
  Eigen::Vector3d stv = Eigen::Vector3d::Zero();
  for (size_t i = a; i < b; ++i) {
    stt += (t[i] - mt) * (t[i] - mt);
    stv += (t[i] - mt) * (v[i] - mv);
  }
  const Eigen::Vector3d slope = stt > 0.0 ? Eigen::Vector3d(stv / stt) : Eigen::Vector3d::Zero();
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  for (size_t i = a; i < b; ++i) {
    const Eigen::Vector3d r = v[i] - mv - slope * (t[i] - mt);
    c += r * r.transpose();
  }
  *mean = mv;
  *mean_cov = c / ((n - 2.0) * n);
}

}  // namespace

std::vector<ThermalWindow> ThermalWindows(const ImuLog& log,
                                          const std::vector<StaticInterval>& intervals,
                                          const ThermalCalibrationOptions& options) {
  std::vector<ThermalWindow> windows;
  if (!log.has_temperature()) return windows;
  for (size_t k = 0; k < intervals.size(); ++k) {
    const StaticInterval& in = intervals[k];
    const size_t count = in.end - in.begin;
    if (count < static_cast<size_t>(options.min_window_samples)) continue;
    const double duration = log.t[in.end - 1] - log.t[in.begin];
    const auto [lo, hi] =
        std::minmax_element(log.temperature.begin() + in.begin, log.temperature.begin() + in.end);
    const double change = *hi - *lo;
    int parts =
        static_cast<int>(std::max(std::ceil(duration / options.window_seconds),
                                  std::ceil(change / options.max_window_temperature_change)));
    parts = std::max(1, std::min(parts, static_cast<int>(count / options.min_window_samples)));
    for (int p = 0; p < parts; ++p) {
      ThermalWindow w;
      w.interval = static_cast<int>(k);
      w.begin = in.begin + count * p / parts;
      w.end = in.begin + count * (p + 1) / parts;
      double sum_t = 0.0, sum_temperature = 0.0;
      for (size_t i = w.begin; i < w.end; ++i) {
        sum_t += log.t[i];
        sum_temperature += log.temperature[i];
      }
      const double n = static_cast<double>(w.end - w.begin);
      w.time = sum_t / n;
      w.t_begin = log.t[w.begin];
      w.t_end = log.t[w.end - 1];
      w.temperature = sum_temperature / n;
      // The rate over rate_seconds around the window, all samples.
      const double half = 0.5 * options.rate_seconds;
      const size_t a = std::lower_bound(log.t.begin(), log.t.end(), w.time - half) - log.t.begin();
      const size_t b = std::upper_bound(log.t.begin(), log.t.end(), w.time + half) - log.t.begin();
      w.rate = TemperatureSlope(log, a, b);
      DetrendedMean(log.t, log.accel, w.begin, w.end, &w.accel_mean, &w.accel_mean_cov);
      if (log.has_gyro()) {
        Eigen::Matrix3d c;
        DetrendedMean(log.t, log.gyro, w.begin, w.end, &w.gyro_mean, &c);
        w.gyro_mean_var = c.diagonal().cwiseMax(1e-30);
      }
      windows.push_back(w);
    }
  }
  return windows;
}

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
                                               {"gyro bias", o.gyro_bias_order}};
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

// The accelerometer scale the fit starts from: nominal_scale, unless the
// window means read with it are not near gravity (median |a| outside
// [0.5 g, 1.5 g]: raw counts with nominal_scale 1, or SI data given a
// counts sensitivity). Then the data's own scale g / median |a_raw| is used
// and `note` says so (an offset-free start; the fit estimates the rest).
double StartAccelScale(const std::vector<ThermalWindow>& windows,
                       const ThermalCalibrationOptions& o, std::string* note) {
  std::vector<double> norms;
  for (const ThermalWindow& w : windows) norms.push_back(w.accel_mean.norm());
  if (norms.empty()) return o.accel_nominal_scale;
  std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
  const double median = norms[norms.size() / 2];
  const double read = median * o.accel_nominal_scale;
  if (!(median > 0.0) || (read > 0.5 * o.gravity && read < 1.5 * o.gravity)) {
    return o.accel_nominal_scale;
  }
  const double scale = o.gravity / median;
  std::ostringstream s;
  s.precision(4);
  s << "nominal_scale " << o.accel_nominal_scale << " reads the static poses as " << read
    << " m/s^2, not gravity: the fit starts from the data's own scale " << scale
    << " (set nominal_scale to m/s^2 per raw unit)";
  *note = s.str();
  return scale;
}

// One fit at fixed orders.
struct Fit {
  bool ok = false;
  std::vector<double> theta;
  std::vector<bool> fixed;
  double chi2 = NAN;
  int free = 0;
  int residuals = 0;
  Eigen::MatrixXd covariance;  // layout.size square, zero rows for held ones
  std::string message;
};

class ThermalFitter {
 public:
  ThermalFitter(const std::vector<ThermalWindow>& windows, const ThermalElementSeries& element,
                const ThermalCalibrationOptions& o, bool has_gyro, double reference_temperature,
                double span)
      : windows_(windows),
        element_(element),
        o_(o),
        has_gyro_(has_gyro),
        reference_(reference_temperature),
        half_span_(std::max(1.0, 0.5 * span)) {
    start_accel_scale_ = StartAccelScale(windows, o, &scale_note_);
    // The spread of the window means per axis, the data-based floor of the
    // bias terms' prior ranges: for the accelerometer within each static
    // interval (between poses gravity moves, not the temperature), for the
    // gyroscope over all windows.
    Eigen::Vector3d glo = Eigen::Vector3d::Constant(INFINITY), ghi = -glo;
    std::map<int, std::pair<Eigen::Vector3d, Eigen::Vector3d>> per_interval;
    for (const ThermalWindow& w : windows) {
      auto it = per_interval.find(w.interval);
      if (it == per_interval.end()) {
        per_interval[w.interval] = {w.accel_mean, w.accel_mean};
      } else {
        it->second.first = it->second.first.cwiseMin(w.accel_mean);
        it->second.second = it->second.second.cwiseMax(w.accel_mean);
      }
      glo = glo.cwiseMin(w.gyro_mean);
      ghi = ghi.cwiseMax(w.gyro_mean);
    }
    for (const auto& [interval, range] : per_interval) {
      accel_range_ = std::max(accel_range_, (range.second - range.first).maxCoeff());
    }
    gyro_range_ = (ghi - glo).maxCoeff();
  }

  // Fits `orders`, starting from `start` (parameters matched by name).
  Fit Run(const ThermalOrders& orders, const std::map<std::string, double>& start) const {
    const ThermalLayout layout(orders, has_gyro_);
    std::vector<double> initial(layout.size, 0.0);
    initial[layout.upper + 0] = initial[layout.upper + 3] = initial[layout.upper + 5] =
        start_accel_scale_;
    if (has_gyro_) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const ThermalWindow& w : windows_) mean += w.gyro_mean;
      mean /= static_cast<double>(windows_.size());
      for (int i = 0; i < 3; ++i) initial[layout.gyro_bias + i] = mean(i);
    }
    for (int j = 0; j < layout.size; ++j) {
      const auto it = start.find(layout.names[j]);
      if (it != start.end()) initial[j] = it->second;
    }
    // U's off-diagonal starts (and, when undetermined, stays) at 0, not at
    // a previous step's value.
    for (int k : {1, 2, 4}) initial[layout.upper + k] = 0.0;
    // What is determined depends on where the Jacobian is taken (a bias far
    // from its value tilts the poses' directions and lends the
    // non-orthogonality information it does not have), so the test is
    // taken twice: at the start, for a first solve that also holds U's
    // off-diagonal (on the faces |U d| depends on it only to second order,
    // and a free start slides along that valley), then once more at that
    // first solution, whose bias and scale are the data's, for the final
    // solve from `initial`. It is not repeated at the final solution: one
    // that slid along a valley the poses leave open (six faces and one or
    // two tilted poses: U's columns turned by tens of degrees, the bias at
    // metres per second squared) would find itself determined there.
    Fit fit;
    fit.theta = initial;
    std::vector<double> sigmas = AccelSigmas(layout, initial);
    fit.fixed = Held(layout, Undetermined(layout, fit.theta, sigmas));
    for (int j : {layout.upper + 1, layout.upper + 2, layout.upper + 4}) fit.fixed[j] = true;
    if (!Solve(layout, sigmas, &fit)) return fit;
    sigmas = AccelSigmas(layout, fit.theta);
    const std::vector<bool> again = Held(layout, Undetermined(layout, fit.theta, sigmas));
    if (again != fit.fixed) {
      fit.fixed = again;
      fit.theta = initial;
      if (!Solve(layout, sigmas, &fit)) return fit;
      sigmas = AccelSigmas(layout, fit.theta);
    }
    Covariance(layout, sigmas, &fit);
    return fit;
  }

  // One pose direction: the magnitude sees only the component along
  // gravity (axis `single_axis_`), so everything else of the accelerometer
  // is held: U, the other axes' bias and bias terms, scale and
  // misalignment. (The linearised test would otherwise read the thermal
  // drift of the level axes as information on their base bias.)
  void SetSinglePose(int axis) { single_axis_ = axis; }
  // Only poses near the faces: the non-orthogonality (U's off-diagonal
  // and its thermal terms) enters |U d| to second order only and is held.
  void SetFacesOnly(bool faces_only) { faces_only_ = faces_only; }

  double Score(const Fit& f) const {
    const double n = f.residuals, k = f.free;
    if (o_.selection == ThermalOrderSelection::kAicc) {
      return f.chi2 + 2.0 * k + (n - k - 1.0 > 0.0 ? 2.0 * k * (k + 1.0) / (n - k - 1.0) : 1e30);
    }
    return f.chi2 + k * std::log(n);
  }

  // Non-empty when nominal_scale did not read the poses near gravity.
  const std::string& scale_note() const { return scale_note_; }

 private:
  std::vector<bool> Held(const ThermalLayout& layout, std::vector<bool> fixed) const {
    if (faces_only_) {
      for (int j : {layout.upper + 1, layout.upper + 2, layout.upper + 4}) fixed[j] = true;
      for (int j = 0; j < layout.size; ++j) {
        const ThermalLayout::Slot& s = layout.slots[j];
        if (s.thermal && s.sensor == ThermalSensor::kAccel &&
            s.quantity == ThermalQuantity::kMisalignment) {
          fixed[j] = true;
        }
      }
    }
    if (single_axis_ < 0) return fixed;
    for (int j = 0; j < layout.size; ++j) {
      const ThermalLayout::Slot& s = layout.slots[j];
      if (s.sensor != ThermalSensor::kAccel || j == layout.lag) continue;
      if (j >= layout.upper && j < layout.upper + 6) {
        fixed[j] = true;
      } else if (s.quantity != ThermalQuantity::kBias || s.component != single_axis_) {
        fixed[j] = true;
      }
    }
    return fixed;
  }

  // sigma_k of the magnitude residual: n^T U C_v U^T n at theta.
  std::vector<double> AccelSigmas(const ThermalLayout& layout,
                                  const std::vector<double>& theta) const {
    Eigen::Matrix3d u = Eigen::Matrix3d::Zero();
    const double* p = theta.data() + layout.upper;
    u << p[0], p[1], p[2], 0.0, p[3], p[4], 0.0, 0.0, p[5];
    const Eigen::Vector3d b(theta[0], theta[1], theta[2]);
    std::vector<double> out;
    for (const ThermalWindow& w : windows_) {
      Eigen::Vector3d s = u * (w.accel_mean - b);
      if (!(s.norm() > 0.0)) s = Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d n = s.normalized();
      const double v = n.dot(u * w.accel_mean_cov * u.transpose() * n);
      out.push_back(std::sqrt(std::max(v, 1e-300)));
    }
    return out;
  }

  void Build(const ThermalLayout& layout, const std::vector<double>& sigmas, double* theta,
             ceres::Problem* problem) const {
    for (size_t k = 0; k < windows_.size(); ++k) {
      problem->AddResidualBlock(ThermalWindowResidual::Create(layout, windows_[k], &element_,
                                                              reference_, o_.gravity, sigmas[k]),
                                nullptr, theta);
    }
  }

  // The whitened Jacobian at theta, dense (residuals x parameters).
  Eigen::MatrixXd Jacobian(const ThermalLayout& layout, const std::vector<double>& sigmas,
                           std::vector<double> theta, Eigen::VectorXd* residual) const {
    ceres::Problem::Options po;
    ceres::Problem problem(po);
    Build(layout, sigmas, theta.data(), &problem);
    ceres::CRSMatrix crs;
    std::vector<double> r;
    problem.Evaluate(ceres::Problem::EvaluateOptions(), nullptr, &r, nullptr, &crs);
    Eigen::MatrixXd j = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
    for (int row = 0; row < crs.num_rows; ++row) {
      for (int at = crs.rows[row]; at < crs.rows[row + 1]; ++at) {
        j(row, crs.cols[at]) = crs.values[at];
      }
    }
    if (residual != nullptr) *residual = Eigen::Map<Eigen::VectorXd>(r.data(), r.size());
    return j;
  }

  // A plausible size of each parameter (the header's prior ranges).
  std::vector<double> PriorScale(const ThermalLayout& layout,
                                 const std::vector<double>& theta) const {
    std::vector<double> scale(layout.size, 1.0);
    const double* u = theta.data() + layout.upper;
    const double u_diag[3] = {std::abs(u[0]), std::abs(u[3]), std::abs(u[5])};
    const double accel_unit = std::max({u_diag[0], u_diag[1], u_diag[2], 1e-300});
    const double gyro_unit = o_.gyro_nominal_scale;
    constexpr double kCharacteristicRange = 30.0;
    for (int j = 0; j < layout.size; ++j) {
      const ThermalLayout::Slot& s = layout.slots[j];
      if (j == layout.lag) {
        scale[j] = 100.0;
      } else if (!s.thermal) {
        if (j < layout.upper) {
          scale[j] = std::max(1.0 / accel_unit, 10.0 * accel_range_);
        } else if (j < layout.upper + 6) {
          const bool diagonal = s.component == 0 || s.component == 3 || s.component == 5;
          scale[j] = (diagonal ? 0.1 : 0.05) * accel_unit;
        } else {
          scale[j] = std::max(0.2 / gyro_unit, 10.0 * gyro_range_);
        }
      } else {
        // The linear term's range (physical, or twice the change the data
        // show over the half span when larger: raw units whose nominal
        // scale is unknown), each further power divided by a 30 degree
        // characteristic range.
        const double per_power = std::pow(kCharacteristicRange, s.power - 1);
        double linear = 1e-4;  // scale, misalignment: 1e-4 per degC
        if (s.quantity == ThermalQuantity::kBias) {
          const bool accel = s.sensor == ThermalSensor::kAccel;
          linear = std::max(accel ? 0.01 / accel_unit : 1e-3 / gyro_unit,
                            2.0 * (accel ? accel_range_ : gyro_range_) / half_span_);
        }
        scale[j] = linear / per_power;
      }
    }
    return scale;
  }

  // Modified Gram-Schmidt over the prior-scaled columns in priority order
  // (the header): true = undetermined.
  // The test is taken with U's off-diagonal at 0 (the axis-aligned U a
  // MEMS part is near): on the six faces |U d| depends on the
  // off-diagonal only to second order, so away from 0 the linearisation
  // lends it information the poses do not have, and a solve that slid
  // along that valley would confirm itself (seen on six faces plus one
  // tilted pose: U's columns turned by 70 degrees, the bias at 2000 m/s^2).
  std::vector<bool> Undetermined(const ThermalLayout& layout, std::vector<double> theta,
                                 const std::vector<double>& sigmas) const {
    for (int k : {1, 2, 4}) theta[layout.upper + k] = 0.0;
    Eigen::MatrixXd j = Jacobian(layout, sigmas, theta, nullptr);
    const std::vector<double> prior = PriorScale(layout, theta);
    for (int c = 0; c < layout.size; ++c) j.col(c) *= prior[c];
    // U's off-diagonal and the accelerometer misalignment terms enter |U d|
    // on the faces only to second order: the first-order "information" the
    // columns carry there comes from small perturbations of the design (the
    // thermal drift and the pose noise tilting a tilted pose's direction
    // lend each of the three off-diagonals information on what is one
    // combination of them; measured 0.2-0.4 % of their squared norm beyond
    // the columns kept before them), which the nonlinear problem does not
    // honour: a solve slides along the valley. Such a column is undetermined
    // when the columns kept before it explain all but kCollinear of it.
    // (Other terms are not held to this: x beside the constant on a
    // single warm-up keeps under 1 % and is rightly determined.)
    constexpr double kCollinear = 1e-2;
    std::vector<bool> valley(layout.size, false);
    for (int k : {1, 2, 4}) valley[layout.upper + k] = true;
    for (int c = 0; c < layout.size; ++c) {
      const ThermalLayout::Slot& s = layout.slots[c];
      valley[c] = valley[c] || (s.thermal && s.sensor == ThermalSensor::kAccel &&
                                s.quantity == ThermalQuantity::kMisalignment);
    }
    const Eigen::VectorXd original = j.colwise().squaredNorm().transpose();
    std::vector<bool> undetermined(layout.size, false), done(layout.size, false);
    std::vector<int> groups = layout.group;
    std::sort(groups.begin(), groups.end());
    groups.erase(std::unique(groups.begin(), groups.end()), groups.end());
    for (int g : groups) {
      while (true) {
        int best = -1;
        double best_norm = -1.0;
        for (int c = 0; c < layout.size; ++c) {
          if (done[c] || layout.group[c] != g) continue;
          const double n = j.col(c).squaredNorm();
          if (n > best_norm) {
            best_norm = n;
            best = c;
          }
        }
        if (best < 0) break;
        done[best] = true;
        if (!(best_norm >= o_.min_information) ||
            (valley[best] && !(best_norm >= kCollinear * original(best)))) {
          undetermined[best] = true;
          continue;
        }
        const Eigen::VectorXd q = j.col(best) / std::sqrt(best_norm);
        for (int c = 0; c < layout.size; ++c) {
          if (!done[c]) j.col(c) -= q * q.dot(j.col(c));
        }
      }
    }
    return undetermined;
  }

  bool Solve(const ThermalLayout& layout, const std::vector<double>& sigmas, Fit* fit) const {
    ceres::Problem problem;
    Build(layout, sigmas, fit->theta.data(), &problem);
    std::vector<int> held;
    for (int j = 0; j < layout.size; ++j) {
      if (fit->fixed[j]) held.push_back(j);
    }
    if (static_cast<int>(held.size()) == layout.size) {
      problem.SetParameterBlockConstant(fit->theta.data());
    } else if (!held.empty()) {
      problem.SetManifold(fit->theta.data(), new ceres::SubsetManifold(layout.size, held));
    }
    // The lag filter is stable for tau >= 0 only (a negative tau, an
    // element leading its own sensor, is not physical).
    if (layout.lag >= 0 && !fit->fixed[layout.lag]) {
      fit->theta[layout.lag] = std::max(0.0, fit->theta[layout.lag]);
      problem.SetParameterLowerBound(fit->theta.data(), layout.lag, 0.0);
    }
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = o_.max_iterations;
    so.num_threads = 1;
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    fit->residuals = static_cast<int>(problem.NumResiduals());
    fit->free = layout.size - static_cast<int>(held.size());
    fit->chi2 = 2.0 * summary.final_cost;
    fit->ok = summary.IsSolutionUsable() && std::isfinite(fit->chi2);
    for (double v : fit->theta) fit->ok = fit->ok && std::isfinite(v);
    fit->message = summary.BriefReport();
    return fit->ok;
  }

  void Covariance(const ThermalLayout& layout, const std::vector<double>& sigmas, Fit* fit) const {
    const Eigen::MatrixXd j = Jacobian(layout, sigmas, fit->theta, nullptr);
    std::vector<int> free;
    for (int c = 0; c < layout.size; ++c) {
      if (!fit->fixed[c]) free.push_back(c);
    }
    Eigen::MatrixXd jf(j.rows(), free.size());
    for (size_t c = 0; c < free.size(); ++c) jf.col(c) = j.col(free[c]);
    // Column scaling keeps the normal matrix well conditioned.
    Eigen::VectorXd d = jf.colwise().norm().transpose();
    for (int c = 0; c < d.size(); ++c) {
      if (!(d(c) > 0.0)) d(c) = 1.0;
      jf.col(c) /= d(c);
    }
    const Eigen::MatrixXd info = jf.transpose() * jf;
    Eigen::MatrixXd inv = info.ldlt().solve(Eigen::MatrixXd::Identity(info.rows(), info.cols()));
    const int dof = fit->residuals - fit->free;
    const double factor = dof > 0 ? std::max(1.0, fit->chi2 / dof) : 1.0;
    fit->covariance = Eigen::MatrixXd::Zero(layout.size, layout.size);
    for (size_t a = 0; a < free.size(); ++a) {
      for (size_t b = 0; b < free.size(); ++b) {
        fit->covariance(free[a], free[b]) = factor * inv(a, b) / (d(a) * d(b));
      }
    }
  }

  const std::vector<ThermalWindow>& windows_;
  const ThermalElementSeries& element_;
  const ThermalCalibrationOptions& o_;
  const bool has_gyro_;
  const double reference_;
  const double half_span_;
  double accel_range_ = 0.0;
  double start_accel_scale_ = 1.0;
  std::string scale_note_;
  double gyro_range_ = 0.0;
  int single_axis_ = -1;
  bool faces_only_ = false;
};

std::map<std::string, double> Named(const ThermalOrders& orders, bool has_gyro, const Fit& fit) {
  const ThermalLayout layout(orders, has_gyro);
  std::map<std::string, double> out;
  for (int j = 0; j < layout.size; ++j) out[layout.names[j]] = fit.theta[j];
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
void FillTerm(const ThermalLayout& layout, const Fit& fit, ThermalSensor sensor, ThermalQuantity q,
              int start, int order, int max_order, const std::string& selection,
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
  const std::vector<ThermalWindow> windows = ThermalWindows(log, detection.intervals, options);
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
      log, std::max(1.0, (log.t.back() - log.t.front()) / std::max<size_t>(1, log.size() - 1)));
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
  Fit best = fitter.Run(orders, {});
  if (!best.ok) return fail(log.source + ": the thermal fit failed (" + best.message + ")");
  double best_score = fitter.Score(best);
  ThermalFitReport rep;
  rep.scores.push_back(best_score);
  rep.steps.push_back("start");
  while (true) {
    ThermalOrders chosen = orders;
    Fit chosen_fit;
    double chosen_score = best_score;
    std::string chosen_name;
    auto consider = [&](const ThermalOrders& candidate, const std::string& name) {
      Fit f = fitter.Run(candidate, Named(orders, has_gyro, best));
      // A step whose new coefficients are all undetermined adds nothing.
      if (!f.ok || f.free <= best.free) return;
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
  if (has_gyro) {
    model.notes.push_back(
        "gyro scale and misalignment against temperature are not estimated (static windows see "
        "no rotation rate)");
  }
  if (model.lag_estimated) {
    std::ostringstream s;
    s.precision(3);
    s << "the heating and cooling branches disagree: the element lags the temperature sensor by "
      << model.lag_time_constant << " s (std " << model.lag_time_constant_std << " s)";
    model.notes.push_back(s.str());
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
