// The plan report (report.h, PlanToHtml).
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "gravcal/workflows/report.h"
#include "workflows/report/svg_plot.h"

namespace gravcal {
namespace {

using internal::FormatNumber;
using internal::HtmlEscape;

// The body-to-world rotation of a pose whose sensor-frame up is `up`: the
// shortest rotation taking up to the world's vertical (z).
Eigen::Matrix3d PoseRotation(const Eigen::Vector3d& up) {
  return Eigen::Quaterniond::FromTwoVectors(up.normalized(), Eigen::Vector3d::UnitZ())
      .toRotationMatrix();
}

// A small picture of the housing in one pose: a box (longest along x,
// flattest along z, so the faces can be told apart) seen from the front
// right and above, resting on a table line, with the housing's x, y and z
// axes as coloured arrows and the pose number. data-up states the up
// direction drawn (for tests/report_browser_test.cc).
std::string HousingPicture(const Eigen::Vector3d& up, int number) {
  const Eigen::Matrix3d r = PoseRotation(up);
  // Camera: looking along -view; screen right and screen up.
  const Eigen::Vector3d view = Eigen::Vector3d(1.0, -1.4, 0.9).normalized();
  const Eigen::Vector3d right = Eigen::Vector3d::UnitZ().cross(view).normalized();
  const Eigen::Vector3d screen_up = view.cross(right);
  const double size = 140.0, scale = 34.0, cx = size / 2, cy = size / 2 + 6;
  auto project = [&](const Eigen::Vector3d& body) {
    const Eigen::Vector3d w = r * body;
    return Eigen::Vector2d(cx + scale * w.dot(right), cy - scale * w.dot(screen_up));
  };
  const Eigen::Vector3d half(1.0, 0.7, 0.35);
  std::array<Eigen::Vector3d, 8> corners;
  for (int i = 0; i < 8; ++i) {
    corners[i] = Eigen::Vector3d((i & 1) ? half.x() : -half.x(), (i & 2) ? half.y() : -half.y(),
                                 (i & 4) ? half.z() : -half.z());
  }
  // The lowest corner rests on the table.
  double lowest = 0.0;
  for (const Eigen::Vector3d& c : corners) lowest = std::min(lowest, (r * c).z());
  std::ostringstream s;
  s << "<svg class='housing' data-up='" << FormatNumber(up.x(), "%.4f") << " "
    << FormatNumber(up.y(), "%.4f") << " " << FormatNumber(up.z(), "%.4f") << "' width='" << size
    << "' height='" << size << "' viewBox='0 0 " << size << " " << size
    << "' xmlns='http://www.w3.org/2000/svg'>";
  const double table_y = cy - scale * (lowest * Eigen::Vector3d::UnitZ()).dot(screen_up);
  s << "<line x1='8' y1='" << FormatNumber(table_y, "%.1f") << "' x2='" << size - 8 << "' y2='"
    << FormatNumber(table_y, "%.1f") << "' stroke='#bbb' stroke-width='3'/>";
  for (int i = 0; i < 8; ++i) {
    for (int bit : {1, 2, 4}) {
      const int j = i | bit;
      if (j == i) continue;
      const Eigen::Vector2d a = project(corners[i]), b = project(corners[j]);
      s << "<line class='housing-edge' x1='" << FormatNumber(a.x(), "%.1f") << "' y1='"
        << FormatNumber(a.y(), "%.1f") << "' x2='" << FormatNumber(b.x(), "%.1f") << "' y2='"
        << FormatNumber(b.y(), "%.1f") << "' stroke='#555' stroke-width='1.2'/>";
    }
  }
  const char* names = "xyz";
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector2d o = project(Eigen::Vector3d::Zero());
    const Eigen::Vector2d tip = project(1.45 * Eigen::Vector3d::Unit(a));
    s << "<line class='housing-axis' x1='" << FormatNumber(o.x(), "%.1f") << "' y1='"
      << FormatNumber(o.y(), "%.1f") << "' x2='" << FormatNumber(tip.x(), "%.1f") << "' y2='"
      << FormatNumber(tip.y(), "%.1f") << "' stroke='" << internal::kAxisColors[a]
      << "' stroke-width='2.5'/><text x='" << FormatNumber(tip.x() + 3, "%.1f") << "' y='"
      << FormatNumber(tip.y() - 3, "%.1f") << "' fill='" << internal::kAxisColors[a]
      << "' font-size='12'>" << names[a] << "</text>";
  }
  s << "<text x='6' y='16' font-size='14' font-weight='bold'>" << number << "</text></svg>";
  return s.str();
}

// One row per parameter: predicted sigma and target in readable units.
std::string SigmaTable(const std::string& caption, const SensorPrediction& prediction,
                       ReadableUnit (*unit_of)(const std::string&)) {
  const std::vector<std::string>& names = prediction.parameter_names;
  const Eigen::VectorXd& std = prediction.predicted_std_scale_free;
  const Eigen::VectorXd& targets = prediction.targets_scale_free;
  const std::vector<bool>& targeted = prediction.targeted;
  std::ostringstream s;
  s << "<table class='sigma'><caption>" << HtmlEscape(caption)
    << "</caption><tr><th>parameter</th><th>predicted sigma</th><th>target</th></tr>";
  for (size_t i = 0; i < names.size(); ++i) {
    const ReadableUnit unit = unit_of(names[i]);
    const bool stated = i < targeted.size() && targeted[i];
    s << "<tr><td>" << HtmlEscape(names[i]) << "</td><td>"
      << FormatNumber(std(i) * unit.factor, "%.3g") << " " << unit.unit << "</td><td>"
      << (stated ? FormatNumber(targets(i) * unit.factor, "%.3g") + " " + unit.unit
                 : std::string("(limit ") + FormatNumber(targets(i) * unit.factor, "%.3g") + " " +
                       unit.unit + ")")
      << "</td></tr>";
  }
  s << "</table>";
  return s.str();
}

}  // namespace

std::string PlanToHtml(const RecordingPlan& plan) {
  std::ostringstream h;
  h << internal::HtmlPageStart("gravcal plan");
  h << "<h1>Recording plan</h1>";
  h << "<p class='verdict'>" << plan.poses.size() << " poses, "
    << FormatNumber(plan.total_seconds, "%.0f") << " s in total (holds and "
    << FormatNumber(plan.overhead_seconds, "%.0f") << " s per pose to move and settle); "
    << (plan.meets_targets ? "every target met" : "not every target met") << ".</p>";
  h << "<p>" << HtmlEscape(plan.message) << "</p>";
  h << "<p class='note'>Criterion: " << HtmlEscape(plan.criterion)
    << ". Candidate poses: " << HtmlEscape(plan.pose_set)
    << ". Noise: " << HtmlEscape(plan.noise_source) << ".</p>";

  h << "<h2>The sequence</h2><p class='note'>Each picture shows the housing as it should lie "
       "(the table is the grey line; the arrows labelled x, y, z are the housing's axes; the "
       "box is longest along x and flattest along z). Between two poses: the turn to "
       "make.</p><div class='sequence' style='display:flex;flex-wrap:wrap;align-items:center'>";
  for (size_t k = 0; k < plan.poses.size(); ++k) {
    const PlannedPose& p = plan.poses[k];
    if (k > 0 && k - 1 < plan.rotations.size()) {
      h << "<div class='turn' style='width:150px;font-size:smaller;margin:4px'>&rarr; "
        << HtmlEscape(plan.rotations[k - 1].instruction) << "</div>";
    }
    const bool extra = plan.gyro_extra_poses > 0 &&
                       k >= plan.poses.size() - static_cast<size_t>(plan.gyro_extra_poses);
    h << "<figure class='pose" << (extra ? " pose-gyro" : "")
      << "' style='width:180px;margin:4px;font-size:smaller'>"
      << HousingPicture(p.up, static_cast<int>(k + 1)) << "<figcaption>"
      << HtmlEscape(p.instruction) << "; hold " << FormatNumber(p.hold_seconds, "%.1f") << " s"
      << (extra ? " (for the gyroscope)" : "") << "</figcaption></figure>";
  }
  h << "</div>";

  std::vector<Eigen::Vector3d> ups;
  std::vector<std::string> labels;
  for (size_t k = 0; k < plan.poses.size(); ++k) {
    ups.push_back(plan.poses[k].up);
    labels.push_back(std::to_string(k + 1));
  }
  h << internal::RenderSphere("up directions of the poses (sensor frame)", ups, labels);

  h << "<h2>Predicted standard deviations</h2>";
  h << SigmaTable("accelerometer (calibration JSON: accel.covariance)", plan.accel, ReadableUnitOf);
  if (!plan.gyro.parameter_names.empty()) {
    h << SigmaTable("gyroscope (calibration JSON: gyro.covariance)", plan.gyro, GyroReadableUnitOf);
  }
  if (!plan.schemes.empty()) {
    h << "<h2>Against fixed schemes</h2><table class='schemes'><tr><th>scheme</th><th>poses</th>"
         "<th>hold that meets the targets</th><th>total time</th></tr>";
    h << "<tr><td>this plan</td><td>" << plan.poses.size() << "</td><td>&ndash;</td><td>"
      << FormatNumber(plan.total_seconds, "%.0f") << " s</td></tr>";
    for (const SchemeComparison& s : plan.schemes) {
      h << "<tr><td>" << HtmlEscape(s.name) << "</td><td>" << s.poses << "</td><td>"
        << (s.meets_targets ? FormatNumber(s.hold_seconds, "%.1f") + " s" : "never") << "</td><td>"
        << (s.meets_targets ? FormatNumber(s.total_seconds, "%.0f") + " s" : "&ndash;")
        << "</td></tr>";
    }
    h << "</table><p class='note'>The schemes are judged on the accelerometer's targets.</p>";
  }
  h << internal::HtmlPageEnd();
  return h.str();
}

}  // namespace gravcal
