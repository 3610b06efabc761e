// Helpers shared by the tests.
#ifndef GRAVCAL_TESTS_TEST_UTIL_H_
#define GRAVCAL_TESTS_TEST_UTIL_H_

#include <sys/stat.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/gravity.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/position.h"
#include "gravcal/estimation/refinement.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "util/random_vector.h"

namespace gravcal {
namespace testing_util {

// The folder for scratch files, $TMPDIR (/tmp when unset), with a trailing
// '/'. Tests and benchmarks never hard-code /tmp.
inline std::string ScratchFolder() {
  const char* dir = std::getenv("TMPDIR");
  std::string folder = dir != nullptr && *dir != '\0' ? dir : "/tmp";
  if (folder.back() != '/') folder += '/';
  return folder;
}

// A mkstemp() template for a scratch file: "<ScratchFolder()><stem>XXXXXX".
inline std::string ScratchFileTemplate(const std::string& stem) {
  return ScratchFolder() + stem + "XXXXXX";
}

// A 16-bit accelerometer at +-2 g full scale: m/s^2 per count.
constexpr double kCountScale = kStandardGravity / 16384.0;

// The free magnitude parameters (b, free entries of U) of a model, in the
// order of the refinement's covariance.
inline Eigen::VectorXd FreeParameters(const AccelModel& m, AccelParameterization p) {
  const std::vector<int> free = FreeUpperIndices(p);
  Eigen::VectorXd x(3 + free.size());
  x.head<3>() = m.bias;
  double u[6];
  m.GetUpper(u);
  for (size_t i = 0; i < free.size(); ++i) x(3 + i) = u[free[i]];
  return x;
}

// A uniformly random unit vector.
inline Eigen::Vector3d RandomDirection(std::mt19937_64* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d v = internal::DrawVector3([&] { return n(*rng); });
  return v.normalized();
}

// The twelve directions of gravity in the body frame of Chen et al.: six
// faces and six 45-degree poses.
inline std::vector<Eigen::Vector3d> TwelveDirections() {
  const double c = std::sqrt(0.5);
  return {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1},
          {c, c, 0}, {-c, c, 0}, {0, c, c}, {0, -c, c}, {c, 0, c}, {c, 0, -c}};
}

// Static positions of a sensor `truth` whose body frame sees gravity along
// `directions` (unit, body frame), each tilted by N(0, tilt_rad) per axis,
// with `samples` samples of white noise `noise_si` (m/s^2 per sample) each:
// the mean raw vector gets noise of the mean and the covariance of the mean
// is the exact one. nominal_up is set for axis directions when
// `set_nominal` is true.
inline std::vector<Position> MakePositions(const AccelModel& truth,
                                           const std::vector<Eigen::Vector3d>& directions,
                                           double gravity, double tilt_rad, double noise_si,
                                           int samples, bool set_nominal, std::mt19937_64* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  // Raw noise: the truth's inverse maps SI noise into raw units.
  const Eigen::Matrix3d minv = truth.matrix().inverse();
  const Eigen::Matrix3d raw_cov = noise_si * noise_si * minv * minv.transpose();
  const Eigen::Matrix3d raw_cov_mean = raw_cov / samples;
  const Eigen::Matrix3d l = raw_cov_mean.llt().matrixL();
  std::vector<Position> out;
  for (size_t k = 0; k < directions.size(); ++k) {
    const Eigen::Vector3d tilt = tilt_rad * internal::DrawVector3([&] { return n(*rng); });
    const Eigen::Matrix3d r =
        tilt.norm() > 0 ? Eigen::AngleAxisd(tilt.norm(), tilt.normalized()).toRotationMatrix()
                        : Eigen::Matrix3d::Identity();
    const Eigen::Vector3d f = gravity * (r * directions[k]);
    Position p;
    p.raw_mean = truth.Invert(f) + l * internal::DrawVector3([&] { return n(*rng); });
    p.raw_mean_cov = raw_cov_mean;
    p.sample_count = samples;
    p.t_begin = 10.0 * k;
    p.t_end = 10.0 * k + 5.0;
    if (set_nominal) {
      for (int a = 0; a < 6; ++a) {
        if ((directions[k] - NominalAxis(a)).norm() < 1e-9) p.nominal_up = a;
      }
    }
    out.push_back(p);
  }
  return out;
}

// The folder of real recordings, or "" when it is not there (tests skip).
inline std::string RealDataDir() {
  struct stat st;
  const std::string dir = GRAVCAL_REAL_DATA_DIR;
  if (stat(dir.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) return dir;
  return "";
}

inline std::string SourceDir() { return GRAVCAL_SOURCE_DIR; }

// A real recording with its shipped config: loads configs/<config_name>,
// then reads <RealDataDir()>/<file> with the config's input settings.
inline bool LoadRealSession(const std::string& config_name, const std::string& file, Config* config,
                            ImuLog* log, std::string* error) {
  return LoadConfigFile(SourceDir() + "/configs/" + config_name, config, error) &&
         ReadImuLog(RealDataDir() + "/" + file, config->input, log, error);
}

// The angle (rad, in [0, pi]) of the rotation between two attitudes.
inline double QuaternionAngle(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b);
}

// Adds every entry of `error` / `sigma` to an error/sigma accumulator
// (SigmaCheck) as "<name>(r,c)", or "<name>(i)" for a vector.
template <class Check>
void AddEach(Check* check, const std::string& name, const Eigen::MatrixXd& error,
             const Eigen::MatrixXd& sigma) {
  for (int r = 0; r < error.rows(); ++r) {
    for (int c = 0; c < error.cols(); ++c) {
      const std::string index =
          error.cols() == 1 ? std::to_string(r) : std::to_string(r) + "," + std::to_string(c);
      check->Add(name + "(" + index + ")", error(r, c), sigma(r, c));
    }
  }
}

// --- Counts of successes over independent trials ---------------------------
//
// A test that counts how often a method succeeds over n independent trials
// states the method's success probability p per trial (from the method's
// design, e.g. its significance level, or from a larger measured run that
// the test's comment records) and derives its threshold from the binomial
// distribution, so that an honest method fails the test with probability
// below kCountFailureProbability (the same 0.001 as SigmaCheck's band).
constexpr double kCountFailureProbability = 0.001;

// P(X = k) for X ~ Binomial(n, p).
inline double BinomialProbability(int n, double p, int k) {
  if (k < 0 || k > n) return 0.0;
  if (p <= 0.0) return k == 0 ? 1.0 : 0.0;
  if (p >= 1.0) return k == n ? 1.0 : 0.0;
  return std::exp(std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0) +
                  k * std::log(p) + (n - k) * std::log1p(-p));
}

// The successes out of n that a method succeeding with probability p per
// trial reaches except with probability below `alpha`: the largest k with
// P(X < k) < alpha.
inline int RequiredSuccesses(int n, double p, double alpha = kCountFailureProbability) {
  double below = 0.0;  // P(X < k)
  int k = 0;
  while (k < n && below + BinomialProbability(n, p, k) < alpha) {
    below += BinomialProbability(n, p, k);
    ++k;
  }
  return k;
}

// The successes out of n that a method succeeding with probability at most p
// per trial exceeds only with probability below `alpha`: the smallest m with
// P(X > m) < alpha.
inline int AllowedSuccesses(int n, double p, double alpha = kCountFailureProbability) {
  return n - RequiredSuccesses(n, 1.0 - p, alpha);
}

// Issue 6: 24 random poses held 10 s during a warm-up from 20 to 35 degC
// (time constant 120 s), so temperature and time both vary and are not
// proportional: the session in which hidden effects are looked for.
inline SimulatorOptions WarmUpSession() {
  SimulatorOptions o;
  o.scheme = {PoseScheme::kRandom, 24};
  o.hold_seconds = 10.0;
  o.initial_still_seconds = 5.0;
  o.rotation_seconds = 2.0;
  o.temperature_start = 20.0;
  o.temperature_end = 35.0;
  o.temperature_tau = 120.0;
  return o;
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_TEST_UTIL_H_
