// gravcal/simulation/simulator.h: simulated multi-position IMU sessions with known truth.
//
// A session is a sequence of static poses joined by smooth rotations. Each
// pose is a nominal orientation from the scheme, disturbed by a random
// placement (tilt and heading) error. The true specific force in the body
// frame is f = C_bn^T (0, 0, g) (the unit reads +g on the axis that points up)
// plus, while static, hand tremor and a per-pose disturbance if set; the raw
// accelerometer is
//   v = M^-1 f + b + n_a,     n_a white, plus a bias random walk and bias
// instability if set,
// and the raw gyroscope u = M_g^-1 (w + G f) + b_g + n_g, with w the true
// body rate (exactly consistent with the attitude trajectory) and G the
// g-sensitivity (zero by default). Raw outputs are either
// in counts (quantised) or in SI units. A temperature column follows a
// warm-up curve.
#ifndef GRAVCAL_SIMULATION_SIMULATOR_H_
#define GRAVCAL_SIMULATION_SIMULATOR_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/gyro_model.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/model_effects.h"

namespace gravcal {

// One pose of a planned session (gravcal plan): the sensor-frame direction
// that points up (the accelerometer reads +g along it) and how long it is
// held, seconds.
struct PlannedHold {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  double hold_seconds = 10.0;
  // The turn into this pose from the previous one (the plan's rotations):
  // body-frame unit axis, angle in degrees (0..180, right hand rule) and
  // duration in seconds (0 = rotation_seconds). When every pose after the
  // first has a turn (nonzero axis), the poses follow them from the first
  // pose's heading (up = R(axis, -angle) previous up must hold within a
  // degree); otherwise each pose gets a random heading of its own and the
  // shortest rotation joins them.
  Eigen::Vector3d turn_axis = Eigen::Vector3d::Zero();
  double turn_angle_deg = 0.0;
  double turn_seconds = 0.0;
};

// The truth spread of every effect, by effect (SimulatorOptions::effect_std).
struct EffectSpreads {
  std::array<double, kNumEffects> values{};
  double& operator[](Effect e) { return values[static_cast<int>(e)]; }
  double operator[](Effect e) const { return values[static_cast<int>(e)]; }
};

// The poses of a simulated multi-position session: six, twelve (the seed's
// six faces plus six 45-degree poses), ten (ten poses of differing roll and
// pitch), or random with random_poses uniformly drawn attitudes (1 to
// 100000). Written as PoseScheme's name from its one table, with ":N" for
// random ("twelve", "random:24"): the value of sim_scheme and of
// truth.json's "scheme".
struct SimulatorScheme {
  PoseScheme kind = PoseScheme::kTwelve;
  // kRandom only.
  long random_poses = 0;

  // The number of poses; false with `error` saying what is wrong (a random
  // count out of range, a kind outside the enum).
  bool PoseCount(long* count, std::string* error) const;
};
// "six", "twelve", "ten", "random:N".
std::string ToString(const SimulatorScheme& scheme);
// Parses that text; false with a one-line `error` giving the text and the
// accepted forms ("'x' is not one of six, twelve, ten or random:N").
bool ParseSimulatorScheme(const std::string& text, SimulatorScheme* scheme, std::string* error);

struct SimulatorOptions {
  SimulatorScheme scheme;
  // Issue 15: when not empty, these poses in this order, each held its own
  // time, replace `scheme` and `hold_seconds`.
  std::vector<PlannedHold> planned_poses;
  // Time held still in each pose, and the initial still period, seconds.
  double hold_seconds = 10.0;
  double initial_still_seconds = 10.0;
  // Duration of each rotation between poses, seconds.
  double rotation_seconds = 3.0;
  double sample_rate = 100.0;
  double gravity = 9.80665;

  // Raw accelerometer in counts (true) or m/s^2 (false).
  bool raw_counts = true;
  // Counts per g of the accelerometer (16384 = +-2 g, 16 bit).
  double accel_counts_per_g = 16384.0;
  // Counts per deg/s of the gyroscope (131 = +-250 deg/s, 16 bit).
  double gyro_counts_per_dps = 131.0;

  // Accelerometer white noise, m/s^2 per sample (standard deviation).
  double accel_noise = 0.02;
  // Accelerometer bias random walk, m/s^2 / sqrt(s). 0 = off.
  double accel_bias_random_walk = 0.0;
  // Gyroscope white noise, rad/s per sample.
  double gyro_noise = 0.002;
  // Gyroscope bias random walk, rad/s / sqrt(s). 0 = off.
  double gyro_bias_random_walk = 0.0;

  // Truth error magnitudes (standard deviations of the random sensor).
  // Accelerometer bias in m/s^2 (converted to raw units).
  double accel_bias_std = 0.3;
  double accel_scale_std = 0.02;
  double accel_misalignment_std = 0.01;  // rad
  double gyro_bias_std = 0.02;           // rad/s
  double gyro_scale_std = 0.02;
  double gyro_misalignment_std = 0.005;  // rad

  // Bias instability (flicker, simulation/noise_process.h) of each axis:
  // B in m/s^2 (accelerometer) and rad/s (gyroscope), the Allan deviation
  // flat at 0.664 B over [bias_instability_tau_low, bias_instability_tau_high]
  // seconds. From a stream of its own; 0 = off.
  double accel_bias_instability = 0.0;
  double gyro_bias_instability = 0.0;
  double bias_instability_tau_low = 1.0;
  double bias_instability_tau_high = 100.0;
  // A tone (a sinusoid, as real still logs show: a 17 Hz line on one gyro
  // axis from a fan, a motor or the sensor's own drive) on one raw axis
  // ("x", "y" or "z") of each sensor: amplitude in m/s^2 (accelerometer) and
  // rad/s (gyroscope) at tone_frequency Hz (below half the sample rate).
  // Deterministic (no random draw), so it changes no other number. 0 = off.
  // tone_axis may name several axes ("xz": the same tone on x and z).
  double accel_tone = 0.0;
  double gyro_tone = 0.0;
  double tone_frequency = 17.0;
  std::string tone_axis = "x";
  // A low-frequency line on every axis (a heater's or an air conditioner's
  // cycle: the bump real Allan curves show at tens to hundreds of seconds):
  // amplitude in m/s^2 (accelerometer) and rad/s (gyroscope), period in
  // seconds, each axis's phase drawn from a stream of its own (so it
  // changes no other number). Its Allan deviation peaks at 0.72 times the
  // amplitude near tau = 0.37 period. 0 = off.
  double accel_slow_line = 0.0;
  double gyro_slow_line = 0.0;
  double slow_line_period = 600.0;

  // Placement error of each pose, degrees (standard deviation per axis).
  double placement_error_deg = 2.0;
  // Hand tremor while "static": specific force disturbance, m/s^2 rms. 0 = a
  // table.
  double tremor = 0.0;
  // What the samples of a pose cannot show (placement settling, mount flex):
  // a specific-force offset N(0, pose_disturbance^2) per body axis, m/s^2,
  // constant over each still period, drawn per pose from a stream of its
  // own. It enters every pose's mean and the gravity direction the poses
  // show, exactly as a pose-to-pose variance component. 0 = off.
  double pose_disturbance = 0.0;

  // Rotations between poses: smooth (minimum-jerk about one fixed axis,
  // rotation_seconds each) or hand (hand-like: each lasts a random
  // hand_min_seconds..hand_max_seconds, its rate speeds up and slows down
  // irregularly, and the axis wobbles by about hand_wobble_deg on the way;
  // still at both ends).
  RotationProfile rotation_profile = RotationProfile::kSmooth;
  double hand_min_seconds = 1.0;
  double hand_max_seconds = 4.0;
  double hand_wobble_deg = 10.0;

  // Temperature: starts at temperature_start and relaxes towards
  // temperature_end with time constant temperature_tau seconds.
  double temperature_start = 25.0;
  double temperature_end = 25.0;
  double temperature_tau = 300.0;

  // Issue 3: when finite, the gyroscope also senses Earth rotation at this
  // geodetic latitude, degrees (navigation frame East-North-Up). NaN = off.
  double latitude_deg = NAN;
  // Issue 3: the fixture attitudes (roll, pitch) written next to a simulated
  // session (WriteFixtureAttitudes) get N(0, this) degrees of noise, and
  // this is the uncertainty they state (at least 0.001 deg).
  double fixture_attitude_noise_deg = 0.0;
  // Effects beyond the textbook model (model_effects.h), all off (0) by
  // default. Each coefficient is drawn N(0, std) per axis (per element for
  // G) from a random stream of its own, so switching one on changes neither
  // the others nor the rest of the session. The accelerometer terms act in
  // the orthogonalised sensor frame, s = R^T f:
  //   v = U^-1 m + b,  m_i = (1 + c_i dT) (s_i + k2_i s_i^2) + beta_i dT + delta_i t,
  // and the gyroscope u = M_g^-1 (w + G f + gamma dT + eta t) + b_g, with
  // dT = temperature - effect_reference_temperature and t the session time.
  // Typical MEMS magnitudes (consumer parts such as the BMI160 and
  // MPU-6050, datasheets and published calibrations): k2 of 1e-5 to
  // 2.5e-4 per m/s^2 (100-2500 ug/g^2; consumer parts specify about 0.5 % of
  // full scale nonlinearity); accelerometer bias tempco 0.5-2 mg/K
  // (0.005-0.02 m/s^2/K); scale tempco 0.01-0.03 %/K; warm-up bias drift of a
  // few mg over minutes (1e-5 to 1e-4 m/s^2/s); gyroscope g-sensitivity
  // about 0.1 deg/s/g (1.8e-4 rad/s per m/s^2); gyroscope bias tempco
  // 0.01-0.05 deg/s/K (2e-4 to 9e-4 rad/s/K).
  // The spread of each effect of the registry (core/effect_registry.h) that
  // has a simulation key (its definition's kSimulation: the key sim_<...>,
  // e.g. sim_accel_quadratic for k2 per axis, 1/(m/s^2)), indexed by the
  // effect; 0 = off. The gyroscope g-sensitivity G (sim_gyro_g_sensitivity)
  // is in rad/s per m/s^2: u = M_g^-1 (w + G f) + b_g + n_g.
  EffectSpreads effect_std;
  // The temperature at which the temperature terms are zero, degrees C.
  double effect_reference_temperature = 25.0;

  bool IsValid(std::string* error) const;
};

// One simulated static pose, as placed.
struct SimulatedPose {
  // Samples [begin, end) of the log are this pose's still period.
  size_t begin = 0;
  size_t end = 0;
  // Body-to-navigation rotation while held (navigation frame: z up).
  Eigen::Quaterniond attitude = Eigen::Quaterniond::Identity();
  // The housing axis the scheme meant to point up, 0..5 or -1 (see position.h).
  int nominal_up = -1;
};

struct SimulatedSession {
  ImuLog log;
  AccelModel accel_truth;
  GyroModel gyro_truth;
  std::vector<SimulatedPose> poses;
  double gravity = 9.80665;
  // Raw units per m/s^2 (accelerometer) and per rad/s (gyroscope).
  double accel_units_per_si = 1.0;
  double gyro_units_per_si = 1.0;
  // The truth of the effects (SimulatorOptions above): G in rad/s per m/s^2
  // (body frame f), zero unless gyro_g_sensitivity_std is set; `effects`
  // holds every term in SI (gyroscope terms in rad/s, before M_g^-1),
  // reference_temperature = effect_reference_temperature, reference_time 0.
  Eigen::Matrix3d gyro_g_sensitivity = Eigen::Matrix3d::Zero();
  EffectParameters effects;
  uint64_t seed = 0;
};

// Nominal orientations (body-to-navigation) of a scheme, and the nominal up
// axis of each (-1 where none points up). Returns false for a scheme whose
// PoseCount fails.
bool SchemeAttitudes(const SimulatorScheme& scheme, uint64_t seed,
                     std::vector<Eigen::Quaterniond>* attitudes, std::vector<int>* nominal_up,
                     std::string* error);

// Simulates one session. Deterministic for a given (options, seed).
bool Simulate(const SimulatorOptions& options, uint64_t seed, SimulatedSession* session,
              std::string* error);

// The truth as JSON text (accel and gyro models in the calibration JSON
// shape, gravity, poses, seed, options).
std::string TruthToJson(const SimulatedSession& session, const SimulatorOptions& options);

}  // namespace gravcal

#endif  // GRAVCAL_SIMULATION_SIMULATOR_H_
