#include "gravcal/simulation/simulated_attitudes.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "gravcal/estimation/static_alignment.h"
#include "util/units.h"

namespace gravcal {

using internal::kRadToDeg;

std::vector<FixtureAttitude> SimulatedFixtureAttitudes(const SimulatedSession& session,
                                                       double noise_deg, uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x5851f42d4c957f2dULL);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double std_deg = std::max(noise_deg, kMinFixtureStdDeg);
  std::vector<FixtureAttitude> rows;
  const std::vector<double>& t = session.log.t;
  for (const SimulatedPose& pose : session.poses) {
    if (!(pose.begin < pose.end && pose.end <= t.size())) continue;
    const Eigen::Vector3d rph = RollPitchHeading(pose.attitude) * kRadToDeg;
    FixtureAttitude r;
    r.t_begin = t[pose.begin];
    r.t_end = t[pose.end - 1];
    r.roll_deg = std::remainder(rph(0) + noise_deg * n01(rng), 360.0);
    r.pitch_deg = std::clamp(rph(1) + noise_deg * n01(rng), -90.0, 90.0);
    r.heading_deg = std::remainder(rph(2) + noise_deg * n01(rng), 360.0);
    r.roll_std_deg = r.pitch_std_deg = r.heading_std_deg = std_deg;
    rows.push_back(r);
  }
  return rows;
}

}  // namespace gravcal
