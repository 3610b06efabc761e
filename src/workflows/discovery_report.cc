#include "gravcal/workflows/discovery_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/json_helpers.h"
#include "util/statistics.h"
#include "workflows/report/svg_plot.h"

namespace gravcal {

using internal::Median;

namespace {

using OrderedJson = nlohmann::ordered_json;

OrderedJson Number(double v) { return internal::JsonNumber<OrderedJson>(v); }
OrderedJson Vector(const Eigen::Vector3d& v) { return internal::JsonVector<OrderedJson>(v); }
OrderedJson Matrix(const Eigen::Matrix3d& m) { return internal::JsonMatrix<OrderedJson>(m); }

bool IsAccel(Effect e) { return Info(e).sensor == EffectSensor::kAccelerometer; }

const char* SensorName(EffectSensor s) {
  return s == EffectSensor::kAccelerometer ? "accelerometer" : "gyroscope";
}

const char* GapUnit(Effect e) { return IsAccel(e) ? "m/s^2" : "raw gyro units"; }

double Of(const Gap& g, bool accel) { return accel ? g.accel : g.gyro; }
double SigmaOf(const Gap& g, bool accel) { return accel ? g.accel_sigma : g.gyro_sigma; }

OrderedJson GapJson(const Gap& g) {
  return {{"accel", Number(g.accel)},
          {"accel_unit", "m/s^2"},
          {"accel_sigma", Number(g.accel_sigma)},
          {"gyro", Number(g.gyro)},
          {"gyro_unit", "raw gyro units"},
          {"gyro_sigma", Number(g.gyro_sigma)},
          {"accel_unpredictable_positions", g.accel_unpredictable},
          {"gyro_unpredictable_positions", g.gyro_unpredictable}};
}

std::string ModelName(const ModelAssessment& m) {
  std::string name = ToString(m.parameterization);
  for (Effect e : m.effects) name += std::string(" + ") + ToString(e);
  return name;
}

OrderedJson PositionJson(const PositionDisagreement& p) {
  return {{"position", p.index},
          {"time", p.time},
          {"temperature", Number(p.temperature)},
          {"axis", p.axis},
          {"axis_level", p.axis_level},
          {"accel_residual", p.accel_residual},
          {"accel_z", p.accel_z},
          {"gyro_residual", Vector(p.gyro_residual)},
          {"gyro_z", Vector(p.gyro_z)}};
}

// `where`: the summary, the worst positions of each sensor and the groups;
// with every position (measured, simulated) when `detail`.
OrderedJson WhereJson(const Disagreement& d, bool detail) {
  OrderedJson w;
  w["summary"] = d.summary;
  OrderedJson worst_a = OrderedJson::array(), worst_g = OrderedJson::array();
  for (int k : d.worst_accel) worst_a.push_back(PositionJson(d.positions[k]));
  for (int k : d.worst_gyro) worst_g.push_back(PositionJson(d.positions[k]));
  w["accel"] = {{"chi2", d.accel_chi2},
                {"dof", d.accel_dof},
                {"p_value", d.accel_p},
                {"worst_positions", worst_a}};
  if (d.gyro_dof > 0) {
    w["gyro"] = {{"chi2", d.gyro_chi2},
                 {"dof", d.gyro_dof},
                 {"p_value", d.gyro_p},
                 {"worst_positions", worst_g}};
  }
  OrderedJson groups = OrderedJson::array();
  for (const GroupDisagreement& g : d.groups) {
    groups.push_back({{"by", g.by},
                      {"group", g.group},
                      {"positions", g.count},
                      {"accel_sigma", Number(g.accel_sigma)},
                      {"gyro_sigma", Number(g.gyro_sigma)}});
  }
  w["groups"] = groups;
  if (detail) {
    OrderedJson all = OrderedJson::array();
    for (const PositionDisagreement& p : d.positions) {
      OrderedJson j = PositionJson(p);
      j["accel_measured"] = Vector(p.accel_measured);
      j["accel_simulated"] = Vector(p.accel_simulated);
      if (d.gyro_dof > 0) {
        j["gyro_measured"] = Vector(p.gyro_measured);
        j["gyro_simulated"] = Vector(p.gyro_simulated);
      }
      all.push_back(j);
    }
    w["positions"] = all;
  }
  return w;
}

OrderedJson ParametersJson(const EffectEstimate& e) {
  OrderedJson params = OrderedJson::array();
  for (size_t i = 0; i < e.names.size(); ++i) {
    params.push_back({{"name", e.names[i]},
                      {"value", Number(i < e.values.size() ? e.values[i] : NAN)},
                      {"std", Number(i < e.std.size() ? e.std[i] : NAN)},
                      {"unit", e.unit}});
  }
  return params;
}

OrderedJson CandidatesJson(const std::vector<CandidateScore>& scores) {
  OrderedJson out = OrderedJson::array();
  for (const CandidateScore& c : scores) {
    const bool accel = IsAccel(c.effect);
    OrderedJson j = {
        {"effect", ToString(c.effect)}, {"tried", c.tried}, {"significant", c.significant}};
    if (c.tried) {
      j["information"] = c.information;
      j["dof"] = c.dof;
      j["delta_chi2"] = Number(c.delta_chi2);
      j["dispersion"] = Number(c.dispersion);
      j["p_value"] = Number(c.p_value);
      j["delta_bic"] = Number(c.delta_bic);
      j["gap_after"] = Number(Of(c.gap, accel));
      j["cv_gap_after"] = Number(Of(c.cv_gap, accel));
      j["cv_gap_after_sigma"] = Number(SigmaOf(c.cv_gap, accel));
      if (accel) {
        j["magnitude_dof"] = c.magnitude_dof;
        j["trend_delta_chi2"] = Number(c.trend_delta_chi2);
        j["rotation_delta_chi2"] = Number(c.rotation_delta_chi2);
        j["confirmation_p_value"] = Number(c.confirmation_p_value);
        j["preference_margin"] = Number(c.preference_margin);
        j["runner_up"] =
            std::isfinite(c.preference_margin) ? OrderedJson(ToString(c.runner_up)) : OrderedJson();
        j["preference_threshold"] = Number(c.preference_threshold);
        j["confirmed_by"] = c.confirmed_by;
      }
    }
    if (!c.reason.empty()) j["reason"] = c.reason;
    out.push_back(j);
  }
  return out;
}

OrderedJson ModelJson(const ModelAssessment& m) {
  OrderedJson j;
  j["model"] = ModelName(m);
  j["parameterization"] = ToString(m.parameterization);
  j["effects"] = EffectNames(m.effects);
  j["gap"] = GapJson(m.gap);
  j["cv_gap"] = GapJson(m.cv_gap);
  const EffectFitResult& f = m.fit;
  j["accel"] = {{"bias", Vector(f.accel.bias)},
                {"bias_std", Vector(f.accel_bias_std)},
                {"upper", Matrix(f.accel.upper)},
                {"chi2", f.accel_fit.chi2},
                {"dof", f.accel_fit.dof()}};
  j["accel"]["information"] = f.accel_fit.information;
  if (f.gyro_fit.fitted) {
    j["gyro"] = {{"bias", Vector(f.gyro.bias)},
                 {"bias_std", Vector(f.gyro_bias_std)},
                 {"chi2", f.gyro_fit.chi2},
                 {"dof", f.gyro_fit.dof()},
                 {"information", f.gyro_fit.information}};
  }
  OrderedJson params = OrderedJson::object();
  for (const EffectEstimate& e : f.estimates) params[ToString(e.effect)] = ParametersJson(e);
  j["parameters"] = params;
  j["reference_temperature"] = Number(f.parameters.reference_temperature);
  j["reference_time"] = Number(f.parameters.reference_time);
  return j;
}

// ---------------------------------------------------------------------------
// HTML, drawn with the report plotting module (workflows/report/svg_plot.h).

using internal::HtmlEscape;
using internal::Series;
using internal::SeriesStyle;

using internal::FormatNumber;

std::string Scatter(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                    const std::vector<Series>& series) {
  internal::Plot p;
  p.title = title;
  p.x.label = xlabel;
  p.y.label = ylabel;
  p.y.include_zero = true;
  p.width = 580;
  p.height = 320;
  p.series = series;
  internal::Rule zero;
  zero.value = 0.0;
  zero.color = "#bbb";
  p.rules.push_back(zero);
  return internal::RenderPlot(p);
}

// Bars of a value per position, with dashed lines at +-1 and +-3.
std::string Bars(const std::string& title, const std::string& ylabel,
                 const std::vector<double>& values, const std::string& color) {
  internal::Plot p;
  p.title = title;
  p.x = {"position", internal::AxisScale::kLinear, -0.6, values.size() - 0.4, false, true};
  p.y.label = ylabel;
  p.width = 580;
  p.height = 320;
  for (double level : {-3.0, -1.0, 1.0, 3.0}) {
    internal::Rule r;
    r.value = level;
    r.color = std::fabs(level) > 2 ? "#d33" : "#bbb";
    if (std::fabs(level) > 2) r.label = level > 0 ? "+3 sigma" : "-3 sigma";
    p.rules.push_back(r);
  }
  Series bars;
  bars.style = SeriesStyle::kBars;
  bars.color = color;
  bars.bar_width = 0.7;
  for (size_t k = 0; k < values.size(); ++k) {
    bars.x.push_back(static_cast<double>(k));
    bars.y.push_back(values[k]);
  }
  p.series.push_back(bars);
  return internal::RenderPlot(p);
}

// "accelerometer: <information>; gyroscope: <information>" of a fit.
std::string BaselineInformation(const EffectFitResult& f) {
  std::string out;
  if (f.accel_fit.fitted) out = "accelerometer: " + f.accel_fit.information;
  if (f.gyro_fit.fitted) {
    out += (out.empty() ? "" : "; ") + ("gyroscope: " + f.gyro_fit.information);
  }
  return out;
}

std::string GapCells(const Gap& before, const Gap& after, bool accel) {
  std::ostringstream s;
  s << "<td>" << FormatNumber(Of(before, accel)) << " &rarr; " << FormatNumber(Of(after, accel))
    << "</td><td>" << FormatNumber(SigmaOf(before, accel), "%.3g") << " &rarr; "
    << FormatNumber(SigmaOf(after, accel), "%.3g") << "</td>";
  return s.str();
}

std::string WherePlots(const Disagreement& d, const std::string& label) {
  std::vector<double> za, zg;
  for (const PositionDisagreement& p : d.positions) {
    za.push_back(p.accel_z);
    zg.push_back(p.gyro_z.norm() / std::sqrt(3.0));
  }
  std::string s = Bars(label + ": accelerometer |a| - g per position", "sigma", za, "#3b6ea8");
  if (d.gyro_dof > 0) {
    s += Bars(label + ": gyroscope residual per position (rms over axes)", "sigma", zg, "#c07a2c");
  }
  return s;
}

std::string GroupsTable(const Disagreement& d) {
  std::ostringstream s;
  s << "<table><tr><th>by</th><th>group</th><th>positions</th><th>accel rms, sigma</th>"
    << "<th>gyro rms, sigma</th></tr>";
  for (const GroupDisagreement& g : d.groups) {
    s << "<tr><td>" << g.by << "</td><td>" << HtmlEscape(g.group) << "</td><td>" << g.count
      << "</td><td>" << FormatNumber(g.accel_sigma, "%.3g") << "</td><td>"
      << FormatNumber(g.gyro_sigma, "%.3g") << "</td></tr>";
  }
  s << "</table>";
  return s.str();
}

std::string CandidatesTable(const std::vector<CandidateScore>& scores) {
  std::ostringstream s;
  s << "<table><tr><th>candidate</th><th>information used</th><th>p-value</th><th>delta "
       "BIC</th><th>CV gap after, sigma</th><th>verdict</th></tr>";
  for (const CandidateScore& c : scores) {
    const bool accel = IsAccel(c.effect);
    s << "<tr><td>" << ToString(c.effect) << "</td><td>" << HtmlEscape(c.information) << "</td><td>"
      << FormatNumber(c.p_value, "%.3g") << "</td><td>" << FormatNumber(c.delta_bic, "%.1f")
      << "</td><td>" << FormatNumber(SigmaOf(c.cv_gap, accel), "%.3g") << "</td><td>"
      << (c.significant ? "significant" : HtmlEscape(c.reason)) << "</td></tr>";
  }
  s << "</table>";
  return s.str();
}

// Residuals before and after a step against its regressor (or against the
// effect's own contribution), one pair of series per axis.
std::vector<Series> BeforeAfter(const DiscoveryStep& s, bool accel, bool against_contribution) {
  std::vector<Series> series;
  const char* colors_before[3] = {"#9bb7d6", "#d6b79b", "#a8d69b"};
  const char* colors_after[3] = {"#1f4e8c", "#8c4e1f", "#2f7a1f"};
  for (int axis = 0; axis < (accel ? 1 : 3); ++axis) {
    Series b, a;
    const std::string suffix = accel ? "" : std::string(" ") + "xyz"[axis];
    b.name = "before" + suffix;
    a.name = "after" + suffix;
    b.color = colors_before[axis];
    a.color = colors_after[axis];
    b.style = a.style = SeriesStyle::kPoints;
    b.opacity = a.opacity = 0.8;
    for (size_t k = 0; k < s.regressor.size(); ++k) {
      const double x = against_contribution ? s.contribution[k](axis) : s.regressor[k];
      b.x.push_back(x);
      a.x.push_back(x);
      b.y.push_back(s.residual_before[k](axis));
      a.y.push_back(s.residual_after[k](axis));
    }
    series.push_back(b);
    series.push_back(a);
  }
  return series;
}

}  // namespace

std::string DiscoveryToJson(const DiscoveryResult& r) {
  OrderedJson out;
  out["source"] = r.source;
  out["gravity"] = {{"value", r.gravity}, {"source", r.gravity_source}};
  std::vector<double> sa, sg;
  OrderedJson positions = OrderedJson::array();
  for (size_t k = 0; k < r.observations.size(); ++k) {
    const StaticObservation& o = r.observations[k];
    positions.push_back({{"position", k},
                         {"t_begin", o.accel.t_begin},
                         {"t_end", o.accel.t_end},
                         {"samples", o.accel.sample_count},
                         {"temperature", Number(o.temperature())}});
    if (k < r.baseline.fit.accel_sigmas.size()) sa.push_back(r.baseline.fit.accel_sigmas[k]);
    if (k < r.baseline.fit.gyro_sigmas.size()) sg.push_back(r.baseline.fit.gyro_sigmas[k].mean());
  }
  out["positions"] = positions;
  out["noise"] = {{"accel_sigma_median", Number(sa.empty() ? NAN : Median(sa))},
                  {"accel_unit", "m/s^2 (|a| of a position mean)"},
                  {"gyro_sigma_median", Number(sg.empty() ? NAN : Median(sg))},
                  {"gyro_unit", "raw gyro units (one axis of a position mean)"}};
  OrderedJson baseline = ModelJson(r.baseline);
  baseline["disagreement"] = WhereJson(r.baseline_where, true);
  out["baseline"] = baseline;
  OrderedJson steps = OrderedJson::array();
  for (const DiscoveryStep& s : r.steps) {
    const bool accel = IsAccel(s.effect);
    OrderedJson j = {{"effect", ToString(s.effect)},
                     {"description", Info(s.effect).description},
                     {"sensor", accel ? "accelerometer" : "gyroscope"},
                     {"information", s.information},
                     {"confirmed_by", s.confirmed_by},
                     {"parameters", ParametersJson(s.estimate)},
                     {"p_value", Number(s.p_value)},
                     {"delta_bic", Number(s.delta_bic)},
                     {"dof", s.dof},
                     {"gap_unit", GapUnit(s.effect)},
                     {"gap_before", Number(Of(s.gap_before, accel))},
                     {"gap_after", Number(Of(s.gap_after, accel))},
                     {"cv_gap_before", Number(Of(s.cv_gap_before, accel))},
                     {"cv_gap_after", Number(Of(s.cv_gap_after, accel))},
                     {"gap_before_sigma", Number(SigmaOf(s.gap_before, accel))},
                     {"gap_after_sigma", Number(SigmaOf(s.gap_after, accel))},
                     {"cv_gap_before_sigma", Number(SigmaOf(s.cv_gap_before, accel))},
                     {"cv_gap_after_sigma", Number(SigmaOf(s.cv_gap_after, accel))},
                     {"where", WhereJson(s.where, false)},
                     {"ambiguous_with", EffectNames(s.ambiguous_with)},
                     {"candidates", CandidatesJson(s.candidates)}};
    steps.push_back(j);
  }
  out["steps"] = steps;
  OrderedJson ambiguous = OrderedJson::array();
  for (const Ambiguity& a : r.ambiguous) {
    ambiguous.push_back({{"effects", EffectNames(a.effects)},
                         {"delta_bic", a.delta_bic},
                         {"step", a.step},
                         {"advice", a.advice}});
  }
  out["ambiguous"] = ambiguous;
  OrderedJson final_model = ModelJson(r.final_model);
  final_model["disagreement"] = WhereJson(r.final_where, true);
  if (!r.final_candidates.empty()) final_model["candidates"] = CandidatesJson(r.final_candidates);
  out["final_model"] = final_model;
  out["verdict"] = r.verdict;
  OrderedJson sensors = OrderedJson::array();
  for (const SensorVerdict& v : r.sensors) {
    sensors.push_back({{"sensor", SensorName(v.sensor)},
                       {"information", v.information},
                       {"named", EffectNames(v.named)},
                       {"excess", Number(v.excess)},
                       {"p_value", Number(v.p_value)},
                       {"unexplained", v.unexplained},
                       {"verdict", v.verdict}});
  }
  out["sensors"] = sensors;
  // Issue 35: temperature beyond the catalogue (thermal_discovery.h).
  if (r.thermal.tried || !r.thermal.reason.empty()) {
    const ThermalDiscovery& t = r.thermal;
    out["thermal"] = {{"tried", t.tried},
                      {"reason", t.reason},
                      {"span_degC", Number(t.span)},
                      {"accel_bias_order", t.accel_bias_order},
                      {"accel_scale_order", t.accel_scale_order},
                      {"gyro_bias_order", t.gyro_bias_order},
                      {"lag", t.lag},
                      {"lag_time_constant_s", Number(t.lag_time_constant)},
                      {"lag_time_constant_std_s", Number(t.lag_time_constant_std)},
                      {"named", t.named},
                      {"findings", t.findings},
                      {"steps", t.steps}};
  }
  out["warnings"] = r.warnings;
  OrderedJson codes = OrderedJson::array();
  for (size_t i = 0; i < r.warnings.size(); ++i) {
    codes.push_back(
        ToString(i < r.warning_codes.size() ? r.warning_codes[i] : WarningCode::kUnclassified));
  }
  out["warning_codes"] = codes;
  out["message"] = r.message;
  out["time_s"] = r.seconds;
  return out.dump(2, ' ', false, OrderedJson::error_handler_t::replace) + "\n";
}

std::string DiscoveryToHtml(const DiscoveryResult& r) {
  std::ostringstream h;
  h << internal::HtmlPageStart("gravcal discovery: " + r.source);
  h << "<h1>Model discrepancy report</h1><p>" << HtmlEscape(r.source) << " &mdash; "
    << r.observations.size() << " static positions, gravity " << FormatNumber(r.gravity, "%.6g")
    << " m/s^2 (" << HtmlEscape(r.gravity_source) << "), " << FormatNumber(r.seconds * 1e3, "%.1f")
    << " ms</p>\n";
  h << "<p class='verdict'><b>Verdict:</b> " << HtmlEscape(r.verdict) << "</p>\n";

  h << "<h2>How to read this</h2><p>Each static position's measured reading is compared with the "
       "reading the fitted model predicts (accelerometer: |a| - g; gyroscope: the mean rate at "
       "rest). Residuals are in units of the noise that position's own samples show "
       "(sigma): within +-1 is noise, beyond +-3 (red lines) the model misses something. The "
       "gap is the rms residual; the cross-validated (CV) gap predicts each position from a fit "
       "without it, so an effect that only fits noise does not lower it. An effect is named "
       "when its likelihood-ratio p-value is below the step's level, its delta BIC is negative "
       "and it lowers the CV gap.</p>\n";

  h << "<h2>Per sensor</h2><p>Each sensor is judged on its own evidence: its fits, tests, BIC "
       "and cross-validation use only its own residuals and noise, so one sensor's "
       "unexplained excess does not hide an effect of the other.</p>"
    << "<table><tr><th>sensor</th><th>information used</th><th>named</th><th>final residual / "
       "noise</th><th>verdict</th></tr>";
  for (const SensorVerdict& v : r.sensors) {
    std::string named;
    for (Effect e : v.named) named += (named.empty() ? "" : ", ") + std::string(ToString(e));
    h << "<tr><td>" << SensorName(v.sensor) << "</td><td>" << HtmlEscape(v.information)
      << "</td><td>" << (named.empty() ? "none" : named) << "</td><td>"
      << FormatNumber(v.excess, "%.3g") << " x</td><td" << (v.unexplained ? " class='warn'" : "")
      << ">" << HtmlEscape(v.verdict) << "</td></tr>";
  }
  h << "</table>\n";

  h << "<h2>Models</h2><table><tr><th>step</th><th>model</th><th>effect</th><th>information "
       "used</th><th>p-value</th>"
    << "<th>delta BIC</th><th>gap</th><th>gap, sigma</th><th>CV gap</th><th>CV gap, sigma</th>"
    << "</tr>";
  h << "<tr><td>baseline</td><td>" << HtmlEscape(ModelName(r.baseline)) << "</td><td></td><td>"
    << HtmlEscape(BaselineInformation(r.baseline.fit)) << "</td><td></td>"
    << "<td></td><td>accel " << FormatNumber(r.baseline.gap.accel) << " m/s^2; gyro "
    << FormatNumber(r.baseline.gap.gyro) << "</td><td>"
    << FormatNumber(r.baseline.gap.accel_sigma, "%.3g") << "; "
    << FormatNumber(r.baseline.gap.gyro_sigma, "%.3g") << "</td><td>"
    << FormatNumber(r.baseline.cv_gap.accel) << "; " << FormatNumber(r.baseline.cv_gap.gyro)
    << "</td><td>" << FormatNumber(r.baseline.cv_gap.accel_sigma, "%.3g") << "; "
    << FormatNumber(r.baseline.cv_gap.gyro_sigma, "%.3g") << "</td></tr>";
  for (size_t i = 0; i < r.steps.size(); ++i) {
    const DiscoveryStep& s = r.steps[i];
    const bool accel = IsAccel(s.effect);
    h << "<tr><td>" << i + 1 << "</td><td>+ " << ToString(s.effect) << "</td><td>"
      << HtmlEscape(Info(s.effect).description) << "</td><td>" << HtmlEscape(s.information)
      << (s.confirmed_by.empty() ? "" : "; confirmed by the " + HtmlEscape(s.confirmed_by))
      << "</td><td>" << FormatNumber(s.p_value, "%.3g") << "</td><td>"
      << FormatNumber(s.delta_bic, "%.1f") << "</td>" << GapCells(s.gap_before, s.gap_after, accel)
      << GapCells(s.cv_gap_before, s.cv_gap_after, accel) << "</tr>";
  }
  h << "</table><p>Gaps of a step are for the sensor of its effect ("
    << "m/s^2 or raw gyro "
    << "units).</p>\n";

  if (!r.ambiguous.empty()) {
    h << "<h2>Cannot be told apart in this session</h2><ul>";
    for (const Ambiguity& a : r.ambiguous) {
      h << "<li>step " << a.step + 1 << ": ";
      for (size_t i = 0; i < a.effects.size(); ++i) {
        h << (i ? " vs " : "") << "<b>" << ToString(a.effects[i]) << "</b> (delta BIC "
          << FormatNumber(a.delta_bic[i], "%.1f") << ")";
      }
      h << ". " << HtmlEscape(a.advice) << "</li>";
    }
    h << "</ul>\n";
  }

  h << "<h2>Baseline: where the model disagrees</h2><p>" << HtmlEscape(r.baseline_where.summary)
    << "</p>" << WherePlots(r.baseline_where, "baseline") << GroupsTable(r.baseline_where) << "\n";

  for (size_t i = 0; i < r.steps.size(); ++i) {
    const DiscoveryStep& s = r.steps[i];
    const bool accel = IsAccel(s.effect);
    h << "<h2>Step " << i + 1 << ": " << ToString(s.effect) << "</h2><p>"
      << HtmlEscape(Info(s.effect).description) << ". Decided from the "
      << HtmlEscape(SensorName(Info(s.effect).sensor)) << "'s " << HtmlEscape(s.information)
      << ". Where the model before this step disagreed: " << HtmlEscape(s.where.summary) << "</p>";
    h << "<table><tr><th>parameter</th><th>value</th><th>std</th><th>unit</th></tr>";
    for (size_t k = 0; k < s.estimate.names.size(); ++k) {
      h << "<tr><td>" << s.estimate.names[k] << "</td><td>"
        << FormatNumber(s.estimate.values[k], "%.4g") << "</td><td>"
        << FormatNumber(s.estimate.std[k], "%.2g") << "</td><td>" << HtmlEscape(s.estimate.unit)
        << "</td></tr>";
    }
    h << "</table>";
    const std::string y = accel ? "|a| - g, m/s^2" : "gyro residual, raw units";
    h << Scatter("residual against " + s.regressor_name, s.regressor_name, y,
                 BeforeAfter(s, accel, false));
    if (Info(s.effect).regressor != EffectRegressor::kOrientation) {
      h << Scatter("residual against the fitted effect", "fitted effect contribution", y,
                   BeforeAfter(s, accel, true));
    }
    h << "<h3>Candidates tried</h3>" << CandidatesTable(s.candidates) << "\n";
  }

  h << "<h2>Final model: " << HtmlEscape(ModelName(r.final_model)) << "</h2><p>"
    << HtmlEscape(r.final_where.summary) << "</p>" << WherePlots(r.final_where, "final")
    << GroupsTable(r.final_where);
  if (!r.final_candidates.empty()) {
    h << "<h3>Candidates of the last round (none significant)</h3>"
      << CandidatesTable(r.final_candidates);
  }
  if (!r.warnings.empty()) {
    h << "<h2>Warnings</h2><ul>";
    for (size_t i = 0; i < r.warnings.size(); ++i) {
      const WarningCode code =
          i < r.warning_codes.size() ? r.warning_codes[i] : WarningCode::kUnclassified;
      h << "<li class='warn'><code>" << ToString(code) << "</code> " << HtmlEscape(r.warnings[i])
        << "</li>";
    }
    h << "</ul>";
  }
  h << internal::HtmlPageEnd();
  return h.str();
}

}  // namespace gravcal
