// The report figures that are not x-y plots: the correlation heat map and
// the pose directions on two hemispheres (svg_plot.h).
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "workflows/report/svg_plot.h"

namespace gravcal {
namespace internal {

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

}  // namespace internal
}  // namespace gravcal
