#include "workflows/report/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace gravcal {
namespace internal {

const char* const kAxisColors[3] = {"#1f77b4", "#d62728", "#2ca02c"};

const char* PaletteColor(int i) {
  static const char* const kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                         "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"};
  return kPalette[((i % 8) + 8) % 8];
}

std::string Px(double v) {
  char b[32];
  std::snprintf(b, sizeof(b), "%.1f", v);
  return b;
}

namespace {

// 1, 2 or 5 times a power of ten, at least `raw`.
double NiceStep(double raw) {
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  const double nice = norm <= 1.0 ? 1.0 : norm <= 2.0 ? 2.0 : norm <= 5.0 ? 5.0 : 10.0;
  return nice * mag;
}

void Extend(double v, double* lo, double* hi) {
  if (!std::isfinite(v)) return;
  *lo = std::min(*lo, v);
  *hi = std::max(*hi, v);
}

void ExtendAll(const std::vector<double>& v, double* lo, double* hi) {
  for (double x : v) Extend(x, lo, hi);
}

// One axis after its range and ticks are settled: maps data to pixels
// along [p0, p1].
struct AxisMap {
  AxisScale scale = AxisScale::kLinear;
  double lo = 0.0;
  double hi = 1.0;
  double step = 1.0;
  std::vector<double> ticks;
  double p0 = 0.0;
  double p1 = 1.0;
  double T(double v) const { return scale == AxisScale::kLog ? std::log10(v) : v; }
  double operator()(double v) const { return p0 + (T(v) - T(lo)) / (T(hi) - T(lo)) * (p1 - p0); }
  bool Valid(double v) const { return std::isfinite(v) && (scale == AxisScale::kLinear || v > 0); }
};

AxisMap SettleAxis(const AxisSpec& spec, double data_lo, double data_hi) {
  AxisMap a;
  a.scale = spec.scale;
  double lo = std::isfinite(spec.lo) ? spec.lo : data_lo;
  double hi = std::isfinite(spec.hi) ? spec.hi : data_hi;
  if (spec.include_zero && spec.scale == AxisScale::kLinear) {
    lo = std::min(lo, 0.0);
    hi = std::max(hi, 0.0);
  }
  if (spec.scale == AxisScale::kLog) {
    if (!(lo > 0) || !std::isfinite(lo)) lo = 1e-3;
    if (!(hi > lo)) hi = lo * 10.0;
    double e0 = std::floor(std::log10(lo) + 1e-9);
    double e1 = std::ceil(std::log10(hi) - 1e-9);
    if (e1 <= e0) e1 = e0 + 1;
    a.lo = std::pow(10.0, e0);
    a.hi = std::pow(10.0, e1);
    for (double e = e0; e <= e1 + 0.5; e += 1.0) {
      const double p = std::pow(10.0, e);
      a.ticks.push_back(p);
      // With few decades, 2 and 5 between them as well.
      if (e1 - e0 <= 2 && e < e1 - 0.5) {
        a.ticks.push_back(2 * p);
        a.ticks.push_back(5 * p);
      }
    }
    a.step = 10.0;
    return a;
  }
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0.0, hi = 1.0;
  // Integer axes (poses, rotations) label every integer up to 20 of them.
  const int target = spec.integer ? std::max(6, std::min(20, static_cast<int>(hi - lo))) : 6;
  NiceTicks t = MakeNiceTicks(lo, hi, target);
  if (spec.integer && t.step < 1.0) {
    t.step = 1.0;
    t.values.clear();
    t.lo = std::floor(lo);
    t.hi = std::ceil(hi);
    for (double v = t.lo; v <= t.hi + 0.5; v += 1.0) t.values.push_back(v);
  }
  // A fixed end stays where it was asked.
  a.lo = std::isfinite(spec.lo) ? spec.lo : t.lo;
  a.hi = std::isfinite(spec.hi) ? spec.hi : t.hi;
  a.step = t.step;
  for (double v : t.values) {
    if (v >= a.lo - 1e-9 * t.step && v <= a.hi + 1e-9 * t.step) a.ticks.push_back(v);
  }
  return a;
}

std::string LogTickLabel(double v) {
  const int e = static_cast<int>(std::floor(std::log10(v) + 1e-9));
  const double mantissa = v / std::pow(10.0, e);
  char b[32];
  if (e >= -4 && e <= 4) {
    std::snprintf(b, sizeof(b), "%.*f", std::max(0, -e), v);
  } else {
    std::snprintf(b, sizeof(b), "%.0fe%d", mantissa, e);
  }
  return b;
}

std::string Dash(bool dashed) { return dashed ? " stroke-dasharray='6 4'" : ""; }

std::string ClassAttr(const std::string& c) { return c.empty() ? "" : " class='" + c + "'"; }

std::string Title(const std::vector<std::string>& titles, size_t i) {
  if (i >= titles.size() || titles[i].empty()) return "";
  return "<title>" + HtmlEscape(titles[i]) + "</title>";
}

// The legend swatch of one series at (x, y).
std::string Swatch(const Series& s, double x, double y) {
  std::ostringstream o;
  switch (s.style) {
    case SeriesStyle::kLine:
      o << "<line x1='" << Px(x) << "' x2='" << Px(x + 18) << "' y1='" << Px(y) << "' y2='" << Px(y)
        << "' stroke='" << s.color << "' stroke-width='2'" << Dash(s.dashed) << "/>";
      break;
    case SeriesStyle::kPoints:
      o << "<circle cx='" << Px(x + 9) << "' cy='" << Px(y) << "' r='4' fill='" << s.color << "'/>";
      break;
    default:
      o << "<rect x='" << Px(x) << "' y='" << Px(y - 5) << "' width='18' height='10' fill='"
        << s.color << "' fill-opacity='" << std::max(0.35, s.opacity) << "'/>";
  }
  return o.str();
}

}  // namespace

NiceTicks MakeNiceTicks(double lo, double hi, int target) {
  NiceTicks t;
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0.0, hi = 1.0;
  if (!(hi > lo)) {
    const double d = lo == 0.0 ? 1.0 : 0.1 * std::fabs(lo);
    lo -= d;
    hi += d;
  }
  t.step = NiceStep((hi - lo) / std::max(1, target));
  const double k0 = std::floor(lo / t.step + 1e-9);
  const double k1 = std::ceil(hi / t.step - 1e-9);
  t.lo = k0 * t.step;
  t.hi = k1 * t.step;
  for (double k = k0; k <= k1 + 0.5; k += 1.0) {
    const double v = k * t.step;
    t.values.push_back(std::fabs(v) < 1e-12 * t.step ? 0.0 : v);
  }
  return t;
}

std::string TickLabel(double value, double step) {
  if (std::fabs(value) < 1e-9 * step) return "0";
  char b[48];
  const int step_exp = static_cast<int>(std::floor(std::log10(step) + 1e-9));
  if (step_exp < -4 || step_exp > 5) {
    const int value_exp = static_cast<int>(std::floor(std::log10(std::fabs(value)) + 1e-9));
    const int e = std::max(value_exp, step_exp);
    std::snprintf(b, sizeof(b), "%.*fe%d", std::max(0, e - step_exp), value / std::pow(10.0, e), e);
  } else {
    std::snprintf(b, sizeof(b), "%.*f", std::max(0, -step_exp), value);
  }
  return b;
}

namespace {

// The data's extent on both axes (series, their bounds, spans and rules),
// and whether any series has an end label or a legend entry.
struct PlotExtent {
  double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
  bool any_end_label = false;
  bool any_legend = false;
};

PlotExtent MeasureExtent(const Plot& plot) {
  PlotExtent e;
  for (const Span& s : plot.spans) e.any_legend |= !s.legend.empty();
  for (const Series& s : plot.series) {
    e.any_end_label |= !s.end_label.empty();
    e.any_legend |= !s.name.empty();
    if (s.style == SeriesStyle::kBars) {
      for (double x : s.x) {
        Extend(x - s.bar_width / 2, &e.x_lo, &e.x_hi);
        Extend(x + s.bar_width / 2, &e.x_lo, &e.x_hi);
      }
      Extend(0.0, &e.y_lo, &e.y_hi);
    } else {
      ExtendAll(s.x, &e.x_lo, &e.x_hi);
    }
    if (s.style == SeriesStyle::kSteps) Extend(0.0, &e.y_lo, &e.y_hi);
    for (const std::vector<double>* v : {&s.y, &s.lo, &s.hi}) {
      for (double y : *v) {
        if (plot.y.scale == AxisScale::kLog && !(y > 0)) continue;
        Extend(y, &e.y_lo, &e.y_hi);
      }
    }
  }
  for (const Span& s : plot.spans) {
    Extend(s.x0, &e.x_lo, &e.x_hi);
    Extend(s.x1, &e.x_lo, &e.x_hi);
  }
  for (const Rule& r : plot.rules) {
    if (r.vertical) {
      Extend(r.value, &e.x_lo, &e.x_hi);
    } else {
      Extend(r.value, &e.y_lo, &e.y_hi);
    }
  }
  return e;
}

// Where the plotting area sits in the picture (margins, pixels) and the
// two axes mapping data into it (x from 0 to w, y from h up to 0).
struct PlotFrame {
  double left = 84, top = 34, w = 0, h = 0;
  AxisMap xa, ya;
};

PlotFrame LayOut(const Plot& plot, const PlotExtent& e) {
  PlotFrame f;
  const double right = e.any_end_label ? 200 : 24, bottom = 50;
  f.top = e.any_legend ? 50 : 34;
  f.w = plot.width - f.left - right;
  f.h = plot.height - f.top - bottom;
  f.xa = SettleAxis(plot.x, e.x_lo, e.x_hi);
  f.ya = SettleAxis(plot.y, e.y_lo, e.y_hi);
  f.xa.p0 = 0;
  f.xa.p1 = f.w;
  f.ya.p0 = f.h;
  f.ya.p1 = 0;
  return f;
}

// The grid, the ticks and the axis labels.
void WriteAxes(const Plot& plot, const PlotFrame& f, std::ostringstream& o) {
  const AxisMap &xa = f.xa, &ya = f.ya;
  const double left = f.left, top = f.top, w = f.w, h = f.h;
  o << "<g class='axis' data-axis='x' data-scale='"
    << (xa.scale == AxisScale::kLog ? "log" : "linear") << "'>";
  for (double v : xa.ticks) {
    const double px = left + xa(v);
    o << "<line x1='" << Px(px) << "' x2='" << Px(px) << "' y1='" << Px(top) << "' y2='"
      << Px(top + h) << "' class='grid'/><text x='" << Px(px) << "' y='" << Px(top + h + 17)
      << "' class='tick' text-anchor='middle'>"
      << (xa.scale == AxisScale::kLog ? LogTickLabel(v) : TickLabel(v, xa.step)) << "</text>";
  }
  o << "<text x='" << Px(left + w / 2) << "' y='" << Px(plot.height - 8)
    << "' class='axis-label' text-anchor='middle'>" << HtmlEscape(plot.x.label) << "</text></g>";
  o << "<g class='axis' data-axis='y' data-scale='"
    << (ya.scale == AxisScale::kLog ? "log" : "linear") << "'>";
  for (double v : ya.ticks) {
    const double py = top + ya(v);
    o << "<line x1='" << Px(left) << "' x2='" << Px(left + w) << "' y1='" << Px(py) << "' y2='"
      << Px(py) << "' class='grid'/><text x='" << Px(left - 6) << "' y='" << Px(py + 4)
      << "' class='tick' text-anchor='end'>"
      << (ya.scale == AxisScale::kLog ? LogTickLabel(v) : TickLabel(v, ya.step)) << "</text>";
  }
  const double ly = top + h / 2;
  o << "<text x='16' y='" << Px(ly)
    << "' class='axis-label' text-anchor='middle' transform='rotate(-90 16 " << Px(ly) << ")'>"
    << HtmlEscape(plot.y.label) << "</text></g>";
}

// Shaded x ranges with their labels.
void WriteSpans(const Plot& plot, const PlotFrame& f, std::ostringstream& o) {
  for (const Span& s : plot.spans) {
    if (!f.xa.Valid(s.x0) || !f.xa.Valid(s.x1)) continue;
    const double a = f.xa(s.x0), b = f.xa(s.x1);
    o << "<g" << ClassAttr(s.css_class) << "><rect x='" << Px(a) << "' y='0' width='"
      << Px(std::max(1.0, b - a)) << "' height='" << Px(f.h) << "' fill='" << s.color
      << "' fill-opacity='0.18'>"
      << (s.title.empty() ? "" : "<title>" + HtmlEscape(s.title) + "</title>") << "</rect>";
    if (!s.label.empty()) {
      o << "<text x='" << Px((a + b) / 2) << "' y='13' class='span-label' text-anchor='middle'>"
        << HtmlEscape(s.label) << "</text>";
    }
    o << "</g>";
  }
}

// A band between lo and hi: along hi forwards, back along lo.
void WriteEnvelope(const Series& s, const PlotFrame& f, std::ostringstream& o) {
  std::ostringstream path;
  bool first = true;
  for (size_t i = 0; i < s.x.size() && i < s.hi.size(); ++i) {
    if (!f.xa.Valid(s.x[i]) || !f.ya.Valid(s.hi[i])) continue;
    path << (first ? "M" : "L") << Px(f.xa(s.x[i])) << " " << Px(f.ya(s.hi[i]));
    first = false;
  }
  for (size_t i = std::min(s.x.size(), s.lo.size()); i-- > 0;) {
    if (!f.xa.Valid(s.x[i]) || !f.ya.Valid(s.lo[i])) continue;
    path << "L" << Px(f.xa(s.x[i])) << " " << Px(f.ya(s.lo[i]));
  }
  if (!first) {
    o << "<path" << ClassAttr(s.css_class) << " d='" << path.str() << "Z' fill='" << s.color
      << "' fill-opacity='" << s.opacity << "' stroke='" << s.color << "' stroke-width='0.6'/>";
  }
}

void WriteLine(const Series& s, const PlotFrame& f, std::ostringstream& o) {
  std::ostringstream pts;
  size_t count = 0;
  for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
    if (!f.xa.Valid(s.x[i]) || !f.ya.Valid(s.y[i])) continue;
    pts << (count++ ? " " : "") << Px(f.xa(s.x[i])) << "," << Px(f.ya(s.y[i]));
  }
  if (count > 0) {
    o << "<polyline" << ClassAttr(s.css_class) << " points='" << pts.str()
      << "' fill='none' stroke='" << s.color << "' stroke-width='1.6' stroke-opacity='" << s.opacity
      << "'" << Dash(s.dashed) << "/>";
  }
}

// Points, each with its error bar from lo to hi when both are given.
void WritePoints(const Series& s, const PlotFrame& f, std::ostringstream& o) {
  for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
    if (!f.xa.Valid(s.x[i]) || !f.ya.Valid(s.y[i])) continue;
    const double px = f.xa(s.x[i]), py = f.ya(s.y[i]);
    if (i < s.lo.size() && i < s.hi.size() && f.ya.Valid(s.lo[i]) && f.ya.Valid(s.hi[i])) {
      const double a = f.ya(s.lo[i]), b = f.ya(s.hi[i]);
      o << "<path d='M" << Px(px) << " " << Px(a) << "V" << Px(b) << "M" << Px(px - 3) << " "
        << Px(a) << "h6M" << Px(px - 3) << " " << Px(b) << "h6' stroke='" << s.color
        << "' fill='none'/>";
    }
    o << "<circle" << ClassAttr(s.css_class) << " cx='" << Px(px) << "' cy='" << Px(py)
      << "' r='4' fill='" << s.color << "' fill-opacity='" << s.opacity << "'>"
      << Title(s.titles, i) << "</circle>";
  }
}

// Bars from zero (or the nearest edge of the y range) to each value.
void WriteBars(const Series& s, const PlotFrame& f, std::ostringstream& o) {
  const AxisMap &xa = f.xa, &ya = f.ya;
  for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
    if (!xa.Valid(s.x[i]) || !ya.Valid(s.y[i])) continue;
    const double a = xa(s.x[i] - s.bar_width / 2), b = xa(s.x[i] + s.bar_width / 2);
    const double y0 = ya(std::max(ya.lo, std::min(ya.hi, 0.0))), y1 = ya(s.y[i]);
    o << "<rect" << ClassAttr(s.css_class) << " x='" << Px(a) << "' y='" << Px(std::min(y0, y1))
      << "' width='" << Px(std::max(1.0, b - a)) << "' height='" << Px(std::fabs(y1 - y0))
      << "' fill='" << s.color << "' fill-opacity='" << s.opacity << "'>" << Title(s.titles, i)
      << "</rect>";
  }
}

// A histogram: the positive value of bin i over [x_i, x_i+1).
void WriteSteps(const Series& s, const PlotFrame& f, std::ostringstream& o) {
  for (size_t i = 0; i + 1 < s.x.size() && i < s.y.size(); ++i) {
    if (!(s.y[i] > 0)) continue;
    const double a = f.xa(s.x[i]), b = f.xa(s.x[i + 1]), y0 = f.ya(0.0), y1 = f.ya(s.y[i]);
    o << "<rect" << ClassAttr(s.css_class) << " x='" << Px(a) << "' y='" << Px(y1) << "' width='"
      << Px(std::max(1.0, b - a - 1)) << "' height='" << Px(y0 - y1) << "' fill='" << s.color
      << "' fill-opacity='" << s.opacity << "'>" << Title(s.titles, i) << "</rect>";
  }
}

void WriteSeries(const Series& s, const PlotFrame& f, std::ostringstream& o) {
  switch (s.style) {
    case SeriesStyle::kEnvelope:
      return WriteEnvelope(s, f, o);
    case SeriesStyle::kLine:
      return WriteLine(s, f, o);
    case SeriesStyle::kPoints:
      return WritePoints(s, f, o);
    case SeriesStyle::kBars:
      return WriteBars(s, f, o);
    case SeriesStyle::kSteps:
      return WriteSteps(s, f, o);
  }
}

// Vertical and horizontal reference lines with their labels.
void WriteRules(const Plot& plot, const PlotFrame& f, std::ostringstream& o) {
  for (const Rule& r : plot.rules) {
    if (r.vertical) {
      if (!f.xa.Valid(r.value)) continue;
      const double px = f.xa(r.value);
      o << "<line x1='" << Px(px) << "' x2='" << Px(px) << "' y1='0' y2='" << Px(f.h)
        << "' stroke='" << r.color << "' stroke-width='1.4'" << Dash(r.dashed) << "/>";
      if (!r.label.empty()) {
        o << "<text x='" << Px(px + 3) << "' y='" << Px(f.h - 6) << "' class='rule-label' fill='"
          << r.color << "'>" << HtmlEscape(r.label) << "</text>";
      }
    } else {
      if (!f.ya.Valid(r.value)) continue;
      const double py = f.ya(r.value);
      o << "<line x1='0' x2='" << Px(f.w) << "' y1='" << Px(py) << "' y2='" << Px(py)
        << "' stroke='" << r.color << "' stroke-width='1.4'" << Dash(r.dashed) << "/>";
      if (!r.label.empty()) {
        // Below a line under zero, above one over it: +-k pairs stay apart.
        o << "<text x='" << Px(f.w - 4) << "' y='" << Px(r.value < 0 ? py + 13 : py - 4)
          << "' class='rule-label' text-anchor='end' fill='" << r.color << "'>"
          << HtmlEscape(r.label) << "</text>";
      }
    }
  }
}

// The plotting area, which clips what lies outside a fixed range: spans,
// series, rules, then its border.
void WriteArea(const Plot& plot, const PlotFrame& f, std::ostringstream& o) {
  o << "<svg x='" << Px(f.left) << "' y='" << Px(f.top) << "' width='" << Px(f.w) << "' height='"
    << Px(f.h) << "' class='area'>";
  WriteSpans(plot, f, o);
  for (const Series& s : plot.series) WriteSeries(s, f, o);
  WriteRules(plot, f, o);
  o << "</svg><rect x='" << Px(f.left) << "' y='" << Px(f.top) << "' width='" << Px(f.w)
    << "' height='" << Px(f.h) << "' fill='none' stroke='#666'/>";
}

// Labels at the end of lines, in the right margin, kept apart.
void WriteEndLabels(const Plot& plot, const PlotFrame& f, std::ostringstream& o) {
  std::vector<std::pair<double, std::string>> ends;
  for (const Series& s : plot.series) {
    if (s.end_label.empty()) continue;
    for (size_t i = std::min(s.x.size(), s.y.size()); i-- > 0;) {
      // The last point inside the area (a term's line may leave it).
      if (!f.xa.Valid(s.x[i]) || !f.ya.Valid(s.y[i])) continue;
      const double py = f.ya(s.y[i]);
      if (py < 0 || py > f.h) continue;
      ends.push_back(
          {f.top + py, "<tspan fill='" + s.color + "'>" + HtmlEscape(s.end_label) + "</tspan>"});
      break;
    }
  }
  std::sort(ends.begin(), ends.end());
  double last = -1e9;
  for (auto& e : ends) {
    e.first = std::max(e.first, last + 13);
    last = e.first;
    o << "<text x='" << Px(f.left + f.w + 6) << "' y='" << Px(e.first + 4) << "' class='end-label'>"
      << e.second << "</text>";
  }
}

// The legend above the area: named series, then each span legend once.
void WriteLegend(const Plot& plot, const PlotFrame& f, std::ostringstream& o) {
  double lx = f.left;
  for (const Series& s : plot.series) {
    if (s.name.empty()) continue;
    o << "<g class='legend'>" << Swatch(s, lx, f.top - 10) << "<text x='" << Px(lx + 23) << "' y='"
      << Px(f.top - 6) << "'>" << HtmlEscape(s.name) << "</text></g>";
    lx += 36 + 7.2 * s.name.size();
  }
  std::vector<std::string> span_legends;
  for (const Span& s : plot.spans) {
    if (s.legend.empty() ||
        std::find(span_legends.begin(), span_legends.end(), s.legend) != span_legends.end()) {
      continue;
    }
    span_legends.push_back(s.legend);
    o << "<g class='legend'><rect x='" << Px(lx) << "' y='" << Px(f.top - 15)
      << "' width='18' height='10' fill='" << s.color << "' fill-opacity='0.35'/><text x='"
      << Px(lx + 23) << "' y='" << Px(f.top - 6) << "'>" << HtmlEscape(s.legend) << "</text></g>";
    lx += 36 + 7.2 * s.legend.size();
  }
}

}  // namespace

std::string RenderPlot(const Plot& plot) {
  const PlotFrame frame = LayOut(plot, MeasureExtent(plot));
  std::ostringstream o;
  o << "<svg xmlns='http://www.w3.org/2000/svg' class='plot" << (plot.css_class.empty() ? "" : " ")
    << plot.css_class << "' width='" << plot.width << "' height='" << plot.height
    << "' viewBox='0 0 " << plot.width << " " << plot.height << "'>";
  o << "<text x='" << Px(frame.left + frame.w / 2) << "' y='20' class='plot-title'>"
    << HtmlEscape(plot.title) << "</text>";
  WriteAxes(plot, frame, o);
  WriteArea(plot, frame, o);
  WriteEndLabels(plot, frame, o);
  WriteLegend(plot, frame, o);
  o << "</svg>";
  return o.str();
}

Series MinMaxEnvelope(const std::vector<double>& x, const std::vector<double>& y, int columns) {
  Series s;
  const size_t n = std::min(x.size(), y.size());
  if (n <= 2 * static_cast<size_t>(std::max(columns, 1))) {
    s.style = SeriesStyle::kLine;
    s.x.assign(x.begin(), x.begin() + n);
    s.y.assign(y.begin(), y.begin() + n);
    return s;
  }
  s.style = SeriesStyle::kEnvelope;
  const double x0 = x[0], x1 = x[n - 1];
  const double width = (x1 - x0) / columns;
  size_t i = 0;
  for (int c = 0; c < columns && i < n; ++c) {
    const double end = c + 1 == columns ? INFINITY : x0 + (c + 1) * width;
    double lo = INFINITY, hi = -INFINITY;
    for (; i < n && x[i] < end; ++i) Extend(y[i], &lo, &hi);
    if (!(hi >= lo)) continue;
    s.x.push_back(x0 + (c + 0.5) * width);
    s.lo.push_back(lo);
    s.hi.push_back(hi);
  }
  return s;
}

}  // namespace internal
}  // namespace gravcal
