// CalibrationConfig: the calibration part of a Config, usable alone. This
// file includes calibration_config.h and nothing of the workflows besides,
// so it sees what a library user calibrating arrays in memory drags in.
#include "gravcal/workflows/calibration_config.h"

#include <gtest/gtest.h>

#include <string>

namespace gravcal {
namespace {

#ifdef GRAVCAL_SIMULATION_SIMULATOR_H_
constexpr bool kSimulatorIncluded = true;
#else
constexpr bool kSimulatorIncluded = false;
#endif
#ifdef GRAVCAL_SIMULATION_HANDHELD_SIMULATOR_H_
constexpr bool kMotionSimulatorIncluded = true;
#else
constexpr bool kMotionSimulatorIncluded = false;
#endif
#ifdef GRAVCAL_WORKFLOWS_DISCOVERY_H_
constexpr bool kDiscoveryIncluded = true;
#else
constexpr bool kDiscoveryIncluded = false;
#endif

TEST(CalibrationConfig, DragsInNoSimulatorAndNoDiscovery) {
  EXPECT_FALSE(kSimulatorIncluded);
  EXPECT_FALSE(kMotionSimulatorIncluded);
  EXPECT_FALSE(kDiscoveryIncluded);
}

TEST(CalibrationConfig, DefaultsAreValidOptions) {
  const CalibrationConfig c;
  std::string error;
  EXPECT_EQ(c.method, Method::kTwelvePosition);
  EXPECT_TRUE(c.input.IsValid(&error)) << error;
  EXPECT_TRUE(c.calibration.IsValid(&error)) << error;
  EXPECT_TRUE(c.gyro.IsValid(&error)) << error;
  EXPECT_TRUE(c.effects.empty());
}

}  // namespace
}  // namespace gravcal
