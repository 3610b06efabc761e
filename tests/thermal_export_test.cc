// The thermal parameters of the PX4 and ArduPilot exports, applied with the
// targets' own equations (thermal_targets.h, written from their sources),
// against the thermal bias they were made from.
#include "io/thermal_export.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>

#include "thermal_targets.h"
#include "util/numbers.h"

namespace gravcal {
namespace {

using internal::AutopilotThermal;
using internal::PolynomialCoefficients;
using internal::ThermalCurve;
using internal::ExactNumber;

// A cubic accelerometer bias of a MEMS part (BMI088-like: ~0.2 mg/K
// first order) and a gyroscope bias of ~0.015 deg/s/K, about 25 degC.
AutopilotThermal CubicParts() {
  AutopilotThermal t;
  t.accel.t_ref = 25.0;
  t.accel.t_min = -10.0;
  t.accel.t_max = 60.0;
  t.accel.coefficients = PolynomialCoefficients::Zero(3, 4);
  t.accel.coefficients.col(1) << 2.0e-3, -1.5e-3, 3.0e-3;
  t.accel.coefficients.col(2) << 4.0e-5, 2.0e-5, -6.0e-5;
  t.accel.coefficients.col(3) << -8.0e-7, 5.0e-7, 1.0e-6;
  t.has_gyro = true;
  t.gyro = t.accel;
  t.gyro.coefficients.col(1) << 2.6e-4, -1.0e-4, 1.5e-4;
  t.gyro.coefficients.col(2) << 3.0e-6, -2.0e-6, 1.0e-6;
  t.gyro.coefficients.col(3) << -5.0e-8, 4.0e-8, 2.0e-8;
  t.accel_device_id = 2818058;  // an ICM-42688 on SPI, as PX4 numbers it
  t.gyro_device_id = 2818314;
  return t;
}

std::string Px4Line(const std::string& name, const std::string& value, bool integer) {
  return "1\t1\t" + name + "\t" + value + "\t" + (integer ? "6" : "9") + "\n";
}
std::string ParmLine(const std::string& name, const std::string& value) {
  return name + " " + value + "\n";
}

TEST(ThermalExport, ShiftPolynomialIsTheSamePolynomial) {
  PolynomialCoefficients p(3, 4);
  p << 1, 2, 3, 4, -1, 0.5, 0.25, -0.125, 0, 0, 0, 1;
  const PolynomialCoefficients q = internal::ShiftPolynomial(p, 7.5);
  for (double y : {-20.0, -1.0, 0.0, 3.0, 40.0}) {
    for (int i = 0; i < 3; ++i) {
      double pv = 0.0, qv = 0.0;
      for (int k = 3; k >= 0; --k) {
        pv = pv * (y + 7.5) + p(i, k);
        qv = qv * y + q(i, k);
      }
      EXPECT_NEAR(qv, pv, 1e-9 * (1.0 + std::abs(pv)));
    }
  }
}

TEST(ThermalExport, ReduceOrderKeepsACubicAndBoundsAQuintic) {
  ThermalCurve c = CubicParts().accel;
  double error = -1.0;
  ThermalCurve same = internal::ReduceOrder(c, 3, &error);
  EXPECT_EQ(error, 0.0);
  EXPECT_EQ(same.coefficients, c.coefficients);
  c.coefficients.conservativeResize(3, 6);
  c.coefficients.col(4).setConstant(1e-8);
  c.coefficients.col(5).setConstant(-2e-10);
  const ThermalCurve cubic = internal::ReduceOrder(c, 3, &error);
  EXPECT_EQ(cubic.Order(), 3);
  EXPECT_GT(error, 0.0);
  // The reported error is the largest difference on a grid of the range.
  double largest = 0.0;
  for (double t = c.t_min; t <= c.t_max; t += 0.35) {
    largest = std::max(largest, (cubic.At(t) - c.At(t)).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(largest, error * 1.05);
  EXPECT_GE(largest, error * 0.8);
}

// Static bias b0 and the thermal curve b(T): the vehicle's raw reading is
// a_true / s + b0 + b(T). PX4's correction from the exported parameters must
// give a_true back over the whole range, clamped outside it as PX4 does.
TEST(ThermalExport, Px4EquationsUndoTheCubicBiasOverTheRange) {
  const AutopilotThermal t = CubicParts();
  std::string tc, error;
  ASSERT_TRUE(internal::Px4ThermalLines(t, Px4Line, &tc, &error)) << error;
  const Eigen::Vector3d b0(0.12, -0.08, 0.3), bg(0.01, -0.02, 0.005), s(1.01, 0.99, 1.003);
  std::string cal;
  for (int i = 0; i < 3; ++i) {
    const std::string axis(1, "XYZ"[i]);
    cal += Px4Line("CAL_ACC0_" + axis + "OFF", ExactNumber(b0[i]), false);
    cal += Px4Line("CAL_ACC0_" + axis + "SCALE", ExactNumber(s[i]), false);
    cal += Px4Line("CAL_GYRO0_" + axis + "OFF", ExactNumber(bg[i]), false);
  }
  const targets::Params p = targets::ReadQgcParams(cal + tc);
  EXPECT_EQ(p.at("TC_A_ENABLE"), 1.0);
  EXPECT_EQ(p.at("TC_A0_ID"), 2818058.0);
  const Eigen::Vector3d a_true(1.0, -2.0, 9.5), w_true(0.1, -0.2, 0.3);
  double worst_a = 0.0, worst_w = 0.0;
  for (double temp = -20.0; temp <= 70.0; temp += 0.5) {
    const double tc_clamped = std::min(std::max(temp, t.accel.t_min), t.accel.t_max);
    const Eigen::Vector3d raw = a_true.cwiseQuotient(s) + b0 + t.accel.At(tc_clamped);
    worst_a = std::max(worst_a, (targets::Px4Accel(p, 2818058, raw, temp) - a_true).norm());
    const Eigen::Vector3d graw = w_true + bg + t.gyro.At(tc_clamped);
    worst_w = std::max(worst_w, (targets::Px4Gyro(p, 2818314, graw, temp) - w_true).norm());
  }
  // Single precision of 10 m/s^2 and 1 rad/s readings.
  EXPECT_LT(worst_a, 1e-5);
  EXPECT_LT(worst_w, 1e-6);
  // Another sensor's id gets nothing: the check has teeth.
  const Eigen::Vector3d hot = a_true.cwiseQuotient(s) + b0 + t.accel.At(60.0);
  EXPECT_GT((targets::Px4Accel(p, 1, hot, 60.0) - a_true).norm(), 0.05);
}

TEST(ThermalExport, Px4RefusesWithoutTheDeviceIdsByName) {
  AutopilotThermal t = CubicParts();
  t.gyro_device_id = 0;
  std::string text, error;
  EXPECT_FALSE(internal::Px4ThermalLines(t, Px4Line, &text, &error));
  EXPECT_NE(error.find("--gyro_device_id"), std::string::npos) << error;
  EXPECT_NE(error.find("TC_G0_ID"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
  // A calibration without a thermal term needs no id.
  t.accel.coefficients.setZero();
  t.gyro.coefficients.setZero();
  t.accel_device_id = 0;
  EXPECT_TRUE(internal::Px4ThermalLines(t, Px4Line, &text, &error)) << error;
  EXPECT_EQ(text, "");
}

TEST(ThermalExport, ArduPilotEquationsUndoTheCubicBiasOverTheRange) {
  const AutopilotThermal t = CubicParts();
  std::string tcal, error;
  ASSERT_TRUE(internal::ArduPilotThermalLines(t, ParmLine, &tcal, &error)) << error;
  const Eigen::Vector3d b0(0.12, -0.08, 0.3), bg(0.01, -0.02, 0.005), s(1.01, 0.99, 1.003);
  std::string cal;
  for (int i = 0; i < 3; ++i) {
    const std::string axis(1, "XYZ"[i]);
    cal += ParmLine("INS_ACCOFFS_" + axis, ExactNumber(b0[i]));
    cal += ParmLine("INS_ACCSCAL_" + axis, ExactNumber(s[i]));
    cal += ParmLine("INS_GYROFFS_" + axis, ExactNumber(bg[i]));
  }
  const targets::Params p = targets::ReadParm(cal + tcal);
  EXPECT_EQ(p.at("INS_TCAL1_ENABLE"), 1.0);
  EXPECT_EQ(p.at("INS_ACC1_CALTEMP"), 25.0);
  const Eigen::Vector3d a_true(1.0, -2.0, 9.5), w_true(0.1, -0.2, 0.3);
  double worst_a = 0.0, worst_w = 0.0;
  for (double temp = -20.0; temp <= 70.0; temp += 0.5) {
    const double tc_clamped = std::min(std::max(temp, t.accel.t_min), t.accel.t_max);
    const Eigen::Vector3d raw = a_true.cwiseQuotient(s) + b0 + t.accel.At(tc_clamped);
    worst_a = std::max(worst_a, (targets::ArduPilotAccel(p, raw, temp) - a_true).norm());
    const Eigen::Vector3d graw = w_true + bg + t.gyro.At(tc_clamped);
    worst_w = std::max(worst_w, (targets::ArduPilotGyro(p, graw, temp) - w_true).norm());
  }
  // Single precision, and ArduPilot's 1e6-scaled coefficients about 35 degC.
  EXPECT_LT(worst_a, 2e-5);
  EXPECT_LT(worst_w, 2e-6);
  // Without CALTEMP ArduPilot clamps its default -300 to TMIN: the offsets
  // would be taken as holding at -10 degC, a wrong answer at 25 degC.
  targets::Params no_caltemp = p;
  no_caltemp.erase("INS_ACC1_CALTEMP");
  const Eigen::Vector3d at_ref = a_true.cwiseQuotient(s) + b0;
  EXPECT_GT((targets::ArduPilotAccel(no_caltemp, at_ref, 25.0) - a_true).norm(), 0.03);
}

TEST(ThermalExport, ArduPilotRefusesTwoRangesForOneImu) {
  AutopilotThermal t = CubicParts();
  t.gyro.t_max = 50.0;
  std::string text, error;
  EXPECT_FALSE(internal::ArduPilotThermalLines(t, ParmLine, &text, &error));
  EXPECT_NE(error.find("INS_TCAL1"), std::string::npos) << error;
}

}  // namespace
}  // namespace gravcal
