// The fleet report of a batch (report.h, FleetToHtml).
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "gravcal/workflows/report.h"
#include "workflows/report/svg_plot.h"

namespace gravcal {
namespace {

using internal::FormatNumber;
using internal::HtmlEscape;
using internal::Rule;
using internal::Series;
using internal::SeriesStyle;

// The unit of a summary column.
std::string ColumnUnit(const std::string& name) {
  if (name.rfind("residual", 0) == 0) return "m/s^2";
  if (name.find("_s") + 2 == name.size()) return "s";
  if (name.rfind("accel_bias", 0) == 0 || name.rfind("gyro_bias", 0) == 0) return "raw units";
  if (name.rfind("accel_m_", 0) == 0) return "m/s^2 per raw unit";
  if (name.rfind("gyro_m_", 0) == 0) return "rad/s per raw unit";
  return "as calibrated";
}

// Units flagged on `parameter`: the outliers whose reasons name it.
std::vector<std::string> FlaggedOn(const FleetStatistics& s, const std::string& parameter) {
  std::vector<std::string> units;
  for (const FleetOutlier& o : s.outliers) {
    for (const std::string& r : o.reasons) {
      if (r.rfind(parameter + " = ", 0) == 0) units.push_back(o.unit);
    }
  }
  return units;
}

std::string Histogram(const ParameterStatistics& p, const std::vector<SummaryRow>& rows,
                      const FleetStatistics& s) {
  std::vector<double> values;
  std::vector<std::string> names;
  for (const SummaryRow& r : rows) {
    if (r.status != BatchStatus::kOk) continue;
    const auto it = r.values.find(p.name);
    if (it == r.values.end() || !std::isfinite(it->second)) continue;
    values.push_back(it->second);
    names.push_back(r.unit);
  }
  const internal::NiceTicks t = internal::MakeNiceTicks(p.min, p.max, 16);
  Series bars;
  bars.style = SeriesStyle::kSteps;
  bars.color = "#1f77b4";
  bars.opacity = 0.75;
  bars.name = "units";
  bars.x = t.values;
  bars.y.assign(t.values.size() > 1 ? t.values.size() - 1 : 0, 0.0);
  for (double v : values) {
    const size_t b = std::min(bars.y.size() - 1,
                              static_cast<size_t>(std::max(0.0, std::floor((v - t.lo) / t.step))));
    if (!bars.y.empty()) bars.y[b] += 1;
  }
  internal::Plot plot;
  plot.title = p.name;
  plot.x.label = p.name + ", " + ColumnUnit(p.name);
  plot.y.label = "units";
  plot.y.integer = true;
  plot.width = 560;
  plot.height = 280;
  plot.css_class = "plot-histogram";
  plot.series.push_back(bars);
  const std::vector<std::string> flagged = FlaggedOn(s, p.name);
  if (!flagged.empty()) {
    Series marks;
    marks.style = SeriesStyle::kPoints;
    marks.color = "#d62728";
    marks.css_class = "outlier-mark";
    std::string legend = "outlier:";
    for (size_t i = 0; i < values.size(); ++i) {
      if (std::find(flagged.begin(), flagged.end(), names[i]) == flagged.end()) continue;
      marks.x.push_back(values[i]);
      marks.y.push_back(0.5);
      marks.titles.push_back(names[i] + ": " + FormatNumber(values[i], "%.6g"));
      if (marks.x.size() <= 4) legend += " " + names[i];
    }
    marks.name = legend + (marks.x.size() > 4 ? " ..." : "");
    plot.series.push_back(marks);
  }
  Rule median;
  median.value = p.median;
  median.vertical = true;
  median.color = "#222";
  median.dashed = false;
  median.label = "median";
  plot.rules.push_back(median);
  for (double side : {-1.0, 1.0}) {
    Rule r;
    r.value = p.median + side * p.robust_std;
    r.vertical = true;
    r.color = "#2ca02c";
    plot.rules.push_back(r);
  }
  return internal::RenderPlot(plot);
}

}  // namespace

std::string FleetToHtml(const FleetStatistics& s, const std::vector<SummaryRow>& rows,
                        const BatchThroughput& t) {
  std::ostringstream h;
  h << internal::HtmlPageStart("gravcal fleet report");
  h << "<h1>Fleet report</h1><p>" << s.units << " units (shard " << s.info.shard_index << "/"
    << s.info.shard_count << " of a fleet of " << s.info.units_in_fleet << "): <b>" << s.ok
    << " calibrated</b>, " << s.failed << " failed, " << s.not_converged << " not converged, "
    << s.outliers.size() << " outliers (outlier check: " << HtmlEscape(s.outlier_check)
    << ").</p>\n";
  const char* level = s.failed + s.not_converged > 0 ? "again"
                      : s.outliers.empty()           ? "good"
                                                     : "look";
  h << "<div class='verdict " << level << "' id='verdict'><b>"
    << (s.failed + s.not_converged > 0 ? "Some units need another session: see the failed units."
        : s.outliers.empty()           ? "Every unit calibrated and none stands out."
                                       : "Every unit calibrated; look at the outliers.")
    << "</b></div>\n";

  h << "<h2 id='throughput'>Throughput</h2><table class='throughput'>"
    << "<tr><th>units run</th><td class='num'>" << t.computed << "</td></tr>"
    << "<tr><th>reused (stored result up to date)</th><td class='num'>" << t.skipped << "</td></tr>"
    << "<tr><th>wall-clock time, s</th><td class='num'>" << FormatNumber(t.elapsed_seconds, "%.2f")
    << "</td></tr><tr><th>units per second</th><td class='num'>"
    << FormatNumber(t.elapsed_seconds > 0 ? t.computed / t.elapsed_seconds : NAN, "%.2f")
    << "</td></tr>";
  const double busy = t.read_seconds + t.detect_seconds + t.solve_seconds;
  if (busy > 0) {
    h << "<tr><th>time in read / detect / solve</th><td class='num'>"
      << FormatNumber(100 * t.read_seconds / busy, "%.0f") << " % / "
      << FormatNumber(100 * t.detect_seconds / busy, "%.0f") << " % / "
      << FormatNumber(100 * t.solve_seconds / busy, "%.0f") << " %</td></tr>";
  }
  h << "</table>\n";

  h << "<h2 id='parameters'>Parameters over the fleet</h2><p class='note'>Histograms of the "
       "calibrated units; black: the median; green: median +- robust std (1.4826 MAD); red "
       "dots: units flagged as outliers (more than "
    << FormatNumber(s.options.outlier_sigmas, "%g")
    << " robust std from the median). Hover a dot for the unit.</p><div>";
  std::string fixed;
  for (const ParameterStatistics& p : s.parameters) {
    if (!(p.max > p.min)) {
      fixed += (fixed.empty() ? "" : ", ") + p.name;
      continue;
    }
    h << Histogram(p, rows, s);
  }
  h << "</div>";
  if (!fixed.empty()) {
    h << "<p class='note'>The same in every unit (fixed by the model): " << HtmlEscape(fixed)
      << ".</p>";
  }
  h << "<table class='statistics'><tr><th>parameter</th><th>units</th><th>median</th>"
    << "<th>robust std</th><th>min</th><th>max</th><th>unit</th></tr>";
  for (const ParameterStatistics& p : s.parameters) {
    h << "<tr><td>" << HtmlEscape(p.name) << "</td><td class='num'>" << p.units
      << "</td><td class='num'>" << FormatNumber(p.median, "%.6g") << "</td><td class='num'>"
      << FormatNumber(p.robust_std, "%.3g") << "</td><td class='num'>"
      << FormatNumber(p.min, "%.6g") << "</td><td class='num'>" << FormatNumber(p.max, "%.6g")
      << "</td><td>" << ColumnUnit(p.name) << "</td></tr>";
  }
  h << "</table>\n";

  h << "<h2 id='outliers'>Outliers</h2>";
  if (s.outliers.empty()) {
    h << "<p>None.</p>";
  } else {
    h << "<table class='outliers'><tr><th>unit</th><th>why</th></tr>";
    for (const FleetOutlier& o : s.outliers) {
      h << "<tr><td>" << HtmlEscape(o.unit) << "</td><td>";
      for (size_t i = 0; i < o.reasons.size(); ++i) {
        h << (i ? "<br>" : "") << HtmlEscape(o.reasons[i]);
      }
      h << "</td></tr>";
    }
    h << "</table><p class='note'>An outlier is not necessarily wrong: check its session "
         "(calibrate it alone with --report) before rejecting the part.</p>";
  }
  h << "<h2 id='failures'>Failed units</h2>";
  if (s.failures.empty()) {
    h << "<p>None.</p>";
  } else {
    h << "<table class='failures'><tr><th>unit</th><th>status</th><th>message</th></tr>";
    for (const SummaryRow& r : s.failures) {
      h << "<tr><td>" << HtmlEscape(r.unit) << "</td><td>" << ToString(r.status) << "</td><td>"
        << HtmlEscape(r.message) << "</td></tr>";
    }
    h << "</table>";
  }
  h << internal::HtmlPageEnd();
  return h.str();
}

}  // namespace gravcal
