// The calibration report (report.h, CalibrationToHtml).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/conditional_sigmas.h"
#include "gravcal/workflows/report.h"
#include "util/join.h"
#include "util/statistics.h"
#include "workflows/report/calibration_verdict.h"
#include "workflows/report/svg_plot.h"
#include "workflows/report/thermal_report.h"
#include "workflows/report/warning_advice.h"

namespace gravcal {
namespace {

using internal::FormatNumber;
using internal::HtmlEscape;
using internal::Plot;
using internal::Rule;
using internal::Series;
using internal::SeriesStyle;
using internal::Span;

constexpr const char* kXyz = "xyz";

using internal::AfterSigma;
using internal::Judge;
using internal::OutlierThreshold;
using internal::Verdict;
using Level = internal::VerdictLevel;

// The interval shading of the raw-signal plots.
std::vector<Span> PoseSpans(const Calibration& c) {
  std::vector<Span> spans;
  for (size_t k = 0; k < c.positions.size(); ++k) {
    const Position& p = c.positions[k].position;
    Span s;
    s.x0 = p.t_begin;
    s.x1 = p.t_end;
    s.label = std::to_string(k + 1);
    s.css_class = "static-interval";
    std::ostringstream t;
    t << "pose " << k + 1 << ": " << FormatNumber(p.t_begin, "%.1f") << " to "
      << FormatNumber(p.t_end, "%.1f") << " s, " << p.sample_count << " samples, up "
      << NominalAxisName(c.positions[k].nominal_up);
    s.title = t.str();
    s.legend = "static interval used (numbered)";
    spans.push_back(s);
  }
  return spans;
}

// "too short" for RejectionReason::kTooShort ("too_short").
std::string ReasonWords(RejectionReason reason) {
  std::string words = ToString(reason);
  std::replace(words.begin(), words.end(), '_', ' ');
  return words;
}

// The shading of the stretches the detector rejected, the reason in the
// legend and the numbers behind it in the tooltip.
std::vector<Span> RejectedSpans(const StaticDetection& detection) {
  std::vector<Span> spans;
  for (const RejectedStretch& r : detection.rejected) {
    Span s;
    s.x0 = r.t_begin;
    s.x1 = r.t_end;
    s.color = r.reason == RejectionReason::kTooShort ? "#ff7f0e" : "#d62728";
    s.css_class = "rejected-stretch";
    s.legend = "rejected: " + ReasonWords(r.reason);
    s.title = "rejected, " + ReasonWords(r.reason) + ": " + r.detail;
    spans.push_back(s);
  }
  return spans;
}

std::string RawPlot(const ImuLog& log, const std::vector<Eigen::Vector3d>& v, const char* what,
                    const std::vector<Span>& spans, const std::string& css) {
  Plot p;
  p.title = std::string(what) + " against time; shaded and numbered: the static intervals used";
  for (const Span& s : spans) {
    if (s.css_class == "rejected-stretch") {
      p.title = std::string(what) +
                " against time: the static intervals used (numbered) and the stretches rejected";
      break;
    }
  }
  p.x.label = "time, s";
  // The time axis spans the log exactly (ticks inside it).
  if (!log.t.empty()) {
    p.x.lo = log.t.front();
    p.x.hi = log.t.back();
  }
  p.y.label = std::string(what) + ", raw units";
  p.width = 1120;
  p.height = 330;
  p.css_class = css;
  p.spans = spans;
  for (int a = 0; a < 3; ++a) {
    std::vector<double> y(v.size());
    for (size_t i = 0; i < v.size(); ++i) y[i] = v[i](a);
    Series s = internal::MinMaxEnvelope(log.t, y, 700);
    s.name = std::string(1, kXyz[a]);
    s.color = internal::kAxisColors[a];
    s.opacity = s.style == SeriesStyle::kEnvelope ? 0.55 : 1.0;
    p.series.push_back(s);
  }
  return internal::RenderPlot(p);
}

std::string ResidualPlots(const Calibration& c) {
  const size_t n = c.positions.size();
  Series nominal, coarse, refined;
  nominal.style = SeriesStyle::kBars;
  nominal.color = "#7f7f7f";
  coarse.style = refined.style = SeriesStyle::kPoints;
  coarse.name = "after the coarse fit";
  coarse.color = "#ff7f0e";
  refined.name = "after refinement";
  refined.color = "#1f77b4";
  refined.css_class = "pose-residual";
  bool have_nominal = false;
  for (size_t k = 0; k < n; ++k) {
    const PositionReport& p = c.positions[k];
    const double x = static_cast<double>(k + 1);
    nominal.x.push_back(x);
    nominal.y.push_back(p.residual_nominal);
    have_nominal |= std::isfinite(p.residual_nominal);
    coarse.x.push_back(x);
    coarse.y.push_back(p.sigma > 0 ? p.residual_coarse / p.sigma : NAN);
    refined.x.push_back(x);
    refined.y.push_back(AfterSigma(p));
    refined.titles.push_back("pose " + std::to_string(k + 1) + ": " +
                             FormatNumber(refined.y.back(), "%.2f") + " sigma (" +
                             FormatNumber(p.residual_after, "%.3g") + " m/s^2)");
  }
  std::string out;
  if (have_nominal) {
    Plot p;
    p.title = "|a| - g per pose, nominal scale";
    p.x = {"pose", internal::AxisScale::kLinear, 0.4, n + 0.6, false, true};
    p.y.label = "|a| - g, m/s^2";
    p.y.include_zero = true;
    p.width = 370;
    p.series.push_back(nominal);
    out += internal::RenderPlot(p);
  }
  // Coarse and refined residuals apart: the coarse ones can be a hundred
  // times the refined ones, which would flatten the +-3 sigma band.
  for (const Series* s : {&coarse, &refined}) {
    bool any = false;
    for (double y : s->y) any |= std::isfinite(y);
    if (!any) continue;
    Plot p;
    p.title = "|a| - g / sigma, " + s->name;
    p.x = {"pose", internal::AxisScale::kLinear, 0.4, n + 0.6, false, true};
    p.y.label = "|a| - g / sigma of the pose";
    p.y.include_zero = true;
    p.width = 370;
    p.css_class = s == &refined ? "plot-residuals" : "plot-residuals-coarse";
    for (double level : {-3.0, 3.0}) {
      Rule r;
      r.value = level;
      r.color = "#d62728";
      r.label = level > 0 ? "+3 sigma" : "-3 sigma";
      p.rules.push_back(r);
    }
    Series points = *s;
    points.name.clear();
    p.series.push_back(points);
    out += internal::RenderPlot(p);
  }
  return out;
}

struct ParameterRow {
  std::string name;
  double value = NAN;
  double std = NAN;
  std::string unit;
  std::string source;
};

bool Contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

// Whether the result names `method` (its name parsed by Method's table).
bool MadeBy(const Calibration& c, Method method) {
  Method made;
  return FromString(c.method, &made) && made == method;
}

// A parameter without a standard deviation: a recursive filter (the
// handheld one) has no state for it, so it never estimated it; a batch fit
// estimated it and the data did not determine it.
std::string NotDeterminedOrNotEstimated(const Calibration& c) {
  if (MadeBy(c, Method::kHandheldKalman)) {
    return "not estimated (held at its nominal value: the filter has no state for it; "
           "hk_cross_axis: true estimates the cross-axis terms)";
  }
  return "not determined";
}

// Where an accelerometer parameter came from.
std::string AccelSource(const Calibration& c, const std::string& fit_name, double std,
                        bool fixed_by_model, bool from_housing) {
  if (c.not_converged) return "coarse fit (the refinement did not converge)";
  if (Contains(c.refinement.observability.undetermined, fit_name)) {
    return "not determined (held at the coarse fit's value)";
  }
  if (fixed_by_model)
    return "fixed by the " + std::string(ToString(c.accel.model.parameterization)) + " model";
  if (!std::isfinite(std)) return NotDeterminedOrNotEstimated(c);
  if (from_housing) return "housing rotation (the poses' nominal axes)";
  // Issue 33: a sigma that rests on holding undetermined terms says so.
  const std::string held = internal::Join(internal::ConditionalOn(c.refinement));
  const std::string given = held.empty() ? "" : " (sigma conditional on holding " + held + ")";
  if (MadeBy(c, Method::kTwelvePosition)) return "magnitude fit" + given;
  return c.method + " fit" + given;
}

std::vector<ParameterRow> Parameters(const Calibration& c) {
  std::vector<ParameterRow> rows;
  const AccelModel& m = c.accel.model;
  const bool affine = m.parameterization == AccelParameterization::kAffine;
  const bool scale_only = m.parameterization == AccelParameterization::kScale;
  for (int i = 0; i < 3; ++i) {
    const std::string n = std::string("bias_") + kXyz[i];
    rows.push_back({"accel " + n, m.bias(i), c.accel.bias_std(i), "raw units",
                    AccelSource(c, n, c.accel.bias_std(i), false, false)});
  }
  const Eigen::Matrix3d matrix = m.matrix();
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) {
      const std::string n = std::string("u_") + kXyz[std::min(r, k)] + kXyz[std::max(r, k)];
      const bool fixed = (r > k && !affine) || (scale_only && r != k);
      const double s = c.accel.matrix_std(r, k);
      rows.push_back({std::string("accel M_") + kXyz[r] + kXyz[k], matrix(r, k), s,
                      "m/s^2 per raw unit", AccelSource(c, n, s, fixed, affine && r > k)});
    }
  }
  if (c.gyro.estimated) {
    const std::string source = c.method + " (gyroscope)";
    for (int i = 0; i < 3; ++i) {
      const double s = c.gyro.bias_std(i);
      rows.push_back({std::string("gyro bias_") + kXyz[i], c.gyro.model.bias(i), s, "raw units",
                      std::isfinite(s) ? source : NotDeterminedOrNotEstimated(c)});
    }
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) {
        const double s = c.gyro.matrix_std(r, k);
        rows.push_back({std::string("gyro M_") + kXyz[r] + kXyz[k], c.gyro.model.matrix(r, k), s,
                        "rad/s per raw unit",
                        std::isfinite(s) ? source : NotDeterminedOrNotEstimated(c)});
      }
    }
    for (size_t i = 0; i < c.gyro.extra_names.size(); ++i) {
      const double s = i < c.gyro.extra_std.size() ? c.gyro.extra_std[i] : NAN;
      rows.push_back({"gyro " + c.gyro.extra_names[i],
                      i < c.gyro.extra_values.size() ? c.gyro.extra_values[i] : NAN, s, "",
                      std::isfinite(s) ? source : NotDeterminedOrNotEstimated(c)});
    }
  }
  return rows;
}

std::string ParameterTable(const Calibration& c) {
  std::ostringstream h;
  h << "<table class='parameters'><tr><th>parameter</th><th>value</th><th>std</th><th>unit</th>"
    << "<th>from</th></tr>";
  for (const ParameterRow& r : Parameters(c)) {
    h << "<tr><td>" << HtmlEscape(r.name) << "</td><td class='num'>"
      << FormatNumber(r.value, "%.6g") << "</td><td class='num'>" << FormatNumber(r.std, "%.2g")
      << "</td><td>" << HtmlEscape(r.unit) << "</td><td>" << HtmlEscape(r.source) << "</td></tr>";
  }
  h << "</table><p class='note'>a = M (v - b): v the raw reading, b the bias in raw units, M the "
       "matrix to m/s^2 (rad/s for the gyroscope).</p>";
  return h.str();
}

std::string Correlation(const std::string& title, const Eigen::MatrixXd& cov,
                        const std::vector<std::string>& names) {
  const int n = static_cast<int>(cov.rows());
  if (n == 0 || cov.cols() != n || static_cast<int>(names.size()) != n) return "";
  Eigen::MatrixXd corr(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) corr(i, j) = cov(i, j) / std::sqrt(cov(i, i) * cov(j, j));
  }
  return internal::RenderHeatMap(title, names, corr);
}

// One plot per state of the handheld filter: estimate and +-1 sigma band
// over time (at most 400 epochs drawn).
std::string Convergence(const Calibration& c) {
  const EstimateHistory& h = c.history;
  const size_t rows = h.rows(), cols = h.columns.size();
  if (rows == 0 || c.convergence.entries.empty()) return "";
  const size_t stride = std::max<size_t>(1, rows / 400);
  std::ostringstream o;
  o << "<h2 id='convergence'>Filter convergence</h2><p>" << HtmlEscape(c.convergence.criterion)
    << ".</p><div>";
  for (const ConvergenceEntry& e : c.convergence.entries) {
    const auto it = std::find(h.columns.begin(), h.columns.end(), e.name);
    if (it == h.columns.end() || it + 1 == h.columns.end()) continue;
    const size_t col = static_cast<size_t>(it - h.columns.begin());
    Series band, line;
    band.style = SeriesStyle::kEnvelope;
    band.color = "#1f77b4";
    band.opacity = 0.2;
    band.name = "+-1 sigma";
    line.color = "#1f77b4";
    line.name = "estimate";
    for (size_t r = 0; r < rows; r += stride) {
      const double* row = &h.values[r * cols];
      line.x.push_back(row[0]);
      line.y.push_back(row[col]);
      band.x.push_back(row[0]);
      band.lo.push_back(row[col] - row[col + 1]);
      band.hi.push_back(row[col] + row[col + 1]);
    }
    Plot p;
    p.title = e.name + (e.converged ? " (converged at " + FormatNumber(e.time, "%.1f") + " s)"
                                    : " (not converged)");
    p.x.label = "time, s";
    p.y.label = e.name + ", " + e.unit;
    p.width = 560;
    p.height = 260;
    p.css_class = "plot-convergence";
    // The prior band dwarfs the end: the y range is that of the last 90 %
    // of the run.
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = band.x.size() / 10; i < band.x.size(); ++i) {
      if (std::isfinite(band.lo[i])) lo = std::min(lo, band.lo[i]);
      if (std::isfinite(band.hi[i])) hi = std::max(hi, band.hi[i]);
    }
    if (hi > lo) {
      const internal::NiceTicks t = internal::MakeNiceTicks(lo, hi, 5);
      p.y.lo = t.lo;
      p.y.hi = t.hi;
    }
    p.series = {band, line};
    o << internal::RenderPlot(p);
  }
  o << "</div>";
  return o.str();
}

std::string PoseTable(const Calibration& c) {
  std::ostringstream h;
  h << "<table class='poses'><tr><th>pose</th><th>from, s</th><th>to, s</th><th>samples</th>"
    << "<th>up</th><th>nominal, m/s^2</th><th>coarse, m/s^2</th><th>refined, m/s^2</th>"
    << "<th>sigma, m/s^2</th><th>refined / sigma</th></tr>";
  for (size_t k = 0; k < c.positions.size(); ++k) {
    const PositionReport& p = c.positions[k];
    const double z = AfterSigma(p);
    h << "<tr" << (std::fabs(z) > OutlierThreshold(c.positions.size()) ? " class='warn'" : "")
      << "><td>" << k + 1 << "</td><td class='num'>" << FormatNumber(p.position.t_begin, "%.1f")
      << "</td><td class='num'>" << FormatNumber(p.position.t_end, "%.1f")
      << "</td><td class='num'>" << p.position.sample_count << "</td><td>"
      << NominalAxisName(p.nominal_up) << "</td><td class='num'>"
      << FormatNumber(p.residual_nominal, "%.3g") << "</td><td class='num'>"
      << FormatNumber(p.residual_coarse, "%.3g") << "</td><td class='num'>"
      << FormatNumber(p.residual_after, "%.3g") << "</td><td class='num'>"
      << FormatNumber(p.sigma, "%.3g") << "</td><td class='num'>" << FormatNumber(z, "%.2f")
      << "</td></tr>";
  }
  h << "</table>";
  return h.str();
}

std::string CalibrationReport(const Calibration& c, const ImuLog& log, const std::string& source,
                              const StaticDetection* detection) {
  std::ostringstream h;
  h << internal::HtmlPageStart("gravcal calibration: " + source);
  h << "<h1>Calibration report</h1><p>" << HtmlEscape(source) << " &mdash; method "
    << HtmlEscape(c.method) << ", " << log.size() << " samples, ";
  // A filter on a moving log has no static poses to count.
  if (!MadeBy(c, Method::kHandheldKalman)) h << c.positions.size() << " static poses, ";
  h << "gravity " << FormatNumber(c.gravity, "%.6g") << " m/s^2 ("
    << HtmlEscape(c.gravity_source.empty() ? "not resolved" : c.gravity_source) << ")</p>\n";

  const Verdict v = Judge(c);
  const char* level = v.level == Level::kGood ? "good" : v.level == Level::kLook ? "look" : "again";
  const char* words = v.level == Level::kGood   ? "Good: this calibration can be used."
                      : v.level == Level::kLook ? "Look at these before using it."
                                                : "Record the session again.";
  h << "<div class='verdict " << level << "' id='verdict'><b>" << words << "</b><ul>";
  for (const std::string& r : v.reasons) h << "<li>" << HtmlEscape(r) << "</li>";
  for (const std::string& r : v.notes) h << "<li class='note'>" << HtmlEscape(r) << "</li>";
  h << "</ul></div>\n<p>" << HtmlEscape(c.message) << "</p>\n";

  h << "<h2 id='signals'>Raw signals and static intervals</h2>";
  std::vector<Span> spans;
  if (detection != nullptr) spans = RejectedSpans(*detection);
  for (const Span& s : PoseSpans(c)) spans.push_back(s);
  if (log.size() > 0) {
    h << RawPlot(log, log.accel, "accelerometer", spans, "plot-raw plot-accel");
    if (log.has_gyro()) h << RawPlot(log, log.gyro, "gyroscope", spans, "plot-raw plot-gyro");
    h << "<p class='note'>Signals longer than the plot is wide are drawn as the band between "
         "their minimum and maximum in each pixel column. ";
    if (detection != nullptr) {
      h << "The static detector rejected " << detection->rejected.size() << " stretch"
        << (detection->rejected.size() == 1 ? "" : "es")
        << " (shaded orange: still but shorter than min_duration_seconds once settle_seconds "
           "is trimmed from each end; red: nearly still, but moving or rotating above the "
           "thresholds; hover over one for its numbers). The rest between the numbered "
           "intervals was moving.</p>";
      if (detection->intervals.size() != c.positions.size()) {
        h << "<p class='note warn'>The detection shown found " << detection->intervals.size()
          << " static intervals; the calibration used " << c.positions.size() << ".</p>";
      }
    } else {
      h << "Stretches between the shaded intervals were moving, or were still for less than "
           "min_duration_seconds, or were trimmed by settle_seconds.</p>";
    }
  }

  if (!c.positions.empty()) {
    h << "<h2 id='poses'>Pose directions</h2>";
    std::vector<Eigen::Vector3d> up;
    for (const PositionReport& p : c.positions) {
      up.push_back(c.success ? c.accel.model.Apply(p.position.raw_mean) : p.position.raw_mean);
    }
    h << internal::RenderSphere("Direction of up in the sensor frame, per pose", up, {})
      << "<p class='note'>Equal-area view of each half of the sphere, looking down the z axis; "
         "rings at 30 and 60 degrees from the pole. A good session spreads its poses over "
         "both halves and all around.</p>";
    h << "<h2 id='residuals'>Residuals per pose</h2>" << ResidualPlots(c) << PoseTable(c);
  }
  h << internal::ThermalReportSection(c, log);

  h << "<h2 id='parameters'>Parameters</h2>" << ParameterTable(c);
  const std::string ca = Correlation("Accelerometer parameter correlation", c.accel.covariance,
                                     c.accel.covariance_names);
  const std::string cg =
      Correlation("Gyroscope parameter correlation", c.gyro.covariance, c.gyro.covariance_names);
  if (!ca.empty() || !cg.empty()) {
    h << "<h2 id='correlation'>Correlations</h2>" << ca << cg
      << "<p class='note'>Strongly correlated pairs (|r| near 1) are told apart poorly by "
         "this session: add poses that separate them.</p>";
  }
  if (!c.gyro.rotation_residual_deg.empty()) {
    Plot p;
    p.title = "Gyroscope: residual of every rotation";
    p.x = {"rotation", internal::AxisScale::kLinear,
           0.4,        c.gyro.rotation_residual_deg.size() + 0.6,
           false,      true};
    p.y.label = "rotation residual, deg";
    p.y.include_zero = true;
    Series s;
    s.style = SeriesStyle::kBars;
    s.color = "#9467bd";
    s.css_class = "rotation-residual";
    for (size_t k = 0; k < c.gyro.rotation_residual_deg.size(); ++k) {
      s.x.push_back(k + 1.0);
      s.y.push_back(c.gyro.rotation_residual_deg[k]);
    }
    p.series.push_back(s);
    h << "<h2 id='rotations'>Gyroscope rotations</h2>" << internal::RenderPlot(p);
  }
  h << Convergence(c);

  h << "<h2 id='warnings'>Warnings</h2>";
  if (c.warnings.empty()) {
    h << "<p>None.</p>";
  } else {
    h << "<table class='warnings'><tr><th>warning</th><th>what it means</th><th>what to "
         "do</th></tr>";
    for (size_t i = 0; i < c.warnings.size(); ++i) {
      const WarningCode code =
          i < c.warning_codes.size() ? c.warning_codes[i] : WarningCode::kUnclassified;
      const internal::WarningAdvice advice = internal::AdviceFor(code);
      const bool explained = !advice.meaning.empty();
      h << "<tr class='" << (explained ? "warning" : "warning unexplained") << "' data-code='"
        << ToString(code) << "'><td class='warn'>" << HtmlEscape(c.warnings[i]) << "</td><td>"
        << HtmlEscape(explained ? advice.meaning : "No explanation is recorded for this warning.")
        << "</td><td>" << HtmlEscape(advice.action) << "</td></tr>";
    }
    h << "</table>";
  }
  const RefinementResult& r = c.refinement;
  h << "<h2 id='solver'>Solver</h2><p>" << HtmlEscape(c.solver_name) << ": " << r.iterations
    << " iterations, " << HtmlEscape(r.termination) << "; chi2 " << FormatNumber(r.chi2, "%.3g")
    << " on " << r.dof << " degrees of freedom; |a| - g rms "
    << FormatNumber(c.residual_nominal.rms, "%.4g") << " (nominal) &rarr; "
    << FormatNumber(c.residual_coarse.rms, "%.4g") << " (coarse) &rarr; "
    << FormatNumber(c.residual_refined.rms, "%.4g") << " m/s^2 (refined).</p>";
  h << internal::HtmlPageEnd();
  return h.str();
}

}  // namespace

std::string CalibrationToHtml(const Calibration& c, const ImuLog& log, const std::string& source) {
  return CalibrationReport(c, log, source, nullptr);
}

std::string CalibrationToHtml(const Calibration& c, const ImuLog& log, const std::string& source,
                              const StaticDetection& detection) {
  return CalibrationReport(c, log, source, &detection);
}

}  // namespace gravcal
