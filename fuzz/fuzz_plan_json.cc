// Fuzz target: plan.json (PlanPosesFromJson, PlanRotationsFromJson), the
// input of simulate --plan.
//
// Contract checked: on success every pose's up is a finite unit vector with
// a positive finite hold, and every turn joins neighbouring poses about a
// finite unit axis by 0 to 180 degrees in a finite non-negative time.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_check.h"
#include "gravcal/io/plan_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using gravcal::fuzz::Require;
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<gravcal::PlannedPose> poses;
  std::string error;
  const bool poses_ok = gravcal::PlanPosesFromJson(text, "fuzz.json", &poses, &error);
  gravcal::fuzz::RequireOutcome(poses_ok, error);
  if (!poses_ok) return 0;
  for (const gravcal::PlannedPose& pose : poses) {
    Require(pose.up.allFinite() && std::abs(pose.up.norm() - 1.0) < 1e-9, "pose up not unit");
    Require(std::isfinite(pose.hold_seconds) && pose.hold_seconds > 0.0, "hold not positive");
  }
  std::vector<gravcal::PlannedRotation> turns;
  error.clear();
  const bool turns_ok =
      gravcal::PlanRotationsFromJson(text, "fuzz.json", poses.size(), &turns, &error);
  gravcal::fuzz::RequireOutcome(turns_ok, error);
  for (const gravcal::PlannedRotation& turn : turns) {
    Require(
        turn.from >= 0 && turn.to == turn.from + 1 && static_cast<size_t>(turn.to) < poses.size(),
        "turn does not join neighbouring poses");
    Require(turn.axis.allFinite() && std::abs(turn.axis.norm() - 1.0) < 1e-9, "axis not unit");
    Require(turn.angle_deg >= 0.0 && turn.angle_deg <= 180.0, "angle out of range");
    Require(std::isfinite(turn.seconds) && turn.seconds >= 0.0, "duration not finite");
  }
  return 0;
}
