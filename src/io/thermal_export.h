// io/thermal_export.h (private): the thermal bias of a calibration written as
// the autopilots hold it (docs/workflows/export.md, "Thermal compensation").
//
// Both autopilots model temperature as an offset subtracted from the raw
// reading before their offset and per-axis scale, T clamped to the
// calibrated range (Tc = min(max(T, TMIN), TMAX)):
//
//   PX4        a = rot ((v - TC(Tc) - OFF) .* SCALE)
//              TC(Tc) = X0 + X1 d + X2 d^2 + X3 d^3,  d = Tc - TREF
//   ArduPilot  a = rot ((v - P(Tc) + P(Tcal) - OFFS) .* SCAL)
//              P(Tc) = 1e-6 (A1 e + A2 e^2 + A3 e^3),  e = Tc - 35 degC
//              Tcal = clamp(CALTEMP): the temperature OFFS holds at
//
// The curve below is the part of the raw bias that moves with temperature,
// b(T) = sum_k c_k (Tc - t_ref)^k with c_0 = 0 (the static bias at t_ref is
// the calibration's accel.bias / gyro.bias). Neither target has a term for
// scale(T) or misalignment(T): ThermalTruncation measures what they leave.
#ifndef GRAVCAL_IO_THERMAL_EXPORT_H_
#define GRAVCAL_IO_THERMAL_EXPORT_H_

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "gravcal/core/imu_corrector.h"
#include "gravcal/core/thermal_model.h"
#include "gravcal/io/calibration_export.h"
#include "gravcal/io/calibration_io.h"

namespace gravcal {
namespace internal {

using PolynomialCoefficients = Eigen::Matrix<double, 3, Eigen::Dynamic>;

// Per axis, sum_k coefficients(axis, k) (clamp(T, t_min, t_max) - t_ref)^k.
struct ThermalCurve {
  double t_ref = 25.0;
  double t_min = 25.0;
  double t_max = 25.0;
  // Column k multiplies (Tc - t_ref)^k; zero columns = no thermal term.
  PolynomialCoefficients coefficients = PolynomialCoefficients::Zero(3, 1);

  int Order() const { return static_cast<int>(coefficients.cols()) - 1; }
  // The value at T (clamped to the range), in Horner form.
  Eigen::Vector3d At(double temperature) const;
  // True when some coefficient of order >= 1 is not zero.
  bool Varies() const;
};

// q with q(y) = p(y + shift) for every y: the same polynomial about a
// reference `shift` higher (y = x - shift). Exact, same order.
PolynomialCoefficients ShiftPolynomial(const PolynomialCoefficients& p, double shift);

// The curve of order <= max_order closest in least squares over an even
// grid of [t_min, t_max], its value at t_ref kept (the curve itself when its
// order is already low enough). *max_error: the largest |difference| over that grid and the
// three axes.
ThermalCurve ReduceOrder(const ThermalCurve& curve, int max_order, double* max_error);

// What the target's export is made from.
struct AutopilotThermal {
  ThermalCurve accel;
  bool has_gyro = false;
  ThermalCurve gyro;
  // PX4 device ids (CAL_ACC0_ID / CAL_GYRO0_ID on the vehicle); 0 = none.
  int64_t accel_device_id = 0;
  int64_t gyro_device_id = 0;
  // ArduPilot's IMU instance (1..3): INS_TCALn_*, INS_ACCn_CALTEMP.
  int ardupilot_imu = 1;
};

// PX4: the lines after the CAL_* lines of the QGroundControl parameter file
// (TC_A_ENABLE, TC_A0_*, TC_G_ENABLE, TC_G0_*), one per parameter through
// `line`. False with *error when the export would do nothing on a vehicle
// (no device id) or the curve is not a cubic.
bool Px4ThermalLines(
    const AutopilotThermal& thermal,
    const std::function<std::string(const std::string&, const std::string&, bool integer)>& line,
    std::string* text, std::string* error);

// ArduPilot, IMU instance n = thermal.ardupilot_imu: INS_TCALn_ENABLE,
// TMIN, TMAX, ACC1..3_X..Z, GYR1..3_X..Z and INS_ACCn_CALTEMP /
// INS_GYRn_CALTEMP (= t_ref, where the file's offsets hold).
bool ArduPilotThermalLines(
    const AutopilotThermal& thermal,
    const std::function<std::string(const std::string&, const std::string&)>& line,
    std::string* text, std::string* error);

// The accuracy a target's offsets-only thermal model leaves, on the session
// and over the range. `full` and `target` map (raw, T) to the corrected
// output; `raws` are raw readings at `temperatures` (the session's static
// positions). Over the range: each raw of `raws` is also taken through an
// even grid of [t_min, t_max] (the pose held while the temperature moves).
struct ThermalTruncation {
  double session_rms = 0.0;  // rms |target - full| over the session's readings
  double range_max = 0.0;    // largest |target - full| over poses x range grid
  size_t readings = 0;
};
ThermalTruncation MeasureThermalTruncation(
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&, double)>& full,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&, double)>& target,
    const std::vector<Eigen::Vector3d>& raws, const std::vector<double>& temperatures, double t_min,
    double t_max);

// ---------------------------------------------------------------------------
// From the calibration's thermal model (core/thermal_model.h).

// The bias term of one sensor as a curve (t_ref, range and coefficients of
// the model; no coefficients when the term is off).
ThermalCurve BiasCurve(const ThermalModel& model, ThermalSensor sensor);

// The thermal model a PX4 or ArduPilot file holds: the bias terms only, of
// order <= 3 (ReduceOrder when higher), no scale, misalignment or lag.
// reduction[s]: ReduceOrder's largest change of sensor s's bias (raw
// units), 0 when none.
ThermalModel AutopilotHeldThermal(const ThermalModel& full, double reduction[2]);

// The lines ExportResult::dropped gets for the thermal model: what `held`
// (the thermal model the target holds, TruncatedCorrector) leaves out, each
// with its size over the range, and |a_held - a_full| over the session's
// static positions and over the range. Nothing when the model is inactive.
void DescribeThermalTruncation(const LoadedCalibration& calibration, const ImuCorrector& held,
                               std::vector<std::string>* dropped);

// The AutopilotThermal of a calibration (its held model, whether it has a
// gyroscope) and the options' device ids.
AutopilotThermal ToAutopilotThermal(const ThermalModel& held, bool has_gyro,
                                    const ExportOptions& options);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_IO_THERMAL_EXPORT_H_
