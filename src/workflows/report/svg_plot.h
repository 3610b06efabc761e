// Private: the one plotting module of every HTML report (calibration, fleet,
// noise, discovery). Plots are inline SVG strings; no script, no external
// asset, so a report opens without a network.
//
// Axes get "nice" ticks: steps of 1, 2 or 5 times a power of ten on a linear
// axis (so the labels read 0, 0.5, 1, 1.5 and never 8.72, 4.44), powers of
// ten on a logarithmic one. Every axis has a label with its unit. Long
// signals are drawn as min/max envelopes (one column per output pixel or
// so), so a one-hour 200 Hz session stays a few hundred kilobytes.
//
// DOM contract (the browser tests rely on it): each axis is a
// <g class='axis' data-axis='x|y' data-scale='linear|log'> holding its tick
// labels as <text class='tick'>; every plot is an <svg class='plot ...'>.
#ifndef GRAVCAL_SRC_WORKFLOWS_REPORT_SVG_PLOT_H_
#define GRAVCAL_SRC_WORKFLOWS_REPORT_SVG_PLOT_H_

#include <Eigen/Core>
#include <string>
#include <vector>

namespace gravcal {
namespace internal {

// Ticks of a linear axis covering [lo, hi]: about `target` of them, at
// multiples of step = {1, 2, 5} x 10^k; lo and hi are widened to whole steps.
struct NiceTicks {
  double lo = 0.0;
  double hi = 1.0;
  double step = 1.0;
  std::vector<double> values;
};
NiceTicks MakeNiceTicks(double lo, double hi, int target = 6);

// The label of tick `value` on an axis of step `step`: as many decimals as
// the step needs, exponent form for very small or large numbers, "0" for 0.
std::string TickLabel(double value, double step);

enum class AxisScale { kLinear, kLog };

struct AxisSpec {
  // With the unit, e.g. "time, s".
  std::string label;
  AxisScale scale = AxisScale::kLinear;
  // Fixed range; NaN = from the data (padded and widened to nice ticks).
  double lo = NAN;
  double hi = NAN;
  // The range from the data always contains 0.
  bool include_zero = false;
  // Integer ticks only (positions, counts).
  bool integer = false;
};

enum class SeriesStyle {
  kLine,      // polyline through (x, y)
  kPoints,    // markers at (x, y); error bars from lo/hi when given
  kBars,      // bars from 0 to y, centred at x, width bar_width (x units)
  kEnvelope,  // filled band between lo and hi over x (min/max envelope)
  kSteps,     // histogram: bars from x[i] to x[i+1] of height y[i]
};

struct Series {
  std::string name;  // legend text; empty = not in the legend
  std::string color = "#1f77b4";
  SeriesStyle style = SeriesStyle::kLine;
  std::vector<double> x;
  std::vector<double> y;
  std::vector<double> lo;
  std::vector<double> hi;
  double bar_width = 0.8;
  double opacity = 1.0;
  bool dashed = false;
  // Label written at the last point of a line (fitted terms, thresholds).
  std::string end_label;
  // Extra class on the series' elements (tests count them).
  std::string css_class;
  // Tooltip per point (kPoints, kBars): empty = none.
  std::vector<std::string> titles;
};

// A shaded stretch of the x axis, numbered (static intervals).
struct Span {
  double x0 = 0.0;
  double x1 = 0.0;
  std::string label;
  std::string color = "#2ca02c";
  std::string css_class = "span";
  std::string title;
  // Legend text of this kind of span; spans with the same text share one
  // legend entry. Empty = not in the legend.
  std::string legend;
};

// A horizontal (y = value) or vertical (x = value) reference line.
struct Rule {
  double value = 0.0;
  bool vertical = false;
  std::string label;
  std::string color = "#888";
  bool dashed = true;
};

struct Plot {
  std::string title;
  AxisSpec x;
  AxisSpec y;
  std::vector<Series> series;
  std::vector<Span> spans;
  std::vector<Rule> rules;
  int width = 900;
  int height = 320;
  // Extra class on the <svg> (e.g. "plot-raw").
  std::string css_class;
};

// The plot as an <svg> element.
std::string RenderPlot(const Plot& plot);

// The min/max envelope of y over x[begin, end) in about `columns` equal
// slices of x: series.x gets the slice centres, lo and hi the extremes. When
// the stretch has no more samples than 2 columns, x and y are copied as they
// are (style kLine).
Series MinMaxEnvelope(const std::vector<double>& x, const std::vector<double>& y, int columns);

// An n x n matrix of values in [-1, 1] (correlations) as coloured cells,
// blue -1, white 0, red +1, with the names along both edges.
std::string RenderHeatMap(const std::string& title, const std::vector<std::string>& names,
                          const Eigen::MatrixXd& values);

// Unit vectors on the two hemispheres (z >= 0 and z < 0 of the body frame),
// each in Lambert azimuthal equal-area projection, numbered 1..n; circles at
// 30 and 60 degrees from the pole. `labels` defaults to the index.
std::string RenderSphere(const std::string& title, const std::vector<Eigen::Vector3d>& directions,
                         const std::vector<std::string>& labels);

// A pixel coordinate with one decimal: enough for the screen, small files.
std::string Px(double v);

// Colours of the x, y, z axes and a palette for other series.
extern const char* const kAxisColors[3];
const char* PaletteColor(int i);

// ---------------------------------------------------------------------------
// HTML around the plots.

std::string HtmlEscape(const std::string& s);

// printf-formatted number, "&ndash;" when not finite.
std::string FormatNumber(double v, const char* format = "%.4g");

// <!DOCTYPE html> ... <body> with the shared style sheet and `title`.
std::string HtmlPageStart(const std::string& title);

// The closing tags, with a small inline script that records how long the
// page took to load in <body data-load-ms>, and its height in px in
// data-height (read by the browser tests).
std::string HtmlPageEnd();

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_REPORT_SVG_PLOT_H_
