#include "gravcal/simulation/simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "gravcal/estimation/spectral_lines.h"
#include "gravcal/workflows/config.h"
#include "sigma_check.h"
#include "test_util.h"

namespace gravcal {
namespace {

// Unit vector of nominal axis 0..5 (+x, -x, +y, -y, +z, -z).
Eigen::Vector3d Axis(int nominal_up) {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  v(nominal_up / 2) = nominal_up % 2 == 0 ? 1.0 : -1.0;
  return v;
}

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

std::string Scientific(double value) {
  std::ostringstream text;
  text << std::scientific << std::setprecision(2) << value;
  return text.str();
}

SimulatedSession MustSimulate(const SimulatorOptions& options, uint64_t seed) {
  SimulatedSession session;
  std::string error;
  EXPECT_TRUE(Simulate(options, seed, &session, &error)) << error;
  return session;
}

// A noise-free session in SI units: the raw outputs are exact.
SimulatorOptions Exact() {
  SimulatorOptions options;
  options.raw_counts = false;
  options.accel_noise = 0.0;
  options.gyro_noise = 0.0;
  return options;
}

TEST(Simulator, DeterministicForASeed) {
  SimulatorOptions options;
  options.tremor = 0.05;
  options.accel_bias_random_walk = 1e-3;
  options.gyro_bias_random_walk = 1e-4;
  const SimulatedSession a = MustSimulate(options, 42);
  const SimulatedSession b = MustSimulate(options, 42);
  ASSERT_EQ(a.log.size(), b.log.size());
  for (size_t i = 0; i < a.log.size(); ++i) {
    ASSERT_EQ(a.log.t[i], b.log.t[i]);
    ASSERT_EQ(a.log.accel[i], b.log.accel[i]) << "sample " << i;
    ASSERT_EQ(a.log.gyro[i], b.log.gyro[i]) << "sample " << i;
  }
  EXPECT_EQ(TruthToJson(a, options), TruthToJson(b, options));
}

TEST(Simulator, DifferentSeedsDiffer) {
  SimulatorOptions options;
  const SimulatedSession a = MustSimulate(options, 1);
  const SimulatedSession b = MustSimulate(options, 2);
  ASSERT_EQ(a.log.size(), b.log.size());
  EXPECT_NE(a.accel_truth.bias, b.accel_truth.bias);
  EXPECT_NE(a.gyro_truth.matrix, b.gyro_truth.matrix);
  EXPECT_GT(testing_util::QuaternionAngle(a.poses[0].attitude, b.poses[0].attitude), 1e-3);
  size_t differing = 0;
  for (size_t i = 0; i < a.log.size(); ++i) differing += a.log.accel[i] != b.log.accel[i];
  EXPECT_GT(differing, a.log.size() / 2);
}

TEST(Simulator, SchemesGiveTheirPoseCounts) {
  const std::vector<std::pair<std::string, size_t>> schemes = {
      {"six", 6}, {"twelve", 12}, {"ten", 10}, {"random:1", 1}, {"random:7", 7}};
  for (const auto& [text, count] : schemes) {
    const std::string& scheme = text;
    SimulatorScheme parsed;
    std::vector<Eigen::Quaterniond> attitudes;
    std::vector<int> up;
    std::string error;
    ASSERT_TRUE(ParseSimulatorScheme(text, &parsed, &error)) << error;
    EXPECT_EQ(ToString(parsed), text);
    ASSERT_TRUE(SchemeAttitudes(parsed, 3, &attitudes, &up, &error)) << error;
    EXPECT_EQ(attitudes.size(), count) << scheme;
    ASSERT_EQ(up.size(), count) << scheme;
    for (size_t k = 0; k < count; ++k) {
      EXPECT_NEAR(attitudes[k].norm(), 1.0, 1e-12);
      // Where an axis is named, it points up.
      if (up[k] >= 0) {
        const Eigen::Vector3d up_body = attitudes[k].conjugate() * Eigen::Vector3d::UnitZ();
        EXPECT_LT((up_body - Axis(up[k])).norm(), 1e-9) << scheme << " pose " << k;
      }
    }
    SimulatorOptions options;
    options.scheme = parsed;
    options.hold_seconds = 2.0;
    options.initial_still_seconds = 1.0;
    options.rotation_seconds = 1.0;
    const SimulatedSession session = MustSimulate(options, 3);
    EXPECT_EQ(session.poses.size(), count) << scheme;
    // Still periods: pose 0 holds initial_still + hold, the others hold.
    ASSERT_FALSE(session.poses.empty());
    EXPECT_EQ(session.poses[0].begin, 0u);
    EXPECT_EQ(session.poses[0].end, 300u);
    for (size_t k = 1; k < session.poses.size(); ++k) {
      EXPECT_EQ(session.poses[k].end - session.poses[k].begin, 200u);
      EXPECT_EQ(session.poses[k].begin, session.poses[k - 1].end + 100u);
    }
    EXPECT_EQ(session.poses.back().end, session.log.size());
    std::string log_error;
    EXPECT_TRUE(session.log.Validate(&log_error)) << log_error;
  }

  // The six faces name +x, -x, +y, -y, +z, -z in order; twelve adds six poses
  // with no axis up, all well apart; ten has six axis-up poses.
  std::vector<Eigen::Quaterniond> attitudes;
  std::vector<int> up;
  ASSERT_TRUE(SchemeAttitudes({PoseScheme::kTwelve}, 0, &attitudes, &up, nullptr));
  for (int k = 0; k < 12; ++k) EXPECT_EQ(up[k], k < 6 ? k : -1);
  for (size_t a = 0; a < attitudes.size(); ++a) {
    for (size_t b = a + 1; b < attitudes.size(); ++b) {
      const Eigen::Vector3d ua = attitudes[a].conjugate() * Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d ub = attitudes[b].conjugate() * Eigen::Vector3d::UnitZ();
      EXPECT_GT(AngleBetween(ua, ub), 40.0 * M_PI / 180.0) << a << " " << b;
    }
  }
  ASSERT_TRUE(SchemeAttitudes({PoseScheme::kTen}, 0, &attitudes, &up, nullptr));
  int with_axis = 0;
  for (int u : up) with_axis += u >= 0;
  EXPECT_EQ(with_axis, 6);
}

TEST(Simulator, StillAccelerometerReadsGravityAlongUp) {
  for (bool raw_counts : {true, false}) {
    SimulatorOptions options;
    options.raw_counts = raw_counts;
    const SimulatedSession session = MustSimulate(options, 7);
    for (const SimulatedPose& pose : session.poses) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (size_t i = pose.begin; i < pose.end; ++i) {
        sum += session.accel_truth.Apply(session.log.accel[i]);
      }
      const Eigen::Vector3d mean = sum / static_cast<double>(pose.end - pose.begin);
      const Eigen::Vector3d expected =
          pose.attitude.conjugate() * Eigen::Vector3d(0.0, 0.0, options.gravity);
      // Noise 0.02 m/s^2 over >= 1000 samples: about 6e-4 per axis.
      EXPECT_NEAR(mean.norm(), options.gravity, 5e-3);
      EXPECT_LT((mean - expected).norm(), 5e-3);
      // Placement error of 2 degrees keeps the named axis close to up.
      if (pose.nominal_up >= 0) {
        EXPECT_LT(AngleBetween(mean, Axis(pose.nominal_up)), 10.0 * M_PI / 180.0);
      }
    }
  }
}

TEST(Simulator, TremorStaysWithinItsRms) {
  SimulatorOptions options = Exact();
  options.tremor = 0.1;
  const SimulatedSession session = MustSimulate(options, 8);
  double sum_sq = 0.0;
  size_t n = 0;
  for (const SimulatedPose& pose : session.poses) {
    const Eigen::Vector3d expected =
        pose.attitude.conjugate() * Eigen::Vector3d(0.0, 0.0, options.gravity);
    for (size_t i = pose.begin; i < pose.end; ++i) {
      sum_sq += (session.accel_truth.Apply(session.log.accel[i]) - expected).squaredNorm();
      n += 3;
    }
  }
  EXPECT_NEAR(std::sqrt(sum_sq / static_cast<double>(n)), options.tremor, 0.01);
}

TEST(Simulator, RawCountsAreIntegers) {
  SimulatorOptions options;
  options.scheme = {PoseScheme::kSix};
  const SimulatedSession counts = MustSimulate(options, 11);
  EXPECT_NEAR(counts.accel_units_per_si, 16384.0 / 9.80665, 1e-9);
  EXPECT_NEAR(counts.gyro_units_per_si, 131.0 * 180.0 / M_PI, 1e-9);
  for (size_t i = 0; i < counts.log.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      ASSERT_EQ(counts.log.accel[i](a), std::round(counts.log.accel[i](a))) << i;
      ASSERT_EQ(counts.log.gyro[i](a), std::round(counts.log.gyro[i](a))) << i;
    }
  }
  options.raw_counts = false;
  const SimulatedSession si = MustSimulate(options, 11);
  EXPECT_EQ(si.accel_units_per_si, 1.0);
  EXPECT_EQ(si.gyro_units_per_si, 1.0);
  size_t fractional = 0;
  for (const Eigen::Vector3d& v : si.log.accel) fractional += v(0) != std::round(v(0));
  EXPECT_GT(fractional, si.log.size() / 2);
}

TEST(Simulator, GyroIntegrationReproducesThePoses) {
  // 100 Hz as simulated by default, and a fine 1 kHz step.
  for (double rate : {100.0, 1000.0}) {
    SimulatorOptions options = Exact();
    options.sample_rate = rate;
    options.placement_error_deg = 10.0;
    const SimulatedSession session = MustSimulate(options, 5);
    const double dt = 1.0 / rate;
    const Eigen::Vector3d gravity(0.0, 0.0, options.gravity);
    // Trapezoidal steps: within one rotation the rate keeps its axis, so the
    // only error is the quadrature of the rate profile, O(dt^2) mid-rotation
    // and far smaller over a whole rotation, whose rate starts and ends at 0.
    Eigen::Quaterniond q = session.poses[0].attitude;
    size_t next = 1;
    double worst = 0.0;
    double worst_force = 0.0;
    for (size_t i = 0; i < session.log.size(); ++i) {
      if (next < session.poses.size() && i == session.poses[next].begin) {
        worst = std::max(worst, testing_util::QuaternionAngle(q, session.poses[next].attitude));
        ++next;
      }
      // The specific force follows the attitude at every sample.
      worst_force = std::max(
          worst_force,
          (session.accel_truth.Apply(session.log.accel[i]) - q.conjugate() * gravity).norm());
      if (i + 1 == session.log.size()) break;
      const Eigen::Vector3d w = 0.5 * (session.gyro_truth.Apply(session.log.gyro[i]) +
                                       session.gyro_truth.Apply(session.log.gyro[i + 1]));
      const double angle = w.norm() * dt;
      if (angle > 0.0) q = (q * Eigen::AngleAxisd(angle, w.normalized())).normalized();
    }
    EXPECT_EQ(next, session.poses.size());
    EXPECT_LT(worst, 1e-6) << rate << " Hz";
    EXPECT_LT(worst_force, 0.2 * options.gravity / (rate * rate)) << rate << " Hz";
    RecordProperty("worst_angle_" + std::to_string(static_cast<int>(rate)), Scientific(worst));
    RecordProperty("worst_force_" + std::to_string(static_cast<int>(rate)),
                   Scientific(worst_force));
  }
}

TEST(Simulator, RotationRateStartsAndEndsAtZero) {
  const SimulatedSession session = MustSimulate(Exact(), 9);
  for (size_t k = 0; k < session.poses.size(); ++k) {
    for (size_t i = session.poses[k].begin; i < session.poses[k].end; ++i) {
      ASSERT_LT(session.gyro_truth.Apply(session.log.gyro[i]).norm(), 1e-12) << i;
    }
    if (k + 1 < session.poses.size()) {
      const size_t end = session.poses[k].end;
      const size_t next = session.poses[k + 1].begin;
      const size_t middle = (end + next) / 2;
      EXPECT_LT(session.gyro_truth.Apply(session.log.gyro[end + 1]).norm(), 1e-2);
      EXPECT_LT(session.gyro_truth.Apply(session.log.gyro[next - 1]).norm(), 1e-2);
      EXPECT_GT(session.gyro_truth.Apply(session.log.gyro[middle]).norm(), 0.1);
    }
  }
}

TEST(Simulator, StillGyroMeanIsTheBias) {
  for (bool raw_counts : {false, true}) {
    SimulatorOptions options;
    options.raw_counts = raw_counts;
    const SimulatedSession session = MustSimulate(options, 13);
    const double noise = options.gyro_noise * session.gyro_units_per_si;
    for (const SimulatedPose& pose : session.poses) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (size_t i = pose.begin; i < pose.end; ++i) sum += session.log.gyro[i];
      const double n = static_cast<double>(pose.end - pose.begin);
      // Rounding to counts with little noise can bias the mean by up to half
      // a count.
      const double tolerance = 5.0 * noise / std::sqrt(n) + (raw_counts ? 0.5 : 0.0);
      EXPECT_LT((sum / n - session.gyro_truth.bias).cwiseAbs().maxCoeff(), tolerance);
    }
  }
}

TEST(Simulator, TemperatureFollowsTheWarmUpCurve) {
  SimulatorOptions options;
  options.temperature_start = 20.0;
  options.temperature_end = 40.0;
  options.temperature_tau = 60.0;
  const SimulatedSession session = MustSimulate(options, 1);
  ASSERT_EQ(session.log.temperature.size(), session.log.size());
  EXPECT_DOUBLE_EQ(session.log.temperature[0], 20.0);
  for (size_t i = 1; i < session.log.size(); ++i) {
    ASSERT_GT(session.log.temperature[i], session.log.temperature[i - 1]);
  }
  const double t = session.log.t.back();
  EXPECT_NEAR(session.log.temperature.back(), 40.0 - 20.0 * std::exp(-t / 60.0), 1e-9);
}

// Without noise, two samples of one still pose differ only by the bias
// walks: per axis N(0, q^2 T) over T seconds. Over 40 seeds the differences
// must match q sqrt(T) (SigmaCheck's band), accelerometer and gyroscope: a
// walk scaled by dt instead of sqrt(dt), or a missing one, fails.
TEST(Simulator, BiasRandomWalkMovesTheBias) {
  SimulatorOptions options = Exact();
  options.accel_bias_random_walk = 0.01;
  options.gyro_bias_random_walk = 1e-3;
  testing_util::SigmaCheck check;
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    const SimulatedSession session = MustSimulate(options, seed);
    const SimulatedPose& pose = session.poses.back();
    const double t = session.log.t[pose.end - 1] - session.log.t[pose.begin];
    const Eigen::Vector3d accel = session.log.accel[pose.end - 1] - session.log.accel[pose.begin];
    const Eigen::Vector3d gyro = session.log.gyro[pose.end - 1] - session.log.gyro[pose.begin];
    testing_util::AddEach(&check, "accel walk", accel,
                          Eigen::Vector3d::Constant(options.accel_bias_random_walk * std::sqrt(t)));
    testing_util::AddEach(&check, "gyro walk", gyro,
                          Eigen::Vector3d::Constant(options.gyro_bias_random_walk * std::sqrt(t)));
  }
  std::printf("%s", check.Table().c_str());
  check.ExpectHonest("bias random walk");
}

TEST(Simulator, RejectsInvalidOptions) {
  using Setter = void (*)(SimulatorOptions*);
  const std::vector<std::pair<std::string, Setter>> cases = {
      {"scheme",
       [](SimulatorOptions* o) {
         o->scheme = {PoseScheme::kRandom, 0};
       }},
      {"hold_seconds", [](SimulatorOptions* o) { o->hold_seconds = 0.001; }},
      {"initial_still_seconds", [](SimulatorOptions* o) { o->initial_still_seconds = -1.0; }},
      {"rotation_seconds", [](SimulatorOptions* o) { o->rotation_seconds = 0.0; }},
      {"sample_rate", [](SimulatorOptions* o) { o->sample_rate = 0.0; }},
      {"sample_rate", [](SimulatorOptions* o) { o->sample_rate = NAN; }},
      {"gravity", [](SimulatorOptions* o) { o->gravity = -9.8; }},
      {"accel_counts_per_g", [](SimulatorOptions* o) { o->accel_counts_per_g = 0.0; }},
      {"gyro_counts_per_dps", [](SimulatorOptions* o) { o->gyro_counts_per_dps = INFINITY; }},
      {"accel_noise", [](SimulatorOptions* o) { o->accel_noise = -0.1; }},
      {"accel_bias_random_walk", [](SimulatorOptions* o) { o->accel_bias_random_walk = NAN; }},
      {"gyro_noise", [](SimulatorOptions* o) { o->gyro_noise = -1.0; }},
      {"gyro_bias_random_walk", [](SimulatorOptions* o) { o->gyro_bias_random_walk = -1.0; }},
      {"accel_bias_std", [](SimulatorOptions* o) { o->accel_bias_std = -1.0; }},
      {"accel_scale_std", [](SimulatorOptions* o) { o->accel_scale_std = 2.0; }},
      {"accel_misalignment_std", [](SimulatorOptions* o) { o->accel_misalignment_std = -1.0; }},
      {"gyro_bias_std", [](SimulatorOptions* o) { o->gyro_bias_std = NAN; }},
      {"gyro_scale_std", [](SimulatorOptions* o) { o->gyro_scale_std = -0.1; }},
      {"gyro_misalignment_std", [](SimulatorOptions* o) { o->gyro_misalignment_std = 1.0; }},
      {"placement_error_deg", [](SimulatorOptions* o) { o->placement_error_deg = -2.0; }},
      {"tremor", [](SimulatorOptions* o) { o->tremor = -0.1; }},
      {"temperature_start", [](SimulatorOptions* o) { o->temperature_start = NAN; }},
      {"temperature_end", [](SimulatorOptions* o) { o->temperature_end = INFINITY; }},
      {"temperature_tau", [](SimulatorOptions* o) { o->temperature_tau = 0.0; }},
  };
  std::string error;
  ASSERT_TRUE(SimulatorOptions().IsValid(&error)) << error;
  for (const auto& [field, set] : cases) {
    SimulatorOptions options;
    set(&options);
    error.clear();
    EXPECT_FALSE(options.IsValid(&error)) << field;
    EXPECT_NE(error.find(field), std::string::npos) << field << ": " << error;
    EXPECT_FALSE(options.IsValid(nullptr)) << field;
    SimulatedSession session;
    error.clear();
    EXPECT_FALSE(Simulate(options, 1, &session, &error)) << field;
    EXPECT_NE(error.find(field), std::string::npos) << field << ": " << error;
  }
  // A session of more than 1e8 samples is refused, not allocated.
  SimulatorOptions huge;
  huge.scheme = {PoseScheme::kRandom, 100000};
  huge.sample_rate = 1000.0;
  EXPECT_FALSE(huge.IsValid(&error));
  EXPECT_NE(error.find("samples"), std::string::npos) << error;
  // One sample period is enough.
  SimulatorOptions shortest;
  shortest.hold_seconds = 0.01;
  shortest.rotation_seconds = 0.01;
  shortest.initial_still_seconds = 0.0;
  EXPECT_TRUE(shortest.IsValid(&error)) << error;
}

TEST(Simulator, RejectsUnknownScheme) {
  std::vector<Eigen::Quaterniond> attitudes;
  std::vector<int> up;
  std::string error;
  SimulatorScheme scheme;
  EXPECT_FALSE(ParseSimulatorScheme("seven", &scheme, &error));
  EXPECT_EQ(error, "'seven' is not one of six, twelve, ten or random:N");
  for (const std::string bad :
       {"random:", "random:x", "random:-3", "random:0", "Six", "", "six:3"}) {
    EXPECT_FALSE(ParseSimulatorScheme(bad, &scheme, &error)) << bad;
    EXPECT_NE(error.find("'" + bad + "'"), std::string::npos) << error;
  }
  // The config key names itself and the accepted values.
  Config config;
  EXPECT_FALSE(SetConfigValue("sim_scheme", "bogus", &config, &error));
  EXPECT_EQ(error, "key 'sim_scheme': 'bogus' is not one of six, twelve, ten or random:N");
  ASSERT_TRUE(SetConfigValue("sim_scheme", "random:5", &config, &error)) << error;
  EXPECT_EQ(ConfigValueText(config, "sim_scheme"), "random:5");
  // So is every other enum key, from the enum's one table.
  EXPECT_FALSE(SetConfigValue("sim_rotation_profile", "jerky", &config, &error));
  EXPECT_EQ(error, "key 'sim_rotation_profile': 'jerky' is not one of smooth or hand");
  ASSERT_TRUE(SetConfigValue("sim_rotation_profile", "hand", &config, &error)) << error;
  EXPECT_EQ(config.simulation.rotation_profile, RotationProfile::kHand);
  EXPECT_FALSE(SetConfigValue("loss", "l2", &config, &error));
  EXPECT_EQ(error, "key 'loss': 'l2' is not one of none, huber, cauchy, soft_l1, arctan or tukey");
  // A count out of range set in code is refused by the simulator.
  SimulatorOptions options;
  options.scheme = {PoseScheme::kRandom, 0};
  EXPECT_FALSE(SchemeAttitudes(options.scheme, 0, &attitudes, &up, &error));
  SimulatedSession session;
  EXPECT_FALSE(Simulate(options, 1, &session, &error));
  EXPECT_NE(error.find("random:0"), std::string::npos) << error;
  EXPECT_FALSE(Simulate(SimulatorOptions(), 1, nullptr, &error));
}

TEST(Simulator, TruthJsonHoldsTheTruth) {
  SimulatorOptions options;
  options.scheme = {PoseScheme::kTen};
  const SimulatedSession session = MustSimulate(options, 17);
  const nlohmann::json j = nlohmann::json::parse(TruthToJson(session, options));
  EXPECT_EQ(j["seed"].get<uint64_t>(), 17u);
  EXPECT_EQ(j["gravity"].get<double>(), options.gravity);
  EXPECT_EQ(j["accel"]["model"], "affine");
  const Eigen::Matrix3d m = session.accel_truth.matrix();
  for (int r = 0; r < 3; ++r) {
    EXPECT_EQ(j["accel"]["bias"][r].get<double>(), session.accel_truth.bias(r));
    EXPECT_EQ(j["gyro"]["bias"][r].get<double>(), session.gyro_truth.bias(r));
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(j["accel"]["matrix"][r][c].get<double>(), m(r, c));
      EXPECT_EQ(j["accel"]["upper"][r][c].get<double>(), session.accel_truth.upper(r, c));
      EXPECT_EQ(j["accel"]["rotation"][r][c].get<double>(), session.accel_truth.rotation(r, c));
      EXPECT_EQ(j["gyro"]["matrix"][r][c].get<double>(), session.gyro_truth.matrix(r, c));
    }
  }
  EXPECT_EQ(j["accel_units_per_si"].get<double>(), session.accel_units_per_si);
  EXPECT_EQ(j["gyro_units_per_si"].get<double>(), session.gyro_units_per_si);
  ASSERT_EQ(j["poses"].size(), 10u);
  for (size_t k = 0; k < 10; ++k) {
    const nlohmann::json& p = j["poses"][k];
    const SimulatedPose& pose = session.poses[k];
    EXPECT_EQ(p["begin"].get<size_t>(), pose.begin);
    EXPECT_EQ(p["end"].get<size_t>(), pose.end);
    EXPECT_EQ(p["t_begin"].get<double>(), session.log.t[pose.begin]);
    EXPECT_EQ(p["t_end"].get<double>(), session.log.t[pose.end - 1]);
    EXPECT_EQ(p["nominal_up"].get<int>(), pose.nominal_up);
    EXPECT_EQ(p["quaternion"][0].get<double>(), pose.attitude.w());
    EXPECT_EQ(p["quaternion"][3].get<double>(), pose.attitude.z());
  }
  for (const char* field : {"scheme",
                            "hold_seconds",
                            "initial_still_seconds",
                            "rotation_seconds",
                            "sample_rate",
                            "gravity",
                            "raw_counts",
                            "accel_counts_per_g",
                            "gyro_counts_per_dps",
                            "accel_noise",
                            "accel_bias_random_walk",
                            "gyro_noise",
                            "gyro_bias_random_walk",
                            "accel_bias_std",
                            "accel_scale_std",
                            "accel_misalignment_std",
                            "gyro_bias_std",
                            "gyro_scale_std",
                            "gyro_misalignment_std",
                            "placement_error_deg",
                            "tremor",
                            "temperature_start",
                            "temperature_end",
                            "temperature_tau"}) {
    EXPECT_TRUE(j["options"].contains(field)) << field;
  }
  EXPECT_EQ(j["options"]["scheme"], "ten");
}

// The tone option: a line at the stated frequency and amplitude on the
// stated raw axis of the gyroscope, found by the noise command's line
// finder in the initial still period; none on another axis; and no other
// number of the session changes (the tone draws nothing).
TEST(Simulator, GyroToneIsALineOnOneAxisAndChangesNothingElse) {
  SimulatorOptions options;
  options.scheme = {PoseScheme::kSix};
  options.raw_counts = false;
  options.initial_still_seconds = 60.0;
  const SimulatedSession plain = MustSimulate(options, 5);
  options.gyro_tone = 0.01;
  options.tone_frequency = 17.0;
  options.tone_axis = "y";
  const SimulatedSession toned = MustSimulate(options, 5);
  ASSERT_EQ(plain.log.size(), toned.log.size());
  for (size_t i = 0; i < plain.log.size(); i += 97) {
    EXPECT_EQ(plain.log.accel[i], toned.log.accel[i]) << i;
    EXPECT_EQ(plain.log.gyro[i](0), toned.log.gyro[i](0)) << i;
  }
  const size_t still = static_cast<size_t>(50.0 * options.sample_rate);
  for (int axis : {0, 1}) {
    std::vector<double> x(still);
    for (size_t i = 0; i < still; ++i) x[i] = toned.log.gyro[i](axis) / toned.gyro_units_per_si;
    const std::vector<SpectralLine> lines = FindSpectralLines(x, 0, still, options.sample_rate);
    bool found = false;
    for (const SpectralLine& l : lines) {
      if (std::fabs(l.frequency_hz - 17.0) > 0.3) continue;
      found = true;
      EXPECT_NEAR(l.amplitude, 0.01, 0.002) << axis;
    }
    EXPECT_EQ(found, axis == 1) << axis;
  }
  options.tone_axis = "w";
  SimulatedSession session;
  std::string error;
  EXPECT_FALSE(Simulate(options, 5, &session, &error));
  EXPECT_NE(error.find("tone_axis"), std::string::npos) << error;
  options.tone_axis = "x";
  options.tone_frequency = 60.0;
  EXPECT_FALSE(Simulate(options, 5, &session, &error));
  EXPECT_NE(error.find("tone_frequency"), std::string::npos) << error;
}

// Tones on several axes ("xz") and the slow line: on a still gyroscope
// (no bias, no white noise, SI output) each axis is exactly the tone where
// named plus amplitude sin(2 pi t / period + phase_i), phases differing
// between axes; the accelerometer and the truth are unchanged.
TEST(Simulator, ToneOnSeveralAxesAndSlowLine) {
  SimulatorOptions options;
  options.scheme = {PoseScheme::kRandom, 1};
  options.raw_counts = false;
  options.initial_still_seconds = 0.0;
  options.hold_seconds = 400.0;
  options.gyro_noise = 0.0;
  options.gyro_bias_std = 0.0;
  options.gyro_scale_std = 0.0;
  options.gyro_misalignment_std = 0.0;
  const SimulatedSession plain = MustSimulate(options, 8);
  options.gyro_tone = 0.01;
  options.tone_axis = "xz";
  options.gyro_slow_line = 2e-4;
  options.slow_line_period = 100.0;
  const SimulatedSession lined = MustSimulate(options, 8);
  ASSERT_EQ(plain.log.size(), lined.log.size());
  std::vector<double> phase;
  for (int a = 0; a < 3; ++a) {
    // The slow line's phase from the first sample (the tone is zero there).
    const double s0 = (lined.log.gyro[0](a) - plain.log.gyro[0](a)) / 2e-4;
    const double s1 = (lined.log.gyro[25](a) - plain.log.gyro[25](a) -
                       (a != 1 ? 0.01 * std::sin(2.0 * M_PI * 17.0 * 0.25) : 0.0)) /
                      2e-4;
    phase.push_back(std::atan2(
        s0, (s1 - s0 * std::cos(2.0 * M_PI * 0.25 / 100.0)) / std::sin(2.0 * M_PI * 0.25 / 100.0)));
    for (size_t i = 0; i < lined.log.size(); i += 37) {
      const double t = lined.log.t[i];
      const double expected = (a != 1 ? 0.01 * std::sin(2.0 * M_PI * 17.0 * t) : 0.0) +
                              2e-4 * std::sin(2.0 * M_PI * t / 100.0 + phase[a]);
      EXPECT_NEAR(lined.log.gyro[i](a) - plain.log.gyro[i](a), expected, 1e-9) << a << " " << i;
    }
  }
  EXPECT_GT(std::abs(std::remainder(phase[0] - phase[1], 2.0 * M_PI)), 1e-3);
  EXPECT_GT(std::abs(std::remainder(phase[1] - phase[2], 2.0 * M_PI)), 1e-3);
  for (size_t i = 0; i < plain.log.size(); i += 101) {
    EXPECT_EQ(plain.log.accel[i], lined.log.accel[i]) << i;
  }
  options.tone_axis = "xw";
  SimulatedSession session;
  std::string error;
  EXPECT_FALSE(Simulate(options, 8, &session, &error));
  EXPECT_NE(error.find("tone_axis"), std::string::npos) << error;
  options.tone_axis = "x";
  options.slow_line_period = 0.0;
  EXPECT_FALSE(Simulate(options, 8, &session, &error));
  EXPECT_NE(error.find("slow_line_period"), std::string::npos) << error;
}

}  // namespace
}  // namespace gravcal
