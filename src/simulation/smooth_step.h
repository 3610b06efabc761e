// simulation/smooth_step.h: the minimum-jerk profile the simulators move the
// unit along (the turns between poses, a unit slipping on a plate).
#ifndef GRAVCAL_SIMULATION_SMOOTH_STEP_H_
#define GRAVCAL_SIMULATION_SMOOTH_STEP_H_

namespace gravcal {
namespace internal {

// Minimum-jerk profile s(x) = 10 x^3 - 15 x^4 + 6 x^5 on [0, 1] and its
// derivative ds/dx = 30 x^2 (1 - x)^2: rate and acceleration are zero at both
// ends.
inline double SmoothStep(double x) { return x * x * x * (10.0 + x * (-15.0 + 6.0 * x)); }
inline double SmoothStepRate(double x) { return 30.0 * x * x * (1.0 - x) * (1.0 - x); }

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SIMULATION_SMOOTH_STEP_H_
