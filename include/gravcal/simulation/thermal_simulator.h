// gravcal/simulation/thermal_simulator.h: simulated sessions across
// temperature with known thermal truth (issue 35), beside the pose simulator
// (simulator.h).
//
// The recorded temperature T_s(t) follows a profile (soak steps, an
// exponential warm-up or cool-down, or a warm-up then cool-down). The
// sensing element's temperature T_e follows T_s through a first-order lag,
// tau dT_e/dt = T_s - T_e, integrated exactly per sample (tau = 0: T_e =
// T_s); heating and cooling branches then disagree (hysteresis) when
// plotted against T_s. With x = T_e - T_ref, the raw readings are the
// thermal model's forward equations (thermal_model.h):
//
//   v = b + db(x) + U^-1 (I + D(x)) f + n_a       accelerometer, counts
//   u = b_g + db_g(x) + M_g^-1 (I + D_g(x)) w + n_g   gyroscope, counts
//
// f = C^T (0, 0, g) the specific force in the body frame (C body to
// navigation, z up: the axis that points up reads +g), w the true body rate
// of the turns between poses, n white noise. The truth of every term is a
// polynomial drawn per axis from the magnitudes below.
//
// Defaults are the Bosch BMI088 datasheet (BST-BMI088-DS001, rev. 1.x):
// accelerometer +-3 g range (10920 LSB/g), noise density 175 ug/sqrt(Hz),
// offset temperature coefficient 0.2 mg/K, sensitivity temperature
// coefficient 0.002 %/K; gyroscope +-2000 deg/s (16.384 LSB/(deg/s)), noise
// density 0.014 deg/s/sqrt(Hz), offset temperature coefficient 0.015
// deg/s/K, sensitivity temperature coefficient 0.03 %/K. The datasheet
// gives the linear coefficients only; the curvature defaults (second and
// third order) are chosen so that over +-30 K each adds about as much as
// the linear term, the shape PX4's third-order fits show on such parts.
#ifndef GRAVCAL_SIMULATION_THERMAL_SIMULATOR_H_
#define GRAVCAL_SIMULATION_THERMAL_SIMULATOR_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/gyro_model.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/thermal_model.h"

namespace gravcal {

enum class ThermalProfile {
  // Multi-pose sessions at several soak temperatures (freezer, room, oven):
  // at each of soak_temperatures the unit is turned through every pose.
  kSoakSteps,
  // One static pose through an exponential warm-up from start_temperature
  // to end_temperature.
  kWarmUp,
  // The same cooling from end_temperature to start_temperature.
  kCoolDown,
  // The uncontrolled warm-up: power on, then turned through the poses
  // repeatedly while it heats.
  kWarmUpPoses,
  // The same warm-up, then a cool-down through the poses (shows lag as
  // hysteresis).
  kWarmCoolPoses,
};
// "soak_steps", "warm_up", "cool_down", "warm_up_poses", "warm_cool_poses".
const char* ToString(ThermalProfile profile);
bool FromString(const std::string& name, ThermalProfile* profile);
std::string AcceptedNames(ThermalProfile);

struct ThermalSimulatorOptions {
  ThermalProfile profile = ThermalProfile::kSoakSteps;
  // kSoakSteps: the soak temperatures, degrees C, and the time spent
  // settling at each before the poses (the temperature moves linearly to
  // the next soak over transition_seconds, the unit resting in the pose it is in).
  std::vector<double> soak_temperatures = {-10.0, 5.0, 20.0, 35.0, 50.0};
  double transition_seconds = 60.0;
  // Ramps: T_s(t) = T_end - (T_end - T_start) exp(-t / ramp_time_constant)
  // (warm-up; the cool-down mirrors it), over ramp_seconds each way.
  double start_temperature = 15.0;
  double end_temperature = 55.0;
  double ramp_time_constant = 600.0;
  double ramp_seconds = 1800.0;
  // The single pose of the ramps: the body axis that points up.
  Eigen::Vector3d single_pose_up = Eigen::Vector3d::UnitZ();
  // The poses: the six faces, then 45-degree poses between them, up to
  // `poses` (6..12).
  int poses = 6;
  // The order of the poses in each pass (a soak, a cycle of the ramps):
  // the same every pass (false: 0, 1, ..., then back to 0), or a new
  // random order each pass, from the pose the unit is in (true: as a hand
  // turns it; the turns then differ from pass to pass, which is what lets
  // the turns determine the accelerometer's non-orthogonality).
  bool shuffle_poses = false;
  double hold_seconds = 20.0;
  double rotation_seconds = 2.0;
  double sample_rate = 100.0;
  double gravity = 9.80665;
  // Raw units: counts (true; the sensitivities below) or SI (false: m/s^2,
  // rad/s, the units configs/thermal.yaml's nominal scales of 1 expect).
  bool raw_counts = true;
  double accel_counts_per_g = 10920.0;
  double gyro_counts_per_dps = 16.384;
  // White noise densities (SI per sqrt(Hz)) and the temperature sensor's
  // white noise (degrees C per sample).
  double accel_noise_density = 175e-6 * 9.80665;
  double gyro_noise_density = 0.014 * 0.017453292519943295;
  double temperature_noise = 0.01;
  // Base errors at T_ref: bias (SI) and scale / misalignment (fraction,
  // rad) standard deviations.
  double accel_bias_std = 0.02 * 9.80665;
  double gyro_bias_std = 0.5 * 0.017453292519943295;
  double scale_std = 0.005;
  double misalignment_std = 0.002;
  // T_ref of the truth, degrees C.
  double reference_temperature = 25.0;
  // Standard deviations of the truth's coefficients of x^1, x^2, x^3 (SI
  // per degC^k): accelerometer bias (m/s^2), scale (fraction), misalignment
  // (rad), gyroscope bias (rad/s). Empty or zeros = no such term.
  std::vector<double> accel_bias_tempco = {0.2e-3 * 9.80665, 4e-6 * 9.80665, 1e-7 * 9.80665};
  std::vector<double> accel_scale_tempco = {2e-5, 4e-7};
  std::vector<double> accel_misalignment_tempco;
  std::vector<double> gyro_bias_tempco = {0.015 * 0.017453292519943295, 3e-4 * 0.017453292519943295,
                                          1e-5 * 0.017453292519943295};
  std::vector<double> gyro_scale_tempco = {3e-4};
  // The gyroscope's misalignment(T), rad per degC^k (6 components); off by
  // default.
  std::vector<double> gyro_misalignment_tempco;
  // The element's lag behind the recorded temperature, s (0 = none).
  double lag_time_constant = 0.0;

  bool IsValid(std::string* error) const;
};

struct ThermalSimulatedSession {
  ImuLog log;
  // The truth: base models and the thermal model, in raw units (the
  // coefficients of the bias terms in counts per degC^k), T_ref =
  // options.reference_temperature, lag_time_constant = options'.
  AccelModel accel;
  GyroModel gyro;
  ThermalModel thermal;
  // The element's temperature per sample, degrees C.
  std::vector<double> element_temperature;
  // Raw units per m/s^2 and per rad/s.
  double accel_units_per_si = 1.0;
  double gyro_units_per_si = 1.0;
  uint64_t seed = 0;
};

// Simulates one session; deterministic for (options, seed). False with a
// message on invalid options.
bool SimulateThermal(const ThermalSimulatorOptions& options, uint64_t seed,
                     ThermalSimulatedSession* session, std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_SIMULATION_THERMAL_SIMULATOR_H_
