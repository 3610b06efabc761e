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

namespace {

// Pixel coordinates with one decimal: enough for the screen, small files.
std::string Px(double v) {
  char b[32];
  std::snprintf(b, sizeof(b), "%.1f", v);
  return b;
}

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

std::string RenderPlot(const Plot& plot) {
  bool any_end_label = false;
  bool any_legend = false;
  for (const Span& s : plot.spans) any_legend |= !s.legend.empty();
  double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
  for (const Series& s : plot.series) {
    any_end_label |= !s.end_label.empty();
    any_legend |= !s.name.empty();
    if (s.style == SeriesStyle::kBars) {
      for (double x : s.x) {
        Extend(x - s.bar_width / 2, &x_lo, &x_hi);
        Extend(x + s.bar_width / 2, &x_lo, &x_hi);
      }
      Extend(0.0, &y_lo, &y_hi);
    } else {
      ExtendAll(s.x, &x_lo, &x_hi);
    }
    if (s.style == SeriesStyle::kSteps) Extend(0.0, &y_lo, &y_hi);
    for (const std::vector<double>* v : {&s.y, &s.lo, &s.hi}) {
      for (double y : *v) {
        if (plot.y.scale == AxisScale::kLog && !(y > 0)) continue;
        Extend(y, &y_lo, &y_hi);
      }
    }
  }
  for (const Span& s : plot.spans) {
    Extend(s.x0, &x_lo, &x_hi);
    Extend(s.x1, &x_lo, &x_hi);
  }
  for (const Rule& r : plot.rules) {
    if (r.vertical) {
      Extend(r.value, &x_lo, &x_hi);
    } else {
      Extend(r.value, &y_lo, &y_hi);
    }
  }
  const double left = 84, right = any_end_label ? 200 : 24, top = any_legend ? 50 : 34, bottom = 50;
  const double w = plot.width - left - right, h = plot.height - top - bottom;
  AxisMap xa = SettleAxis(plot.x, x_lo, x_hi);
  AxisMap ya = SettleAxis(plot.y, y_lo, y_hi);
  xa.p0 = 0;
  xa.p1 = w;
  ya.p0 = h;
  ya.p1 = 0;

  std::ostringstream o;
  o << "<svg xmlns='http://www.w3.org/2000/svg' class='plot" << (plot.css_class.empty() ? "" : " ")
    << plot.css_class << "' width='" << plot.width << "' height='" << plot.height
    << "' viewBox='0 0 " << plot.width << " " << plot.height << "'>";
  o << "<text x='" << Px(left + w / 2) << "' y='20' class='plot-title'>" << HtmlEscape(plot.title)
    << "</text>";

  // Grid and ticks.
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

  // The plotting area clips what lies outside a fixed range.
  o << "<svg x='" << Px(left) << "' y='" << Px(top) << "' width='" << Px(w) << "' height='" << Px(h)
    << "' class='area'>";
  for (const Span& s : plot.spans) {
    if (!xa.Valid(s.x0) || !xa.Valid(s.x1)) continue;
    const double a = xa(s.x0), b = xa(s.x1);
    o << "<g" << ClassAttr(s.css_class) << "><rect x='" << Px(a) << "' y='0' width='"
      << Px(std::max(1.0, b - a)) << "' height='" << Px(h) << "' fill='" << s.color
      << "' fill-opacity='0.18'>"
      << (s.title.empty() ? "" : "<title>" + HtmlEscape(s.title) + "</title>") << "</rect>";
    if (!s.label.empty()) {
      o << "<text x='" << Px((a + b) / 2) << "' y='13' class='span-label' text-anchor='middle'>"
        << HtmlEscape(s.label) << "</text>";
    }
    o << "</g>";
  }
  for (const Series& s : plot.series) {
    const std::string cls = ClassAttr(s.css_class);
    switch (s.style) {
      case SeriesStyle::kEnvelope: {
        std::ostringstream path;
        bool first = true;
        for (size_t i = 0; i < s.x.size() && i < s.hi.size(); ++i) {
          if (!xa.Valid(s.x[i]) || !ya.Valid(s.hi[i])) continue;
          path << (first ? "M" : "L") << Px(xa(s.x[i])) << " " << Px(ya(s.hi[i]));
          first = false;
        }
        for (size_t i = std::min(s.x.size(), s.lo.size()); i-- > 0;) {
          if (!xa.Valid(s.x[i]) || !ya.Valid(s.lo[i])) continue;
          path << "L" << Px(xa(s.x[i])) << " " << Px(ya(s.lo[i]));
        }
        if (!first) {
          o << "<path" << cls << " d='" << path.str() << "Z' fill='" << s.color
            << "' fill-opacity='" << s.opacity << "' stroke='" << s.color
            << "' stroke-width='0.6'/>";
        }
        break;
      }
      case SeriesStyle::kLine: {
        std::ostringstream pts;
        size_t count = 0;
        for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
          if (!xa.Valid(s.x[i]) || !ya.Valid(s.y[i])) continue;
          pts << (count++ ? " " : "") << Px(xa(s.x[i])) << "," << Px(ya(s.y[i]));
        }
        if (count > 0) {
          o << "<polyline" << cls << " points='" << pts.str() << "' fill='none' stroke='" << s.color
            << "' stroke-width='1.6' stroke-opacity='" << s.opacity << "'" << Dash(s.dashed)
            << "/>";
        }
        break;
      }
      case SeriesStyle::kPoints:
        for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
          if (!xa.Valid(s.x[i]) || !ya.Valid(s.y[i])) continue;
          const double px = xa(s.x[i]), py = ya(s.y[i]);
          if (i < s.lo.size() && i < s.hi.size() && ya.Valid(s.lo[i]) && ya.Valid(s.hi[i])) {
            const double a = ya(s.lo[i]), b = ya(s.hi[i]);
            o << "<path d='M" << Px(px) << " " << Px(a) << "V" << Px(b) << "M" << Px(px - 3) << " "
              << Px(a) << "h6M" << Px(px - 3) << " " << Px(b) << "h6' stroke='" << s.color
              << "' fill='none'/>";
          }
          o << "<circle" << cls << " cx='" << Px(px) << "' cy='" << Px(py) << "' r='4' fill='"
            << s.color << "' fill-opacity='" << s.opacity << "'>" << Title(s.titles, i)
            << "</circle>";
        }
        break;
      case SeriesStyle::kBars:
        for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
          if (!xa.Valid(s.x[i]) || !ya.Valid(s.y[i])) continue;
          const double a = xa(s.x[i] - s.bar_width / 2), b = xa(s.x[i] + s.bar_width / 2);
          const double y0 = ya(std::max(ya.lo, std::min(ya.hi, 0.0))), y1 = ya(s.y[i]);
          o << "<rect" << cls << " x='" << Px(a) << "' y='" << Px(std::min(y0, y1)) << "' width='"
            << Px(std::max(1.0, b - a)) << "' height='" << Px(std::fabs(y1 - y0)) << "' fill='"
            << s.color << "' fill-opacity='" << s.opacity << "'>" << Title(s.titles, i)
            << "</rect>";
        }
        break;
      case SeriesStyle::kSteps:
        for (size_t i = 0; i + 1 < s.x.size() && i < s.y.size(); ++i) {
          if (!(s.y[i] > 0)) continue;
          const double a = xa(s.x[i]), b = xa(s.x[i + 1]), y0 = ya(0.0), y1 = ya(s.y[i]);
          o << "<rect" << cls << " x='" << Px(a) << "' y='" << Px(y1) << "' width='"
            << Px(std::max(1.0, b - a - 1)) << "' height='" << Px(y0 - y1) << "' fill='" << s.color
            << "' fill-opacity='" << s.opacity << "'>" << Title(s.titles, i) << "</rect>";
        }
        break;
    }
  }
  for (const Rule& r : plot.rules) {
    if (r.vertical) {
      if (!xa.Valid(r.value)) continue;
      const double px = xa(r.value);
      o << "<line x1='" << Px(px) << "' x2='" << Px(px) << "' y1='0' y2='" << Px(h) << "' stroke='"
        << r.color << "' stroke-width='1.4'" << Dash(r.dashed) << "/>";
      if (!r.label.empty()) {
        o << "<text x='" << Px(px + 3) << "' y='" << Px(h - 6) << "' class='rule-label' fill='"
          << r.color << "'>" << HtmlEscape(r.label) << "</text>";
      }
    } else {
      if (!ya.Valid(r.value)) continue;
      const double py = ya(r.value);
      o << "<line x1='0' x2='" << Px(w) << "' y1='" << Px(py) << "' y2='" << Px(py) << "' stroke='"
        << r.color << "' stroke-width='1.4'" << Dash(r.dashed) << "/>";
      if (!r.label.empty()) {
        // Below a line under zero, above one over it: +-k pairs stay apart.
        o << "<text x='" << Px(w - 4) << "' y='" << Px(r.value < 0 ? py + 13 : py - 4)
          << "' class='rule-label' text-anchor='end' fill='" << r.color << "'>"
          << HtmlEscape(r.label) << "</text>";
      }
    }
  }
  o << "</svg><rect x='" << Px(left) << "' y='" << Px(top) << "' width='" << Px(w) << "' height='"
    << Px(h) << "' fill='none' stroke='#666'/>";

  // Labels at the end of lines, in the right margin, kept apart.
  std::vector<std::pair<double, std::string>> ends;
  for (const Series& s : plot.series) {
    if (s.end_label.empty()) continue;
    for (size_t i = std::min(s.x.size(), s.y.size()); i-- > 0;) {
      // The last point inside the area (a term's line may leave it).
      if (!xa.Valid(s.x[i]) || !ya.Valid(s.y[i])) continue;
      const double py = ya(s.y[i]);
      if (py < 0 || py > h) continue;
      ends.push_back(
          {top + py, "<tspan fill='" + s.color + "'>" + HtmlEscape(s.end_label) + "</tspan>"});
      break;
    }
  }
  std::sort(ends.begin(), ends.end());
  double last = -1e9;
  for (auto& e : ends) {
    e.first = std::max(e.first, last + 13);
    last = e.first;
    o << "<text x='" << Px(left + w + 6) << "' y='" << Px(e.first + 4) << "' class='end-label'>"
      << e.second << "</text>";
  }

  // Legend above the area.
  double lx = left;
  for (const Series& s : plot.series) {
    if (s.name.empty()) continue;
    o << "<g class='legend'>" << Swatch(s, lx, top - 10) << "<text x='" << Px(lx + 23) << "' y='"
      << Px(top - 6) << "'>" << HtmlEscape(s.name) << "</text></g>";
    lx += 36 + 7.2 * s.name.size();
  }
  std::vector<std::string> span_legends;
  for (const Span& s : plot.spans) {
    if (s.legend.empty() ||
        std::find(span_legends.begin(), span_legends.end(), s.legend) != span_legends.end()) {
      continue;
    }
    span_legends.push_back(s.legend);
    o << "<g class='legend'><rect x='" << Px(lx) << "' y='" << Px(top - 15)
      << "' width='18' height='10' fill='" << s.color << "' fill-opacity='0.35'/><text x='"
      << Px(lx + 23) << "' y='" << Px(top - 6) << "'>" << HtmlEscape(s.legend) << "</text></g>";
    lx += 36 + 7.2 * s.legend.size();
  }
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

std::string RenderHeatMap(const std::string& title, const std::vector<std::string>& names,
                          const Eigen::MatrixXd& values) {
  const int n = static_cast<int>(names.size());
  const double cell = n <= 12 ? 34 : std::max(12.0, 420.0 / n);
  const double left = 110, top = 110;
  const double size = cell * n;
  const int width = static_cast<int>(left + size + 110), height = static_cast<int>(top + size + 20);
  auto color = [](double v) {
    v = std::max(-1.0, std::min(1.0, v));
    const int a = static_cast<int>(255 * (1 - std::fabs(v)));
    char b[16];
    if (v >= 0) {
      std::snprintf(b, sizeof(b), "#%02x%02x%02x", 214 + (41 * a) / 255, a, a);
    } else {
      std::snprintf(b, sizeof(b), "#%02x%02x%02x", a, (119 * (255 - a) + 255 * a) / 255, 255);
    }
    return std::string(b);
  };
  std::ostringstream o;
  o << "<svg xmlns='http://www.w3.org/2000/svg' class='plot heatmap' width='" << width
    << "' height='" << height << "'><text x='" << Px(left + size / 2) << "' y='18' "
    << "class='plot-title'>" << HtmlEscape(title) << "</text>";
  for (int i = 0; i < n && i < values.rows(); ++i) {
    o << "<text x='" << Px(left - 5) << "' y='" << Px(top + (i + 0.5) * cell + 4)
      << "' class='cell-name' text-anchor='end'>" << HtmlEscape(names[i]) << "</text>";
    const double cx = left + (i + 0.5) * cell;
    o << "<text x='" << Px(cx) << "' y='" << Px(top - 5)
      << "' class='cell-name' transform='rotate(-60 " << Px(cx) << " " << Px(top - 5) << ")'>"
      << HtmlEscape(names[i]) << "</text>";
    for (int j = 0; j < n && j < values.cols(); ++j) {
      const double v = values(i, j);
      o << "<rect class='cell' x='" << Px(left + j * cell) << "' y='" << Px(top + i * cell)
        << "' width='" << Px(cell) << "' height='" << Px(cell) << "' fill='"
        << (std::isfinite(v) ? color(v) : "#ddd") << "' stroke='#fff'><title>"
        << HtmlEscape(names[i] + " / " + names[j]) << ": " << FormatNumber(v, "%.3f")
        << "</title></rect>";
      if (n <= 12 && std::isfinite(v)) {
        o << "<text x='" << Px(left + (j + 0.5) * cell) << "' y='" << Px(top + (i + 0.5) * cell + 4)
          << "' class='cell-value' text-anchor='middle'>" << FormatNumber(v, "%.2f") << "</text>";
      }
    }
  }
  // Colour bar with its own (round) ticks.
  const double bx = left + size + 30, bw = 16;
  o << "<g class='axis' data-axis='y' data-scale='linear'>";
  for (int k = 0; k < 40; ++k) {
    const double v = 1.0 - 2.0 * (k + 0.5) / 40;
    o << "<rect x='" << Px(bx) << "' y='" << Px(top + k * size / 40) << "' width='" << Px(bw)
      << "' height='" << Px(size / 40 + 0.5) << "' fill='" << color(v) << "'/>";
  }
  for (int k = 0; k <= 4; ++k) {
    const double v = 1.0 - 0.5 * k;
    o << "<text x='" << Px(bx + bw + 4) << "' y='" << Px(top + k * size / 4 + 4)
      << "' class='tick'>" << TickLabel(v, 0.5) << "</text>";
  }
  o << "</g></svg>";
  return o.str();
}

std::string RenderSphere(const std::string& title, const std::vector<Eigen::Vector3d>& directions,
                         const std::vector<std::string>& labels) {
  const double r = 120, cy = 175;
  const double cx[2] = {160, 460};
  std::ostringstream o;
  o << "<svg xmlns='http://www.w3.org/2000/svg' class='plot sphere' width='620' height='330'>"
    << "<text x='310' y='20' class='plot-title'>" << HtmlEscape(title) << "</text>";
  const char* names[2] = {"z >= 0 (seen from +z)", "z < 0 (seen through from +z)"};
  for (int half = 0; half < 2; ++half) {
    o << "<text x='" << Px(cx[half]) << "' y='44' text-anchor='middle' class='axis-label'>"
      << names[half] << "</text>";
    for (double deg : {90.0, 60.0, 30.0}) {
      const double rr = r * std::sqrt(2.0) * std::sin(deg * M_PI / 360.0);
      o << "<circle cx='" << Px(cx[half]) << "' cy='" << Px(cy) << "' r='" << Px(rr) << "' fill='"
        << (deg == 90.0 ? "#f7f7f7" : "none") << "' stroke='#bbb'/>";
    }
    o << "<line x1='" << Px(cx[half] - r) << "' x2='" << Px(cx[half] + r) << "' y1='" << Px(cy)
      << "' y2='" << Px(cy) << "' stroke='#ddd'/><line x1='" << Px(cx[half]) << "' x2='"
      << Px(cx[half]) << "' y1='" << Px(cy - r) << "' y2='" << Px(cy + r) << "' stroke='#ddd'/>"
      << "<text x='" << Px(cx[half] + r + 4) << "' y='" << Px(cy + 4)
      << "' class='cell-name'>+x</text>"
      << "<text x='" << Px(cx[half] - 6) << "' y='" << Px(cy - r - 4)
      << "' class='cell-name'>+y</text>";
  }
  for (size_t k = 0; k < directions.size(); ++k) {
    const Eigen::Vector3d d = directions[k].normalized();
    if (!d.allFinite()) continue;
    const int half = d.z() >= 0 ? 0 : 1;
    // Lambert equal-area: distance from the pole 2 sin(theta / 2), scaled so
    // the equator is the rim.
    const double rho = std::sqrt(std::max(0.0, 1.0 - std::fabs(d.z())));
    const double planar = std::hypot(d.x(), d.y());
    const double ux = planar > 1e-12 ? d.x() / planar : 0.0;
    const double uy = planar > 1e-12 ? d.y() / planar : 0.0;
    const double px = cx[half] + r * rho * ux, py = cy - r * rho * uy;
    const std::string label = k < labels.size() ? labels[k] : std::to_string(k + 1);
    o << "<g class='pose-dot'><circle cx='" << Px(px) << "' cy='" << Px(py)
      << "' r='10' fill='#1f77b4' fill-opacity='0.85'/><text x='" << Px(px) << "' y='" << Px(py + 4)
      << "' text-anchor='middle' class='dot-label'>" << HtmlEscape(label) << "</text></g>";
  }
  o << "</svg>";
  return o.str();
}

std::string HtmlEscape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string FormatNumber(double v, const char* format) {
  if (!std::isfinite(v)) return "&ndash;";
  char b[64];
  std::snprintf(b, sizeof(b), format, v);
  return b;
}

std::string HtmlPageStart(const std::string& title) {
  return "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'><title>" +
         HtmlEscape(title) +
         "</title><style>"
         "body{font-family:'DejaVu Sans',Arial,sans-serif;font-size:15px;max-width:1180px;"
         "margin:1em auto;padding:0 1em;color:#222;line-height:1.4}"
         "h1{font-size:1.6em}h2{font-size:1.25em;border-bottom:1px solid #ddd;margin-top:1.6em}"
         "table{border-collapse:collapse;margin:.5em 0}"
         "td,th{border:1px solid #ccc;padding:3px 8px;font-size:14px;text-align:left}"
         "th{background:#eee}td.num{text-align:right;font-family:monospace}"
         "svg.plot{margin:4px;background:#fff;border:1px solid #eee}"
         "svg text{font-family:'DejaVu Sans',Arial,sans-serif;font-size:12px;fill:#222}"
         "svg .plot-title{font-size:14px;font-weight:bold;text-anchor:middle}"
         "svg .axis-label{font-size:13px}svg .grid{stroke:#eee}"
         "svg .span-label,svg .dot-label{font-size:11px;font-weight:bold}"
         "svg .dot-label{fill:#fff}svg .cell-value{font-size:10px}svg .cell-name{font-size:11px}"
         "svg .end-label,svg .rule-label{font-size:11px}"
         ".verdict{font-size:1.15em;padding:.6em 1em;border-left:6px solid "
         "#1f77b4;background:#eef3f8}"
         ".verdict.good{background:#eaf6ea;border-color:#2ca02c}"
         ".verdict.look{background:#fff6e0;border-color:#e8a317}"
         ".verdict.again{background:#fde8e8;border-color:#d62728}"
         ".warn{color:#7a4200}.note{color:#555;font-size:.93em}"
         "</style></head><body>\n";
}

std::string HtmlPageEnd() {
  return "\n<script>window.addEventListener('load',function(){var b=document.body;"
         "b.setAttribute('data-load-ms',Math.round(performance.now()));"
         "b.setAttribute('data-height',document.documentElement.scrollHeight);});</script>\n"
         "</body></html>\n";
}

}  // namespace internal
}  // namespace gravcal
