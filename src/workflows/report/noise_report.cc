// The noise report (report.h, NoiseToHtml).
#include <cmath>
#include <sstream>

#include "gravcal/workflows/report.h"
#include "workflows/report/svg_plot.h"

namespace gravcal {
namespace {

using internal::FormatNumber;
using internal::HtmlEscape;
using internal::Plot;
using internal::Series;
using internal::SeriesStyle;

struct SensorUnits {
  const char* name;
  const char* unit;     // of the Allan deviation and B
  const char* density;  // of N
  const char* walk;     // of K
  const char* quantum;  // of Q
};

const SensorUnits kAccel = {"accelerometer", "m/s^2", "m/s^2/sqrt(Hz)", "m/s^3/sqrt(Hz)", "m/s"};
const SensorUnits kGyro = {"gyroscope", "rad/s", "rad/s/sqrt(Hz)", "rad/s^2/sqrt(Hz)", "rad"};

// A fitted term's Allan deviation line over the curve's taus.
Series TermLine(const AllanDeviation& curve, const NoiseTerm& term, double (*sigma)(double, double),
                const char* symbol, const char* unit, const char* color) {
  Series s;
  s.color = color;
  s.dashed = true;
  s.css_class = "noise-term";
  for (const AllanPoint& p : curve.points) {
    s.x.push_back(p.tau);
    s.y.push_back(sigma(term.value, p.tau));
  }
  s.end_label = std::string(symbol) + " = " + FormatNumber(term.value, "%.3g") + " " + unit;
  return s;
}

std::string AxisPlot(const AllanDeviation& curve, const AxisNoiseModel& m, const SensorUnits& u,
                     char axis) {
  Plot p;
  p.title = std::string(u.name) + " " + axis + ": Allan deviation";
  p.x.label = "averaging time tau, s";
  p.x.scale = internal::AxisScale::kLog;
  p.y.label = std::string("Allan deviation, ") + u.unit;
  p.y.scale = internal::AxisScale::kLog;
  p.width = 580;
  p.height = 330;
  p.css_class = "plot-allan";
  Series points;
  points.style = SeriesStyle::kPoints;
  points.name = "measured (" + FormatNumber(100 * curve.confidence, "%.0f") + " % interval)";
  points.color = "#222";
  points.css_class = "allan-point";
  for (const AllanPoint& a : curve.points) {
    points.x.push_back(a.tau);
    points.y.push_back(a.adev);
    points.lo.push_back(a.lo);
    points.hi.push_back(a.hi);
  }
  p.series.push_back(points);
  Series model;
  model.name = "fitted model";
  model.color = "#1f77b4";
  for (const AllanPoint& a : curve.points) {
    model.x.push_back(a.tau);
    model.y.push_back(std::sqrt(m.AllanVariance(a.tau)));
  }
  p.series.push_back(model);
  if (m.quantisation.visible()) {
    p.series.push_back(TermLine(
        curve, m.quantisation, [](double q, double tau) { return std::sqrt(3.0) * q / tau; }, "Q",
        u.quantum, "#9467bd"));
  }
  if (m.white_noise.visible()) {
    p.series.push_back(TermLine(
        curve, m.white_noise, [](double n, double tau) { return n / std::sqrt(tau); }, "N",
        u.density, "#ff7f0e"));
  }
  if (m.bias_instability.visible()) {
    p.series.push_back(TermLine(
        curve, m.bias_instability,
        [](double b, double) { return std::sqrt(kFlickerAllanFactor) * b; }, "B", u.unit,
        "#2ca02c"));
  }
  if (m.random_walk.visible()) {
    p.series.push_back(TermLine(
        curve, m.random_walk, [](double k, double tau) { return k * std::sqrt(tau / 3.0); }, "K",
        u.walk, "#d62728"));
  }
  // Keep the axes on the measured curve: term lines run off it.
  double lo = INFINITY, hi = -INFINITY;
  for (const AllanPoint& a : curve.points) {
    lo = std::min(lo, a.lo > 0 ? a.lo : a.adev);
    hi = std::max(hi, a.hi);
  }
  if (hi > lo && lo > 0) {
    p.y.lo = std::pow(10.0, std::floor(std::log10(lo)));
    p.y.hi = std::pow(10.0, std::ceil(std::log10(hi)));
  }
  return internal::RenderPlot(p);
}

std::string TermCell(const NoiseTerm& t) {
  if (!t.visible()) return "<td>not shown: " + HtmlEscape(t.reason) + "</td>";
  return "<td class='num'>" + FormatNumber(t.value, "%.3g") + " &plusmn; " +
         FormatNumber(t.std, "%.2g") + " (tau " + FormatNumber(t.tau, "%.3g") + " s)</td>";
}

std::string Sensor(const std::array<AllanDeviation, 3>& curves,
                   const std::array<AxisNoiseModel, 3>& model, const SensorUnits& u) {
  if (curves[0].points.empty()) return "";
  std::ostringstream h;
  h << "<h2 id='" << u.name << "'>" << char(std::toupper(u.name[0])) << (u.name + 1)
    << "</h2><div>";
  const char* axes = "xyz";
  for (int a = 0; a < 3; ++a) h << AxisPlot(curves[a], model[a], u, axes[a]);
  h << "</div><table class='terms'><tr><th>axis</th><th>white noise N, " << u.density
    << "</th><th>bias instability B, " << u.unit << "</th><th>random walk K, " << u.walk
    << "</th><th>quantisation Q, " << u.quantum << "</th></tr>";
  for (int a = 0; a < 3; ++a) {
    h << "<tr><td>" << axes[a] << "</td>" << TermCell(model[a].white_noise)
      << TermCell(model[a].bias_instability) << TermCell(model[a].random_walk)
      << TermCell(model[a].quantisation) << "</tr>";
  }
  h << "</table>";
  return h.str();
}

}  // namespace

std::string NoiseToHtml(const ImuNoise& noise, const std::string& source) {
  const ImuNoiseModel& m = noise.model;
  std::ostringstream h;
  h << internal::HtmlPageStart("gravcal noise: " + source);
  h << "<h1>Noise report</h1><p>" << HtmlEscape(source) << " &mdash; still from "
    << FormatNumber(m.still_t_begin, "%.1f") << " to " << FormatNumber(m.still_t_end, "%.1f")
    << " s (" << m.still_end - m.still_begin << " samples at " << FormatNumber(m.rate_hz, "%.4g")
    << " Hz).</p><p>" << HtmlEscape(noise.message) << "</p>";
  h << "<p class='note'>Black: the overlapping Allan deviation with its confidence interval; "
       "blue: the fitted model; dashed: each fitted term alone, labelled with its value "
       "(N: white noise, read at tau = 1 s on its line; B: bias instability, the flat floor "
       "is 0.664 B; K: rate random walk; Q: quantisation). A term not shown could not be "
       "read from this log; the table says why.</p>";
  h << Sensor(noise.accel_curves, m.accel, kAccel) << Sensor(noise.gyro_curves, m.gyro, kGyro);
  h << internal::HtmlPageEnd();
  return h.str();
}

}  // namespace gravcal
