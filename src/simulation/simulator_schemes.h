// Private: the poses of a simulated multi-position session (simulator.h):
// the named schemes ("six", "twelve", "ten", "random:N") and the planned
// poses of `gravcal plan`, as nominal body-to-navigation attitudes before
// placement. Used by the synthesis (simulator.cc) and the option
// checks (simulator_validation.cc).
#ifndef GRAVCAL_SRC_SIMULATION_SIMULATOR_SCHEMES_H_
#define GRAVCAL_SRC_SIMULATION_SIMULATOR_SCHEMES_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "gravcal/simulation/simulator.h"

namespace gravcal {
namespace internal {

// The smallest rotation taking the body direction `up` to navigation z (half
// a turn about body x when up points straight down).
Eigen::Quaterniond UpToZenith(const Eigen::Vector3d& up);

// The body axis 0..5 (+x, -x, +y, -y, +z, -z) that points up, or -1.
int UpAxis(const Eigen::Quaterniond& attitude);

// True when the planned poses carry their turns (PlannedHold): every pose
// after the first has a turn axis.
bool PlannedTurns(const SimulatorOptions& options);

// The nominal poses of a session: the scheme's (each held hold_seconds),
// or, when options.planned_poses is set, the planned ones (each held its
// own time; following the planned turns from the first when PlannedTurns).
struct NominalPoses {
  std::vector<Eigen::Quaterniond> attitudes;
  std::vector<int> nominal_up;
  std::vector<double> hold_seconds;
};
bool MakeNominalPoses(const SimulatorOptions& options, uint64_t seed, NominalPoses* poses,
                      std::string* error);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_SIMULATION_SIMULATOR_SCHEMES_H_
