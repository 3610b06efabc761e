#include "gravcal/estimation/recording_plan.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gravcal/core/gravity.h"
#include "util/units.h"

namespace gravcal {

namespace {

const char* const kAxisNames[3] = {"x", "y", "z"};

// "x axis" for a housing axis, else "axis (0.71, 0.71, 0.00)".
std::string AxisText(const Eigen::Vector3d& axis) {
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(std::fabs(axis(a)) - 1.0) < 1e-6) {
      return std::string(axis(a) > 0 ? "+" : "-") + kAxisNames[a] + " axis";
    }
  }
  char text[96];
  std::snprintf(text, sizeof(text), "axis (%.2f, %.2f, %.2f)", axis(0), axis(1), axis(2));
  return text;
}

// An accelerometer parameter's readable unit, and the reference standard
// deviation in that unit (1 mg, 100 ppm, 0.1 mrad).
struct UnitAndReference {
  ReadableUnit unit;
  double reference;
};
UnitAndReference AccelUnitOf(const std::string& parameter) {
  if (parameter.rfind("bias_", 0) == 0) return {{"mg", 1e3 / kStandardGravity}, 1.0};
  if (parameter.size() == 4 && parameter[2] == parameter[3]) return {{"ppm", 1e6}, 100.0};
  return {{"mrad", 1e3}, 0.1};
}

}  // namespace

ReadableUnit ReadableUnitOf(const std::string& parameter) { return AccelUnitOf(parameter).unit; }

ReadableUnit GyroReadableUnitOf(const std::string& parameter) {
  if (parameter.rfind("bias_", 0) == 0) return {"deg/h", internal::kRadToDeg * 3600.0};
  if (parameter == "scale" || (parameter.size() == 4 && parameter[2] == parameter[3])) {
    return {"ppm", 1e6};
  }
  return {"mrad", 1e3};
}

double ReferenceStd(const std::string& parameter) {
  const UnitAndReference u = AccelUnitOf(parameter);
  return u.reference / u.unit.factor;
}

std::string PoseInstruction(const Eigen::Vector3d& up) {
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(std::fabs(up(a)) - 1.0) < 1e-6) {
      return std::string(kAxisNames[a]) + " axis " + (up(a) > 0 ? "up" : "down") +
             " (housing face on the table)";
    }
  }
  // Elevation of each axis above the horizontal plane, asin(up_i): the
  // tilted axes first, then the level ones.
  std::string tilted, level;
  int levels = 0, wedge = 0;
  for (int a = 0; a < 3; ++a) {
    const double elevation = std::asin(std::clamp(up(a), -1.0, 1.0)) * internal::kRadToDeg;
    char part[64];
    if (std::fabs(elevation) < 0.5) {
      std::snprintf(part, sizeof(part), "%s%s", level.empty() ? "" : " and ", kAxisNames[a]);
      level += part;
      ++levels;
      continue;
    }
    if (std::fabs(std::fabs(elevation) - 45.0) < 0.5) ++wedge;
    std::snprintf(part, sizeof(part), "%s%s axis %.0f degrees %s", tilted.empty() ? "" : ", ",
                  kAxisNames[a], std::fabs(elevation), elevation > 0 ? "up" : "down");
    tilted += part;
  }
  std::string text = tilted;
  if (levels > 0) text += ", " + level + (levels > 1 ? " axes level" : " axis level");
  if (levels == 1 && wedge == 2) text += " (on a 45-degree wedge)";
  return text;
}

PlannedRotation TurnBetween(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  PlannedRotation turn;
  const Eigen::Vector3d u = from.normalized(), v = to.normalized();
  // The housing turns about a = v x u (see the header) by the angle between.
  Eigen::Vector3d axis = v.cross(u);
  const double angle = std::atan2(axis.norm(), u.dot(v));
  if (axis.norm() < 1e-9) {
    // Same or opposite: turn about the housing axis most nearly level.
    int a = 0;
    for (int i = 1; i < 3; ++i) {
      if (std::fabs(u(i)) < std::fabs(u(a))) a = i;
    }
    axis = Eigen::Vector3d::Unit(a) - u(a) * u;
  }
  return TurnAbout(axis.normalized(), angle * internal::kRadToDeg, 0.0);
}

PlannedRotation TurnAbout(const Eigen::Vector3d& axis, double angle_deg, double seconds) {
  PlannedRotation turn;
  turn.axis = axis.normalized();
  // Snap to a housing axis when within rounding.
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(std::fabs(turn.axis(a)) - 1.0) < 1e-9) {
      turn.axis = Eigen::Vector3d::Unit(a) * (turn.axis(a) > 0 ? 1.0 : -1.0);
    }
  }
  turn.angle_deg = angle_deg;
  turn.seconds = seconds;
  if (turn.angle_deg < 1e-6) {
    turn.instruction = "lift the housing and set it down again in the same pose";
    return turn;
  }
  char text[200];
  if (seconds > 0.0) {
    std::snprintf(text, sizeof(text),
                  "turn %.0f degrees about the housing's %s (right hand rule), in about %.1f s",
                  turn.angle_deg, AxisText(turn.axis).c_str(), seconds);
  } else {
    std::snprintf(text, sizeof(text), "turn %.0f degrees about the housing's %s (right hand rule)",
                  turn.angle_deg, AxisText(turn.axis).c_str());
  }
  turn.instruction = text;
  return turn;
}

void OrderForHandling(std::vector<PlannedPose> poses, RecordingPlan* plan) {
  plan->poses.clear();
  plan->rotations.clear();
  Eigen::Vector3d current = Eigen::Vector3d::UnitZ();
  while (!poses.empty()) {
    auto next = std::max_element(poses.begin(), poses.end(),
                                 [&](const PlannedPose& a, const PlannedPose& b) {
                                   return a.up.dot(current) < b.up.dot(current);
                                 });
    if (!plan->poses.empty()) {
      PlannedRotation turn = TurnBetween(plan->poses.back().up, next->up);
      turn.from = static_cast<int>(plan->poses.size()) - 1;
      turn.to = turn.from + 1;
      plan->rotations.push_back(turn);
    }
    next->instruction = PoseInstruction(next->up);
    current = next->up;
    plan->poses.push_back(*next);
    poses.erase(next);
  }
}

}  // namespace gravcal
