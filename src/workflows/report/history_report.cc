// The history of a unit's calibrations as HTML (calibration_store.h,
// UnitHistoryToHtml): one plot per parameter against the date.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "gravcal/workflows/calibration_store.h"
#include "workflows/report/svg_plot.h"

namespace gravcal {

namespace {

using internal::HtmlEscape;

std::string Format(const char* format, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, v);
  return buffer;
}

// value +- k sigma as a points series (error bars).
internal::Series Bars(const ParameterHistory& p, double k, const std::string& name,
                      double opacity) {
  internal::Series s;
  s.name = name;
  s.style = internal::SeriesStyle::kPoints;
  s.opacity = opacity;
  s.css_class = k == 1.0 ? "history-value" : "history-band";
  if (k != 1.0) s.color = "#9ecae1";
  for (size_t i = 0; i < p.values.size(); ++i) {
    if (!std::isfinite(p.stds[i])) continue;
    s.x.push_back(p.days[i]);
    s.y.push_back(p.values[i]);
    s.lo.push_back(p.values[i] - k * p.stds[i]);
    s.hi.push_back(p.values[i] + k * p.stds[i]);
    s.titles.push_back(Format("%.6g", p.values[i]) + " +- " + Format("%.3g", p.stds[i]));
  }
  return s;
}

std::string ParameterPlot(const ParameterHistory& p, const std::string& first_date) {
  internal::Plot plot;
  plot.title =
      p.name + (p.drifts ? ": drifts (p = " + Format("%.3g", p.p_value) + ")"
                : std::isfinite(p.p_value)
                    ? ": constant within its sigmas (p = " + Format("%.3g", p.p_value) + ")"
                    : "");
  plot.x.label = "days since " + first_date;
  plot.y.label = p.name;
  plot.height = 240;
  plot.css_class = "plot-history";
  plot.series.push_back(Bars(p, 2.0, "2 sigma", 0.35));
  plot.series.push_back(Bars(p, 1.0, "value, 1 sigma", 1.0));
  if (std::isfinite(p.mean)) {
    internal::Rule mean;
    mean.value = p.mean;
    mean.label = "weighted mean";
    plot.rules.push_back(mean);
  }
  if (std::isfinite(p.slope_per_day) && std::isfinite(p.intercept) && !p.days.empty()) {
    internal::Series line;
    line.name = "trend " + Format("%.3g", p.slope_per_day) + " +- " + Format("%.2g", p.slope_std) +
                " per day";
    line.color = "#d62728";
    line.dashed = true;
    const double d0 = *std::min_element(p.days.begin(), p.days.end());
    const double d1 = *std::max_element(p.days.begin(), p.days.end());
    line.x = {d0, d1};
    line.y = {p.intercept + p.slope_per_day * d0, p.intercept + p.slope_per_day * d1};
    plot.series.push_back(line);
  }
  return internal::RenderPlot(plot);
}

}  // namespace

std::string UnitHistoryToHtml(const UnitHistory& h) {
  std::ostringstream out;
  out << internal::HtmlPageStart("gravcal history " + h.unit);
  out << "<h1>Calibration history of " << HtmlEscape(h.unit) << "</h1>\n<p id='verdict'>"
      << HtmlEscape(h.message) << "</p>\n<table><tr><th>date (UTC)</th><th>file</th><th>vs "
      << "previous</th></tr>\n";
  for (size_t k = 0; k < h.calibrations.size(); ++k) {
    out << "<tr><td>" << HtmlEscape(h.calibrations[k].date) << "</td><td>"
        << HtmlEscape(h.calibrations[k].file) << "</td><td>"
        << (k == 0 ? "" : HtmlEscape(h.steps[k - 1].message)) << "</td></tr>\n";
  }
  out << "</table>\n<p class='note'>Each value with its 1-sigma bar (the fainter bar: 2 "
         "sigma), the weighted mean and the weighted trend line.</p>\n";
  const std::string first = h.calibrations.empty() ? "" : h.calibrations.front().date;
  for (const ParameterHistory& p : h.parameters) out << ParameterPlot(p, first) << "\n";
  out << internal::HtmlPageEnd();
  return out.str();
}

}  // namespace gravcal
