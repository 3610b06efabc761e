#include "gravcal/estimation/static_alignment.h"

#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/warnings.h"
#include "util/so3.h"
#include "util/units.h"

namespace gravcal {
namespace {

using internal::kDegToRad;
using internal::Skew;

// A mean specific force further than this from g (relative) is not a unit
// at rest, or the data is not in m/s^2.
constexpr double kMaxGravityMismatch = 0.2;
// Prior of the heading error when heading is not observed: it couples to
// nothing then, so any value works; 1 rad keeps the numbers tame.
constexpr double kUnobservedHeadingVariance = 1.0;

Eigen::Matrix3d Exp(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  if (angle < 1e-300) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, v / angle).toRotationMatrix();
}

Eigen::Vector3d RollPitchHeadingOf(const Eigen::Matrix3d& c) {
  return Eigen::Vector3d(std::atan2(c(2, 1), c(2, 2)),
                         std::atan2(-c(2, 0), std::hypot(c(2, 1), c(2, 2))),
                         std::atan2(c(1, 0), c(0, 0)));
}

// Per-sample white noise: the mean over axes of the sample variance.
double NoiseLevel(const std::vector<Eigen::Vector3d>& x) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double sum = 0.0;
  for (const Eigen::Vector3d& v : x) sum += (v - mean).squaredNorm();
  return std::sqrt(sum / (3.0 * static_cast<double>(x.size() - 1)));
}

Eigen::Vector3d Mean(const std::vector<Eigen::Vector3d>& x, size_t begin, size_t end) {
  Eigen::Vector3d m = Eigen::Vector3d::Zero();
  for (size_t i = begin; i < end; ++i) m += x[i];
  return m / static_cast<double>(end - begin);
}

using Matrix12 = Eigen::Matrix<double, 12, 12>;
using Vector12 = Eigen::Matrix<double, 12, 1>;
using Measurement3 = Eigen::Matrix<double, 3, 12>;

// Kalman update with z = H dx + noise(R): P -= P H^T S^-1 H P (kept
// symmetric); returns the state correction K z.
Vector12 KalmanUpdate(const Measurement3& h, const Eigen::Vector3d& z, const Eigen::Matrix3d& r,
                      Matrix12* p) {
  const Eigen::Matrix<double, 12, 3> ph = p->selfadjointView<Eigen::Upper>() * h.transpose();
  const Eigen::Matrix3d s = h * ph + r;
  const Eigen::Matrix<double, 12, 3> k = ph * s.inverse();
  p->triangularView<Eigen::Upper>() -= k * ph.transpose();
  return k * z;
}

// P <- F P F^T for F = I + E, where E (dt times the static-base model) is
// non-zero only in rows 3-5 (velocity), columns 0-2 (attitude) and 6-8
// (accelerometer bias): P + E P + (E P)^T + E P E^T, on the upper triangle.
void Propagate(const Eigen::Matrix3d& e_phi, const Eigen::Matrix3d& e_bias, Matrix12* p) {
  const Matrix12 full = p->selfadjointView<Eigen::Upper>();
  const Eigen::Matrix<double, 3, 12> ep =
      e_phi * full.middleRows<3>(0) + e_bias * full.middleRows<3>(6);
  const Eigen::Matrix3d epe =
      ep.middleCols<3>(0) * e_phi.transpose() + ep.middleCols<3>(6) * e_bias.transpose();
  Matrix12 next = full;
  next.middleRows<3>(3) += ep;
  next.middleCols<3>(3) += ep.transpose();
  next.block<3, 3>(3, 3) += epe;
  p->triangularView<Eigen::Upper>() = next;
}

Eigen::Vector3d Log(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

// The coarse attitude from the mean specific force f and, when heading is
// gyrocompassed, the mean body rate w (levelled rate w^l = R_y R_x w reads
// Earth rate (W_h sin h, W_h cos h, .)).
Eigen::Matrix3d CoarseAttitude(const Eigen::Vector3d& f, const Eigen::Vector3d& w,
                               bool gyrocompass) {
  const double roll = std::atan2(f(1), f(2));
  const double pitch = std::atan2(-f(0), std::hypot(f(1), f(2)));
  const Eigen::Matrix3d level = (Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                    .toRotationMatrix();
  double heading = 0.0;
  if (gyrocompass) {
    const Eigen::Vector3d wl = level * w;
    heading = std::atan2(wl(0), wl(1));
  }
  return Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()) * level;
}

}  // namespace

bool StaticAlignmentOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& what) {
    if (error) *error = "alignment: " + what;
    return false;
  };
  if (!(gravity > 0.0) || !std::isfinite(gravity)) return fail("gravity must be positive");
  if (!std::isnan(latitude_deg) && !(std::fabs(latitude_deg) <= 90.0)) {
    return fail("latitude must be within -90..90 degrees");
  }
  if (!(accel_bias_std > 0.0) || !std::isfinite(accel_bias_std)) {
    return fail("align_accel_bias_std must be positive (the accelerometer bias prior, m/s^2)");
  }
  if (!(accel_matrix_std >= 0.0) || !std::isfinite(accel_matrix_std)) {
    return fail("align_accel_matrix_std must be zero or positive");
  }
  if (!(gyro_bias_std > 0.0) || !std::isfinite(gyro_bias_std)) {
    return fail("align_gyro_bias_std must be positive (rad/s)");
  }
  if (!std::isfinite(accel_noise) || !std::isfinite(gyro_noise)) {
    return fail("noise levels must be finite");
  }
  if (!(max_heading_std_deg > 0.0)) return fail("align_max_heading_std must be positive");
  if (!(coarse_seconds > 0.0) || !std::isfinite(coarse_seconds)) {
    return fail("align_coarse_seconds must be positive");
  }
  if (!(zero_velocity_std > 0.0) || !std::isfinite(zero_velocity_std)) {
    return fail("align_zero_velocity_std must be positive");
  }
  return true;
}

Eigen::Vector3d RollPitchHeading(const Eigen::Quaterniond& attitude) {
  return RollPitchHeadingOf(attitude.toRotationMatrix());
}

Eigen::Quaterniond AttitudeFromRollPitchHeading(double roll, double pitch, double heading) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
}

namespace {

// Checks the samples and options; the message says what is wrong.
bool CheckAlignmentInput(const std::vector<Eigen::Vector3d>& specific_force,
                         const std::vector<Eigen::Vector3d>& rate, double dt,
                         const StaticAlignmentOptions& options, std::string* message) {
  if (!options.IsValid(message)) return false;
  const size_t n = specific_force.size();
  if (n < 10) {
    *message = "alignment needs at least 10 samples, got " + std::to_string(n);
    return false;
  }
  if (!rate.empty() && rate.size() != n) {
    *message = "alignment: rate and specific force have different lengths";
    return false;
  }
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    *message = "alignment: the sample period must be positive";
    return false;
  }
  for (size_t i = 0; i < n; ++i) {
    if (!specific_force[i].allFinite() || (!rate.empty() && !rate[i].allFinite())) {
      *message = "alignment: sample " + std::to_string(i) + " is not finite";
      return false;
    }
  }
  const Eigen::Vector3d mean_force = Mean(specific_force, 0, n);
  if (std::fabs(mean_force.norm() / options.gravity - 1.0) > kMaxGravityMismatch) {
    std::ostringstream s;
    s << "alignment: the mean specific force is " << mean_force.norm()
      << " m/s^2, not near g = " << options.gravity
      << ": the interval is not static or the data is not scaled to m/s^2";
    *message = s.str();
    return false;
  }
  return true;
}

// The coarse solution on the first n0 samples and how errors in that
// window's means move it.
struct CoarseSolution {
  size_t n0 = 0;
  Eigen::Vector3d w0 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d c = Eigen::Matrix3d::Identity();
  // phi = A e_a + B e_g (see CoarseAlign).
  Eigen::Matrix3d a_sens = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d b_sens = Eigen::Matrix3d::Zero();
};

// Coarse alignment on the first samples; the filter runs on the rest, so the
// two see independent noise. Fills the coarse angles, the would-be
// gyrocompass heading std and heading_observed of `r`.
CoarseSolution CoarseAlign(const std::vector<Eigen::Vector3d>& specific_force,
                           const std::vector<Eigen::Vector3d>& rate, double dt, bool gyro,
                           const StaticAlignmentOptions& options, StaticAlignmentResult* r) {
  const size_t n = specific_force.size();
  const double g = options.gravity;
  CoarseSolution coarse;
  coarse.n0 =
      std::clamp<size_t>(static_cast<size_t>(std::lround(options.coarse_seconds / dt)), 1, n / 2);
  const size_t n0 = coarse.n0;
  const Eigen::Vector3d f0 = Mean(specific_force, 0, n0);
  r->coarse_roll = std::atan2(f0(1), f0(2));
  r->coarse_pitch = std::atan2(-f0(0), std::hypot(f0(1), f0(2)));
  const bool have_latitude = std::isfinite(options.latitude_deg);
  const double latitude = have_latitude ? options.latitude_deg * kDegToRad : 0.0;
  const double earth_horizontal = kEarthRate * std::fabs(std::cos(latitude));
  const double gyro_bias_var = options.gyro_bias_std * options.gyro_bias_std;
  const double gyro_noise_var = r->gyro_noise * r->gyro_noise;
  coarse.w0 = gyro ? Mean(rate, 0, n0) : Eigen::Vector3d::Zero();
  const Eigen::Vector3d& w0 = coarse.w0;
  if (gyro && have_latitude && earth_horizontal > 0.0) {
    r->gyrocompass_heading_std =
        std::sqrt(gyro_bias_var + gyro_noise_var / static_cast<double>(n - n0)) / earth_horizontal;
    r->heading_observed = r->gyrocompass_heading_std < options.max_heading_std_deg * kDegToRad;
  }
  coarse.c = CoarseAttitude(f0, w0, r->heading_observed);
  const Eigen::Matrix3d& c = coarse.c;
  r->coarse_heading = RollPitchHeadingOf(c)(2);
  // How errors e_a, e_g in the coarse window's means move the coarse
  // attitude: phi = A e_a + B e_g, C_true = Exp(phi) C_est, the true
  // attitude being the one the means without error give (central
  // differences; the accelerometer moves the tilt and, through the levelling,
  // the gyrocompass heading).
  // Linearised at the true specific force's magnitude g: then the tilt rows
  // are exactly those of the velocity model below (dv' = [f^n x] phi +
  // C db_a), so the unobservable tilt-bias direction stays unobservable.
  const Eigen::Vector3d f0g = f0 * (g / f0.norm());
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d df = 1e-6 * g * Eigen::Vector3d::Unit(k);
    coarse.a_sens.col(k) =
        (Log(CoarseAttitude(f0g - df, w0, r->heading_observed) * c.transpose()) -
         Log(CoarseAttitude(f0g + df, w0, r->heading_observed) * c.transpose())) /
        (2e-6 * g);
    if (r->heading_observed) {
      const Eigen::Vector3d dw = 1e-6 * w0.norm() * Eigen::Vector3d::Unit(k);
      coarse.b_sens.col(k) = (Log(CoarseAttitude(f0g, w0 - dw, true) * c.transpose()) -
                              Log(CoarseAttitude(f0g, w0 + dw, true) * c.transpose())) /
                             (2e-6 * w0.norm());
    }
  }
  return coarse;
}

// Earth rate the model accounts for (navigation frame): all of it when
// heading is observed, else its vertical part; the rest is in the gyro bias,
// whose prior grows by `unmodelled_var`.
Eigen::Vector3d ModelledEarthRate(const StaticAlignmentOptions& options, bool heading_observed,
                                  double* unmodelled_var) {
  Eigen::Vector3d earth = Eigen::Vector3d::Zero();
  *unmodelled_var = 0.0;
  if (std::isfinite(options.latitude_deg)) {
    const double latitude = options.latitude_deg * kDegToRad;
    const double earth_horizontal = kEarthRate * std::fabs(std::cos(latitude));
    earth(2) = kEarthRate * std::sin(latitude);
    if (heading_observed) {
      earth(1) = kEarthRate * std::cos(latitude);
    } else {
      *unmodelled_var = earth_horizontal * earth_horizontal;
    }
  } else {
    *unmodelled_var = kEarthRate * kEarthRate;
  }
  return earth;
}

// The filter's initial covariance. Error state: phi 0-2, dv 3-5, db_a 6-8,
// db_g 9-11 (without a gyroscope the last block stays at zero covariance and
// nothing couples to it). The coarse errors are made by the biases and the
// coarse window's mean noise (A, B), so the filter starts with exactly the
// correlation the coarse solution has: a static base cannot undo it.
// Without gyrocompassing heading is a convention (0), not an estimate: its
// error is independent of everything and never corrected.
Matrix12 InitialCovariance(const CoarseSolution& coarse, bool gyro, double earth_unmodelled_var,
                           const StaticAlignmentOptions& options, const StaticAlignmentResult& r) {
  const double g = options.gravity;
  Matrix12 p = Matrix12::Zero();
  const double bias_var = options.accel_bias_std * options.accel_bias_std +
                          options.accel_matrix_std * options.accel_matrix_std * g * g;
  const Eigen::Matrix3d p_ba = bias_var * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d noise0 =
      r.accel_noise * r.accel_noise / static_cast<double>(coarse.n0) * Eigen::Matrix3d::Identity();
  Eigen::Matrix3d a_sens = coarse.a_sens;
  if (!r.heading_observed) a_sens.row(2).setZero();
  p.block<3, 3>(0, 0) = a_sens * (p_ba + noise0) * a_sens.transpose();
  p.block<3, 3>(0, 6) = a_sens * p_ba;
  p.block<3, 3>(6, 0) = p.block<3, 3>(0, 6).transpose();
  p.block<3, 3>(6, 6) = p_ba;
  if (!r.heading_observed) p(2, 2) = kUnobservedHeadingVariance;
  if (gyro) {
    const double gyro_bias_var = options.gyro_bias_std * options.gyro_bias_std;
    const double gyro_noise_var = r.gyro_noise * r.gyro_noise;
    const Eigen::Matrix3d p_bg =
        (gyro_bias_var + earth_unmodelled_var) * Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d noise_g0 =
        gyro_noise_var / static_cast<double>(coarse.n0) * Eigen::Matrix3d::Identity();
    p.block<3, 3>(0, 0) += coarse.b_sens * (p_bg + noise_g0) * coarse.b_sens.transpose();
    p.block<3, 3>(0, 9) = coarse.b_sens * p_bg;
    p.block<3, 3>(9, 0) = p.block<3, 3>(0, 9).transpose();
    p.block<3, 3>(9, 9) = p_bg;
  }
  return p;
}

// The filter's estimates after the last sample.
struct FineSolution {
  Eigen::Matrix3d c_est = Eigen::Matrix3d::Identity();
  Eigen::Vector3d ba = Eigen::Vector3d::Zero();
  Eigen::Vector3d bg = Eigen::Vector3d::Zero();
  Matrix12 p = Matrix12::Zero();
};

// The attitude of a static base does not change: the filter holds it and
// learns from the velocity the accelerometer integrates (zero-velocity
// update, every sample) and, with a gyroscope, from its rate (zero angular
// rate update: u - b_g = C^T w_ie, every sample).
FineSolution RunFineFilter(const std::vector<Eigen::Vector3d>& specific_force,
                           const std::vector<Eigen::Vector3d>& rate, double dt, bool gyro,
                           const CoarseSolution& coarse, const Eigen::Vector3d& earth, Matrix12 p,
                           const StaticAlignmentOptions& options, StaticAlignmentResult* r) {
  const size_t n = specific_force.size();
  const Eigen::Matrix3d& c = coarse.c;
  const bool heading_observed = r->heading_observed;
  FineSolution fine;
  fine.c_est = c;
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  const Eigen::Vector3d gravity_n(0.0, 0.0, options.gravity);
  const double qv = r->accel_noise * r->accel_noise * dt * dt;
  const Eigen::Matrix3d r_velocity =
      options.zero_velocity_std * options.zero_velocity_std * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d r_rate = r->gyro_noise * r->gyro_noise * Eigen::Matrix3d::Identity();
  // dv' = [f^n x] phi + C db_a with the static base's f^n = (0, 0, g).
  const Eigen::Matrix3d e_phi = Skew(gravity_n) * dt;
  // Closed loop: apply a correction and reset the error state.
  auto correct = [&](const Vector12& dx) {
    Eigen::Vector3d dphi = dx.head<3>();
    if (!heading_observed) dphi(2) = 0.0;
    fine.c_est = Exp(dphi) * fine.c_est;
    v -= dx.segment<3>(3);
    fine.ba += dx.segment<3>(6);
    fine.bg += dx.segment<3>(9);
  };
  Measurement3 h_velocity = Measurement3::Zero();
  h_velocity.block<3, 3>(0, 3).setIdentity();
  Measurement3 h_rate = Measurement3::Zero();
  h_rate.block<3, 3>(0, 9).setIdentity();
  for (size_t i = coarse.n0; i < n; ++i) {
    v += (fine.c_est * (specific_force[i] - fine.ba) - gravity_n) * dt;
    // Jacobians at the coarse attitude, not the current estimate (first
    // estimates): the corrections rotate the estimate, and Jacobians that
    // followed them would make the tilt/bias/heading direction no static
    // base can see look observable (measured: heading sigma 3-5x too small
    // with a navigation-grade gyroscope).
    Propagate(e_phi, c * dt, &p);
    p.block<3, 3>(3, 3).diagonal().array() += qv;
    // The two measurements have independent noise: one after the other.
    correct(KalmanUpdate(h_velocity, v, r_velocity, &p));
    if (gyro) {
      // u - b_g - C_est^T w = db_g + C_est^T [w x] phi + noise, from
      // C_true^T = C_est^T (I - [phi x]).
      h_rate.block<3, 3>(0, 0) = c.transpose() * Skew(earth);  // first estimate, as above
      correct(KalmanUpdate(h_rate, rate[i] - fine.bg - fine.c_est.transpose() * earth, r_rate, &p));
    }
    ++r->filter_updates;
  }
  fine.p = Matrix12(p.selfadjointView<Eigen::Upper>());
  return fine;
}

// Angles, covariances and biases of the result from the filter's estimates.
void FillAlignmentResult(const FineSolution& fine, bool gyro, double gravity,
                         StaticAlignmentResult* r) {
  const Eigen::Vector3d rph = RollPitchHeadingOf(fine.c_est);
  r->roll = rph(0);
  r->pitch = rph(1);
  r->heading = r->heading_observed ? rph(2) : 0.0;
  r->attitude = AttitudeFromRollPitchHeading(r->roll, r->pitch, r->heading);
  r->attitude_covariance = fine.p.block<3, 3>(0, 0);
  // d(roll, pitch, heading)/d(phi), C' = Exp(phi) C, by central differences.
  Eigen::Matrix3d j;
  const double eps = 1e-6;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = eps * Eigen::Vector3d::Unit(k);
    Eigen::Vector3d d =
        RollPitchHeadingOf(Exp(e) * fine.c_est) - RollPitchHeadingOf(Exp(-e) * fine.c_est);
    for (int a = 0; a < 3; ++a) d(a) = std::remainder(d(a), 2.0 * M_PI);
    j.col(k) = d / (2.0 * eps);
  }
  const Eigen::Matrix3d angle_cov = j * r->attitude_covariance * j.transpose();
  r->roll_pitch_covariance = angle_cov.topLeftCorner<2, 2>();
  r->roll_std = std::sqrt(angle_cov(0, 0));
  r->pitch_std = std::sqrt(angle_cov(1, 1));
  r->heading_std = r->heading_observed ? std::sqrt(angle_cov(2, 2)) : NAN;
  const Eigen::Vector3d gravity_n(0.0, 0.0, gravity);
  const Eigen::Matrix3d c_out = r->attitude.toRotationMatrix();
  r->gravity_body = c_out.transpose() * gravity_n;
  const Eigen::Matrix3d dg = c_out.transpose() * Skew(gravity_n);
  r->gravity_body_covariance = dg * r->attitude_covariance * dg.transpose();
  r->accel_bias = fine.ba;
  r->accel_bias_std = fine.p.block<3, 3>(6, 6).diagonal().cwiseSqrt();
  if (gyro) {
    r->gyro_bias = fine.bg;
    r->gyro_bias_std = fine.p.block<3, 3>(9, 9).diagonal().cwiseSqrt();
  }
}

// No static base resolves the east components of the biases (the classic
// alignment limit): an accelerometer bias along east tilts the levelling by
// b_a / g, which Earth's vertical rate turns into a gyrocompass heading
// error tan(latitude) b_a / g; a gyroscope bias along east reads as north
// Earth rate, b_g / (W cos(latitude)). The filter's covariance, linearised
// at the coarse attitude, loses part of this with a large accelerometer
// bias (measured at 0.3 m/s^2: 1.1-1.7 deg reported against the 1.75 deg
// limit, and an rms error of 1.9 deg), so the heading sigma is held at
// least at the limit:
//   sigma_h^2 >= (tan(lat) sqrt(b_a^2 + m_a^2 g^2) / g)^2 + (b_g / (W cos(lat)))^2
// with b_a, m_a and b_g the priors (accel_bias_std, accel_matrix_std,
// gyro_bias_std).
void HoldHeadingStdAtTheStaticLimit(const StaticAlignmentOptions& options,
                                    StaticAlignmentResult* r) {
  const double g = options.gravity;
  const double latitude = options.latitude_deg * kDegToRad;
  const double accel = std::sqrt(options.accel_bias_std * options.accel_bias_std +
                                 options.accel_matrix_std * options.accel_matrix_std * g * g);
  const double tilt_part = std::tan(latitude) * accel / g;
  const double gyro_part = options.gyro_bias_std / (kEarthRate * std::fabs(std::cos(latitude)));
  const double limit = std::hypot(tilt_part, gyro_part);
  if (std::isfinite(limit) && !(r->heading_std >= limit)) r->heading_std = limit;
}

// The warnings of a successful alignment: a roll that is not defined, a
// heading that was not observed and why.
void AddAlignmentWarnings(bool gyro, const StaticAlignmentOptions& options,
                          StaticAlignmentResult* r) {
  if (std::fabs(std::cos(r->pitch)) < 0.05) {
    internal::AddWarning(WarningCode::kAlignment,
                         "pitch is near +-90 degrees: roll is not defined there (its standard "
                         "deviation says so); the gravity direction is still determined",
                         &r->warnings, &r->warning_codes);
  }
  if (r->heading_observed) return;
  std::ostringstream s;
  s.precision(3);
  s << "heading not observed (set to 0): ";
  if (!gyro) {
    s << "no gyroscope";
  } else if (!std::isfinite(options.latitude_deg)) {
    s << "no latitude given for gyrocompassing";
  } else {
    s << "gyrocompassing would give " << r->gyrocompass_heading_std / kDegToRad
      << " deg, above align_max_heading_std " << options.max_heading_std_deg
      << " deg (gyroscope bias and noise against Earth rate)";
  }
  internal::AddWarning(WarningCode::kAlignment, s.str(), &r->warnings, &r->warning_codes);
}

}  // namespace

bool AlignStatic(const std::vector<Eigen::Vector3d>& specific_force,
                 const std::vector<Eigen::Vector3d>& rate, double dt,
                 const StaticAlignmentOptions& options, StaticAlignmentResult* result) {
  CHECK(result != nullptr);
  *result = StaticAlignmentResult();
  StaticAlignmentResult& r = *result;
  if (!CheckAlignmentInput(specific_force, rate, dt, options, &r.message)) return false;
  const bool gyro = options.use_gyro && !rate.empty();
  r.accel_noise = options.accel_noise > 0.0 ? options.accel_noise : NoiseLevel(specific_force);
  r.accel_noise = std::max(r.accel_noise, 1e-9);
  if (gyro) {
    r.gyro_noise = options.gyro_noise > 0.0 ? options.gyro_noise : NoiseLevel(rate);
    r.gyro_noise = std::max(r.gyro_noise, 1e-12);
  }
  const CoarseSolution coarse = CoarseAlign(specific_force, rate, dt, gyro, options, &r);
  double earth_unmodelled_var = 0.0;
  const Eigen::Vector3d earth =
      ModelledEarthRate(options, r.heading_observed, &earth_unmodelled_var);
  const Matrix12 p0 = InitialCovariance(coarse, gyro, earth_unmodelled_var, options, r);
  const FineSolution fine =
      RunFineFilter(specific_force, rate, dt, gyro, coarse, earth, p0, options, &r);
  FillAlignmentResult(fine, gyro, options.gravity, &r);
  if (r.heading_observed) HoldHeadingStdAtTheStaticLimit(options, &r);
  AddAlignmentWarnings(gyro, options, &r);
  if (!fine.c_est.allFinite() || !fine.p.allFinite()) {
    r.message = "alignment: the filter diverged";
    return false;
  }
  r.success = true;
  std::ostringstream s;
  s.precision(4);
  s << "aligned on " << specific_force.size() << " samples: roll " << r.roll / kDegToRad << " +- "
    << r.roll_std / kDegToRad << " deg, pitch " << r.pitch / kDegToRad << " +- "
    << r.pitch_std / kDegToRad << " deg";
  r.message = s.str();
  return true;
}

}  // namespace gravcal
