// The temperature section of the calibration report (thermal_report.h).
#include "workflows/report/thermal_report.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "gravcal/core/imu_corrector.h"
#include "gravcal/io/calibration_models.h"
#include "workflows/report/svg_plot.h"

namespace gravcal {
namespace internal {

namespace {

// Points of each curve over the range; most static samples drawn per plot.
constexpr int kCurvePoints = 121;
constexpr size_t kMostPoints = 3000;
// 95 % band.
constexpr double kBandSigmas = 1.96;

const char* BranchColor(ThermalBranch b) {
  switch (b) {
    case ThermalBranch::kHeating:
      return "#d62728";
    case ThermalBranch::kCooling:
      return "#1f77b4";
    case ThermalBranch::kSteady:
      break;
  }
  return "#2ca02c";
}

const char* BranchName(ThermalBranch b) {
  switch (b) {
    case ThermalBranch::kHeating:
      return "heating";
    case ThermalBranch::kCooling:
      return "cooling";
    case ThermalBranch::kSteady:
      break;
  }
  return "steady";
}

struct QuantityView {
  ThermalQuantity quantity;
  const char* title;
  const char* unit;
  double factor;  // value -> plotted unit
};

// The unit a term is drawn in: raw units for the bias, % for the scale,
// mrad for the misalignment.
QuantityView ViewOf(ThermalQuantity q) {
  switch (q) {
    case ThermalQuantity::kBias:
      return {q, "bias change from T_ref", "raw units", 1.0};
    case ThermalQuantity::kScale:
      return {q, "scale change from T_ref", "%", 100.0};
    case ThermalQuantity::kMisalignment:
      break;
  }
  return {q, "misalignment change from T_ref", "mrad", 1e3};
}

std::string TermPlot(const ThermalModel& m, ThermalSensor sensor, ThermalQuantity quantity,
                     double lo, double hi) {
  const ThermalPolynomial& p = m.Sensor(sensor).Term(quantity);
  const QuantityView view = ViewOf(quantity);
  const std::vector<std::string> names = ThermalComponentNames(sensor, quantity);
  Plot plot;
  plot.title = std::string(sensor == ThermalSensor::kAccel ? "Accelerometer" : "Gyroscope") + " " +
               view.title + " (order " + std::to_string(p.order) +
               (p.selection.empty() ? "" : ", " + p.selection) + "), 95 % band";
  plot.x.label = "temperature, degC";
  plot.x.lo = lo;
  plot.x.hi = hi;
  plot.y.label = std::string(view.title) + ", " + view.unit;
  plot.y.include_zero = true;
  plot.css_class =
      std::string("plot-thermal thermal-") + ToString(sensor) + "-" + ToString(quantity);
  for (size_t i = 0; i < names.size(); ++i) {
    Series band, line;
    band.style = SeriesStyle::kEnvelope;
    band.opacity = 0.2;
    band.css_class = "thermal-band";
    line.css_class = "thermal-curve";
    band.color = line.color = i < 3 ? kAxisColors[i] : PaletteColor(static_cast<int>(i));
    bool undetermined = false;
    for (int k = 1; k <= p.order; ++k) undetermined |= !p.Determined(static_cast<int>(i), k);
    line.name = names[i] + (undetermined ? " (undetermined terms read as 0)" : "");
    bool any_band = false;
    for (int g = 0; g < kCurvePoints; ++g) {
      const double t = lo + (hi - lo) * g / (kCurvePoints - 1);
      const double x =
          std::min(std::max(t, m.min_temperature), m.max_temperature) - m.reference_temperature;
      const double xv = std::isfinite(x) ? x : t - m.reference_temperature;
      const double v = view.factor * p.Value(static_cast<int>(i), xv);
      const double s = view.factor * kBandSigmas * p.Std(static_cast<int>(i), xv, false);
      line.x.push_back(t);
      line.y.push_back(v);
      if (std::isfinite(s)) {
        any_band = true;
        band.x.push_back(t);
        band.y.push_back(v);
        band.lo.push_back(v - s);
        band.hi.push_back(v + s);
      }
    }
    // A band of one point (only T_ref, where x = 0) is no band.
    if (any_band && band.x.size() > 1) plot.series.push_back(band);
    plot.series.push_back(line);
  }
  Rule ref;
  ref.value = m.reference_temperature;
  ref.vertical = true;
  ref.label = "T_ref";
  plot.rules.push_back(ref);
  return RenderPlot(plot);
}

// Static samples, thinned to about kMostPoints: the indices.
std::vector<size_t> StaticSamples(const Calibration& c, const ImuLog& log) {
  std::vector<size_t> all;
  for (const PositionReport& p : c.positions) {
    const auto begin = std::lower_bound(log.t.begin(), log.t.end(), p.position.t_begin);
    const auto end = std::upper_bound(log.t.begin(), log.t.end(), p.position.t_end);
    for (auto it = begin; it < end; ++it) all.push_back(static_cast<size_t>(it - log.t.begin()));
  }
  if (all.size() <= kMostPoints) return all;
  std::vector<size_t> thinned;
  const double step = static_cast<double>(all.size()) / kMostPoints;
  for (size_t k = 0; k < kMostPoints; ++k) thinned.push_back(all[static_cast<size_t>(k * step)]);
  return thinned;
}

// |a| - g (gyro = false) or |w| (true) at the static samples against the
// temperature, one series per branch with the thermal model and one grey
// without it.
std::string ResidualPlot(const Calibration& c, const ImuLog& log, const ImuCorrector& with,
                         bool gyro, const std::vector<size_t>& samples,
                         const std::vector<ThermalBranch>& branches,
                         const std::vector<double>& rates) {
  ImuCorrector without = with;
  without.thermal = ThermalModel();
  Series base;
  base.name = "without the thermal model";
  base.style = SeriesStyle::kPoints;
  base.color = "#7f7f7f";
  base.opacity = 0.35;
  base.css_class = "thermal-uncompensated";
  Series branch[3];
  const ThermalBranch kinds[3] = {ThermalBranch::kHeating, ThermalBranch::kCooling,
                                  ThermalBranch::kSteady};
  for (int b = 0; b < 3; ++b) {
    branch[b].name = std::string("compensated, ") + BranchName(kinds[b]);
    branch[b].style = SeriesStyle::kPoints;
    branch[b].color = BranchColor(kinds[b]);
    branch[b].css_class = std::string("thermal-residual branch-") + BranchName(kinds[b]);
  }
  auto value = [&](const ImuCorrector& k, size_t i, double* out) {
    Eigen::Vector3d a = log.accel[i];
    Eigen::Vector3d w = gyro ? log.gyro[i] : Eigen::Vector3d::Zero();
    if (!k.CorrectRow(log.temperature[i], rates[i], log.t[i], &a, gyro ? &w : nullptr, nullptr)) {
      return false;
    }
    *out = gyro ? w.norm() : a.norm() - c.gravity;
    return true;
  };
  for (size_t i : samples) {
    double v0, v1;
    if (!value(without, i, &v0) || !value(with, i, &v1)) continue;
    base.x.push_back(log.temperature[i]);
    base.y.push_back(v0);
    const int b = branches[i] == ThermalBranch::kHeating   ? 0
                  : branches[i] == ThermalBranch::kCooling ? 1
                                                           : 2;
    branch[b].x.push_back(log.temperature[i]);
    branch[b].y.push_back(v1);
  }
  Plot plot;
  plot.title = gyro ? "Gyroscope |w| at rest against temperature, after the correction"
                    : "|a| - g of every static sample against temperature, after the correction";
  plot.x.label = "temperature, degC";
  plot.y.label = gyro ? "|w| at rest, rad/s" : "|a| - g, m/s^2";
  plot.y.include_zero = true;
  plot.css_class = gyro ? "plot-thermal-residual-gyro" : "plot-thermal-residual";
  plot.series.push_back(base);
  for (const Series& s : branch) {
    if (!s.x.empty()) plot.series.push_back(s);
  }
  return RenderPlot(plot);
}

}  // namespace

std::vector<double> TemperatureRates(const ImuLog& log) {
  std::vector<double> rates(log.size(), NAN);
  if (!log.has_temperature()) return rates;
  const double half = 0.5 * kBranchWindowSeconds;
  size_t lo = 0, hi = 0;
  for (size_t k = 0; k < log.size(); ++k) {
    while (lo < k && log.t[lo] < log.t[k] - half) ++lo;
    while (hi + 1 < log.size() && log.t[hi + 1] <= log.t[k] + half) ++hi;
    if (hi < k) hi = k;
    const double dt = log.t[hi] - log.t[lo];
    if (dt > 0.0) rates[k] = (log.temperature[hi] - log.temperature[lo]) / dt;
  }
  return rates;
}

std::vector<ThermalBranch> ThermalBranches(const ImuLog& log) {
  const std::vector<double> rates = TemperatureRates(log);
  std::vector<ThermalBranch> out(log.size(), ThermalBranch::kSteady);
  const double threshold = kBranchSlopePerMinute / 60.0;
  for (size_t k = 0; k < rates.size(); ++k) {
    if (rates[k] > threshold) out[k] = ThermalBranch::kHeating;
    if (rates[k] < -threshold) out[k] = ThermalBranch::kCooling;
  }
  return out;
}

std::string ThermalReportSection(const Calibration& c, const ImuLog& log) {
  const ThermalModel& m = c.thermal;
  if (!m.active()) return "";
  std::ostringstream h;
  h << "<h2 id='thermal'>Temperature</h2><p>Thermal model about T_ref = "
    << FormatNumber(m.reference_temperature, "%.4g") << " degC, valid over ["
    << FormatNumber(m.min_temperature, "%.4g") << ", " << FormatNumber(m.max_temperature, "%.4g")
    << "] degC (the correction clamps outside it)";
  if (m.lag_time_constant != 0.0) {
    h << "; sensor lag tau = " << FormatNumber(m.lag_time_constant, "%.3g") << " s";
    if (std::isfinite(m.lag_time_constant_std)) {
      h << " &plusmn; " << FormatNumber(m.lag_time_constant_std, "%.2g");
    }
  }
  h << ".</p>\n";
  if (!m.notes.empty()) {
    h << "<ul class='thermal-notes'>";
    for (const std::string& n : m.notes) h << "<li>" << HtmlEscape(n) << "</li>";
    h << "</ul>\n";
  }
  double lo = m.min_temperature, hi = m.max_temperature;
  if (!(hi > lo) && log.has_temperature()) {
    const auto mm = std::minmax_element(log.temperature.begin(), log.temperature.end());
    lo = *mm.first;
    hi = *mm.second;
  }
  if (!(hi > lo)) {
    lo = m.reference_temperature - 1.0;
    hi = m.reference_temperature + 1.0;
  }
  for (ThermalSensor s : {ThermalSensor::kAccel, ThermalSensor::kGyro}) {
    for (ThermalQuantity q :
         {ThermalQuantity::kBias, ThermalQuantity::kScale, ThermalQuantity::kMisalignment}) {
      if (m.Sensor(s).Term(q).active()) h << TermPlot(m, s, q, lo, hi);
    }
  }
  h << "<p class='note'>Each curve is the term's change from its value at T_ref; the band is "
       "1.96 sigma of that change from the coefficients' covariance (none where a coefficient "
       "is undetermined).</p>\n";
  LoadedCalibration loaded;
  std::string error;
  if (!log.has_temperature() || c.positions.empty() ||
      !ModelsFromCalibration(c, "the calibration", &loaded, &error)) {
    return h.str();
  }
  const std::vector<size_t> samples = StaticSamples(c, log);
  const std::vector<ThermalBranch> branches = ThermalBranches(log);
  const std::vector<double> rates = TemperatureRates(log);
  h << "<h3>Residual after compensation</h3>"
    << ResidualPlot(c, log, loaded.corrector, false, samples, branches, rates);
  if (log.has_gyro() && loaded.corrector.has_gyro) {
    h << ResidualPlot(c, log, loaded.corrector, true, samples, branches, rates);
  }
  h << "<p class='note'>Static samples (at most " << kMostPoints
    << " drawn), coloured by what the temperature was doing: heating (red) or cooling (blue) "
       "faster than "
    << kBranchSlopePerMinute << " degC/min over " << kBranchWindowSeconds
    << " s, else steady (green). Grey: the same samples without the thermal model. Heating and "
       "cooling apart from each other at one temperature is hysteresis or sensor lag.</p>\n";
  return h.str();
}

}  // namespace internal
}  // namespace gravcal
