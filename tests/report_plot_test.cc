// The reports' plotting module (src/workflows/report/svg_plot.h) without a
// browser: nice ticks, tick labels, min/max envelopes, and the plot's DOM
// contract (axes, spans).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "workflows/report/svg_plot.h"

namespace gravcal {
namespace internal {
namespace {

size_t Count(const std::string& text, const std::string& needle) {
  size_t n = 0;
  for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

TEST(NiceTicks, StepsAreOneTwoFiveAndCoverTheRange) {
  struct Case {
    double lo, hi, step;
  };
  // The old discovery report labelled [-0.5, 18.5] as -0.5, 9, 18.5 and
  // [0.151, 8.72] as 0.151, 4.44, 8.72.
  for (const Case& c :
       {Case{-0.5, 18.5, 5.0}, Case{0.151, 8.72, 2.0}, Case{0.0, 1.0, 0.2}, Case{9.79, 9.83, 0.01},
        Case{-3.5, 3.5, 2.0}, Case{0.0, 3600.0, 1000.0}, Case{1.2e-5, 9.7e-5, 2e-5}}) {
    const NiceTicks t = MakeNiceTicks(c.lo, c.hi, 6);
    EXPECT_NEAR(t.step, c.step, 1e-12 * c.step) << c.lo << " " << c.hi;
    EXPECT_LE(t.lo, c.lo + 1e-9 * t.step);  // a range ending on a tick keeps it
    EXPECT_GE(t.hi, c.hi - 1e-9 * t.step);
    EXPECT_LT(t.hi - t.lo, (c.hi - c.lo) + 2 * t.step);
    for (double v : t.values) EXPECT_NEAR(v / t.step, std::round(v / t.step), 1e-9);
  }
  // A flat range still gets ticks around it.
  const NiceTicks flat = MakeNiceTicks(9.81, 9.81, 6);
  EXPECT_LT(flat.lo, 9.81);
  EXPECT_GT(flat.hi, 9.81);
}

TEST(NiceTicks, LabelsHaveTheDigitsTheStepNeeds) {
  EXPECT_EQ(TickLabel(0.5, 0.5), "0.5");
  EXPECT_EQ(TickLabel(1.0, 0.5), "1.0");
  EXPECT_EQ(TickLabel(1000.0, 1000.0), "1000");
  EXPECT_EQ(TickLabel(9.82, 0.01), "9.82");
  EXPECT_EQ(TickLabel(-2e-17, 0.2), "0");
  EXPECT_EQ(TickLabel(4e-5, 2e-5), "4e-5");
  EXPECT_EQ(TickLabel(1.2e-4, 2e-5), "1.2e-4");
}

TEST(MinMaxEnvelope, KeepsEveryExtremeInFewColumns) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<double> t(720000), y(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    t[i] = i / 200.0;
    y[i] = noise(rng);
  }
  y[123456] = 40.0;  // a single spike must survive
  const Series s = MinMaxEnvelope(t, y, 700);
  EXPECT_EQ(s.style, SeriesStyle::kEnvelope);
  EXPECT_LE(s.x.size(), 700u);
  EXPECT_EQ(*std::max_element(s.hi.begin(), s.hi.end()), 40.0);
  EXPECT_EQ(*std::min_element(s.lo.begin(), s.lo.end()), *std::min_element(y.begin(), y.end()));
  // A short series is drawn as it is.
  const std::vector<double> tx = {0, 1, 2}, ty = {3, 4, 5};
  const Series line = MinMaxEnvelope(tx, ty, 700);
  EXPECT_EQ(line.style, SeriesStyle::kLine);
  EXPECT_EQ(line.y, ty);
}

TEST(RenderPlot, AxesSpansAndLegendInTheSvg) {
  Plot p;
  p.title = "t <&>";
  p.x.label = "time, s";
  p.y.label = "accelerometer, raw units";
  Series s;
  s.name = "x";
  s.x = {0, 10, 20};
  s.y = {-1, 2, 0.5};
  p.series.push_back(s);
  for (int k = 0; k < 3; ++k) {
    Span span;
    span.x0 = 5 * k;
    span.x1 = 5 * k + 2;
    span.label = std::to_string(k + 1);
    span.css_class = "static-interval";
    p.spans.push_back(span);
  }
  const std::string svg = RenderPlot(p);
  EXPECT_EQ(Count(svg, "class='static-interval'"), 3u);
  EXPECT_EQ(Count(svg, "class='axis' data-axis='x' data-scale='linear'"), 1u);
  EXPECT_EQ(Count(svg, "class='axis' data-axis='y' data-scale='linear'"), 1u);
  EXPECT_NE(svg.find("time, s"), std::string::npos);
  EXPECT_NE(svg.find("t &lt;&amp;&gt;"), std::string::npos);
  EXPECT_NE(svg.find("class='legend'"), std::string::npos);
  // y from -1 to 2: ticks -1, -0.5, ..., 2.
  EXPECT_NE(svg.find(">-0.5</text>"), std::string::npos);
  EXPECT_NE(svg.find(">2.0</text>"), std::string::npos);
  p.y.scale = AxisScale::kLog;
  p.series[0].y = {1e-4, 3e-3, 2e-2};
  const std::string log = RenderPlot(p);
  EXPECT_NE(log.find("data-scale='log'"), std::string::npos);
  EXPECT_NE(log.find(">0.0001</text>"), std::string::npos);
  EXPECT_NE(log.find(">0.1</text>"), std::string::npos);
}

}  // namespace
}  // namespace internal
}  // namespace gravcal
