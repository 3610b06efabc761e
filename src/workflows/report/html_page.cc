// The HTML around the plots of every report (svg_plot.h): escaping, numbers,
// the page's head with its style sheet, and its end.
#include <cmath>
#include <cstdio>
#include <string>

#include "workflows/report/svg_plot.h"

namespace gravcal {
namespace internal {

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
