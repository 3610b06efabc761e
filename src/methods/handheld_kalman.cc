#include "gravcal/methods/handheld_kalman.h"

#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>

#include "core/calibration_gravity.h"
#include "gravcal/estimation/strapdown.h"

namespace gravcal {
namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat9X = Eigen::Matrix<double, 9, Eigen::Dynamic>;

constexpr const char* kAxes = "xyz";
// Still-period checks: rms deviation from the mean above these is not still.
constexpr double kStillAccelRms = 0.5;  // m/s^2
constexpr double kStillGyroRms = 0.1;   // rad/s
// A sample interval longer than this many nominal intervals is a gap.
constexpr double kGapFactor = 20.0;

Mat3 Skew(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// One sensor's current estimate: y_hat = (I + E)^-1 (y_m - b).
struct SensorEstimate {
  Vec3 bias = Vec3::Zero();
  Mat3 e = Mat3::Zero();
  Mat3 inverse = Mat3::Identity();

  Vec3 Correct(const Vec3& measured) const { return inverse * (measured - bias); }
  void Refresh() { inverse = (Mat3::Identity() + e).inverse(); }
};

// The transition of one IMU step on the navigation error rows, A_k =
//   [[I - dt W,        0,            0],
//    [dt [(C f) x],    I - 2 dt W,   0],
//    [0,               dt I,         I]]      (W = [w_ie x]),
// applied to the rows of a 9-row matrix: x <- A_k x.
struct NavigationStep {
  double dt = 0.0;
  Mat3 velocity_from_attitude;  // dt [(C f) x]
  bool earth_rate = false;
  Mat3 attitude_attitude;  // I - dt W
  Mat3 velocity_velocity;  // I - 2 dt W

  template <typename Matrix>
  void Apply(Matrix* x) const {
    auto phi = x->template topRows<3>();
    auto vel = x->template middleRows<3>(3);
    auto pos = x->template bottomRows<3>();
    pos += dt * vel;
    if (earth_rate) {
      const Eigen::Matrix<double, 3, Matrix::ColsAtCompileTime> v_old = vel;
      vel.noalias() = velocity_velocity * v_old;
      vel.noalias() += velocity_from_attitude * phi;
      const Eigen::Matrix<double, 3, Matrix::ColsAtCompileTime> phi_old = phi;
      phi.noalias() = attitude_attitude * phi_old;
    } else {
      vel.noalias() += velocity_from_attitude * phi;
    }
  }
};

StrapdownOptions StrapdownFor(const HandheldKalmanOptions& options, double gravity) {
  StrapdownOptions s;
  s.gravity = gravity;
  s.earth_rate = options.earth_rate;
  s.latitude_deg = options.gravity.latitude;
  return s;
}

// The error-state filter over one pass of the log (see handheld_kalman.h).
class Filter {
 public:
  Filter(const HandheldKalmanOptions& options, double gravity, const ErrorStateLayout& layout)
      : options_(options), layout_(layout), strapdown_(StrapdownFor(options, gravity)) {
    const int n = layout_.size();
    p_.setZero(n, n);
    b_.setZero(9, n - 9);
    a_.setIdentity();
    q_.setZero();
    joseph_.setZero(n, n);
    h_.setZero(6, n);
  }

  // Starts from sensor estimates (accel, gyro) at the coarse levelling of
  // the mean measured specific force f_mean of the still period, corrected
  // with `accel`.
  void Initialize(const Vec3& f_mean, const SensorEstimate& accel, const SensorEstimate& gyro) {
    accel_ = accel;
    gyro_ = gyro;
    lever_.setZero();
    rate_.setZero();
    const Vec3 f0 = accel_.Correct(f_mean);
    const Eigen::Quaterniond q0 = LevelAttitude(f0);
    NavigationState start;
    start.attitude = q0;
    strapdown_.SetState(start);
    const int n = layout_.size();
    Eigen::VectorXd prior(n);
    auto set = [&](StateBlock block, double std) {
      prior.segment(layout_.offset(block), layout_.block_size(block)).setConstant(std * std);
    };
    set(StateBlock::kAttitude, options_.initial_attitude_std);
    set(StateBlock::kVelocity, options_.velocity_noise);
    set(StateBlock::kPosition, options_.position_noise);
    set(StateBlock::kAccelBias, options_.accel_bias_std);
    set(StateBlock::kGyroBias, options_.gyro_bias_std);
    auto set_matrix = [&](StateBlock block, const SensorErrorTerms& terms, double scale_std) {
      const int offset = layout_.offset(block);
      for (size_t j = 0; j < terms.matrix_entries.size(); ++j) {
        const bool diagonal = terms.matrix_entries[j].first == terms.matrix_entries[j].second;
        const double std = diagonal ? scale_std : options_.cross_axis_std;
        prior(offset + static_cast<int>(j)) = std * std;
      }
    };
    set_matrix(StateBlock::kAccelMatrix, layout_.accel(), options_.accel_scale_std);
    set_matrix(StateBlock::kGyroMatrix, layout_.gyro(), options_.gyro_scale_std);
    if (layout_.block_size(StateBlock::kLeverArm) > 0) {
      set(StateBlock::kLeverArm, options_.lever_arm_std);
    }
    // phi = phi_independent + L C0 df, df = -(I + E)^-1 (db_a + dE_a f0),
    // with phi_x = -(C0 df)_y / g and phi_y = (C0 df)_x / g.
    const double g = f0.norm();
    Mat3 l = Mat3::Zero();
    l(0, 1) = -1.0 / g;
    l(1, 0) = 1.0 / g;
    const Mat3 lc = l * q0.toRotationMatrix() * accel_.inverse;
    Eigen::MatrixXd t = Eigen::MatrixXd::Identity(n, n);
    t.block<3, 3>(0, layout_.offset(StateBlock::kAccelBias)) = -lc;
    const int am = layout_.offset(StateBlock::kAccelMatrix);
    for (size_t j = 0; j < layout_.accel().matrix_entries.size(); ++j) {
      const auto [r, c] = layout_.accel().matrix_entries[j];
      t.block<3, 1>(0, am + static_cast<int>(j)) = -lc.col(r) * f0(c);
    }
    // With a lever arm the navigation origin is the turning point and the
    // sensor starts at C0 r, estimated 0: dp0 = -C0 r = C0 dr.
    if (layout_.block_size(StateBlock::kLeverArm) > 0) {
      t.block<3, 3>(6, layout_.offset(StateBlock::kLeverArm)) = q0.toRotationMatrix();
    }
    p_ = t * prior.asDiagonal() * t.transpose();
    p_initial_ = p_;
  }

  // One IMU step from sample (f0, w0) to (f1, w1), measured values in SI.
  void Step(double dt, const Vec3& f0_m, const Vec3& w0_m, const Vec3& f1_m, const Vec3& w1_m) {
    const Vec3 f0 = accel_.Correct(f0_m);
    const Vec3 f1 = accel_.Correct(f1_m);
    const Vec3 w0 = gyro_.Correct(w0_m);
    const Vec3 w1 = gyro_.Correct(w1_m);
    StrapdownStep s;
    strapdown_.Step(dt, f0, w0, f1, w1, &s);
    rate_ = w1;
    Accumulate(s);
    elapsed_ += dt;
  }

  double elapsed() const { return elapsed_; }

  // Covariance to now: P = Phi P Phi^T + Q.
  void Propagate() {
    const int ns = layout_.size() - 9;
    const Mat9 pnn = p_.topLeftCorner<9, 9>();
    const Mat9X pns = p_.topRightCorner(9, ns);
    const Eigen::MatrixXd& full = p_;
    Mat9X t2 = a_ * pns;
    t2.noalias() += b_ * full.bottomRightCorner(ns, ns);
    Mat9 t1 = a_ * pnn;
    t1.noalias() += b_ * pns.transpose();
    Mat9 new_nn = t1 * a_.transpose();
    new_nn.noalias() += t2 * b_.transpose();
    p_.topLeftCorner<9, 9>() = new_nn + q_;
    p_.topRightCorner(9, ns) = t2;
    p_.bottomLeftCorner(ns, 9) = t2.transpose();
    const double walk[2] = {options_.accel_bias_walk, options_.gyro_bias_walk};
    const StateBlock bias[2] = {StateBlock::kAccelBias, StateBlock::kGyroBias};
    for (int s = 0; s < 2; ++s) {
      if (walk[s] <= 0.0) continue;
      const int o = layout_.offset(bias[s]);
      for (int i = 0; i < 3; ++i) p_(o + i, o + i) += walk[s] * walk[s] * elapsed_;
    }
    a_.setIdentity();
    b_.setZero();
    q_.setZero();
    elapsed_ = 0.0;
  }

  // Zero-velocity and zero-position pseudo-measurements, Joseph form,
  // closed-loop feedback. Returns the normalised innovation squared.
  double Update() {
    const NavigationState& nav = strapdown_.state();
    const Mat3& c = strapdown_.attitude_matrix();
    // The point held still: the sensor, or with a lever arm r the point the
    // unit turns about, at p - C r with velocity v - C (w x r). To first
    // order (u = C (w x r)):
    //   z_v = dv - [u x] phi - C [r x] (I+E_g)^-1 (db_g + dE_g w) - C [w x] dr
    //   z_p = dp - [(C r) x] phi - C dr
    const Vec3 u = c * rate_.cross(lever_);
    Eigen::Matrix<double, 6, 1> z;
    z << nav.velocity - u, nav.position - c * lever_;
    h_.setZero();
    h_.block<3, 3>(0, 3).setIdentity();
    h_.block<3, 3>(3, 6).setIdentity();
    const int lever = layout_.offset(StateBlock::kLeverArm);
    if (layout_.block_size(StateBlock::kLeverArm) > 0) {
      h_.block<3, 3>(0, 0) = -Skew(u);
      h_.block<3, 3>(3, 0) = -Skew(c * lever_);
      const Mat3 kr = -c * Skew(lever_) * gyro_.inverse;
      h_.block<3, 3>(0, layout_.offset(StateBlock::kGyroBias)) = kr;
      const int gm = layout_.offset(StateBlock::kGyroMatrix);
      for (size_t j = 0; j < layout_.gyro().matrix_entries.size(); ++j) {
        const auto [r, col] = layout_.gyro().matrix_entries[j];
        h_.block<3, 1>(0, gm + static_cast<int>(j)) = kr.col(r) * rate_(col);
      }
      h_.block<3, 3>(0, lever) = -c * Skew(rate_);
      h_.block<3, 3>(3, lever) = -c;
    }
    Eigen::Matrix<double, 6, 1> r;
    r << Vec3::Constant(options_.velocity_noise * options_.velocity_noise),
        Vec3::Constant(options_.position_noise * options_.position_noise);
    const Eigen::Matrix<double, Eigen::Dynamic, 6> pht = p_ * h_.transpose();
    Eigen::Matrix<double, 6, 6> s = h_ * pht;
    s.diagonal() += r;
    const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(s);
    const Eigen::Matrix<double, Eigen::Dynamic, 6> k = llt.solve(pht.transpose()).transpose();
    const double nis = z.dot(llt.solve(z));
    const Eigen::VectorXd x = k * z;
    // Joseph form: P = (I - K H) P (I - K H)^T + K R K^T.
    joseph_.setIdentity();
    joseph_.noalias() -= k * h_;
    Eigen::MatrixXd p = joseph_ * p_ * joseph_.transpose();
    p.noalias() += k * r.asDiagonal() * k.transpose();
    p_ = 0.5 * (p + p.transpose());
    Feedback(x);
    return nis;
  }

  bool Healthy() const {
    return p_.allFinite() && strapdown_.state().velocity.allFinite() &&
           p_.diagonal().minCoeff() >= 0.0;
  }

  // Current estimate of each state in layout order (navigation errors are
  // zero after feedback; sensor states are the estimates themselves).
  double SensorValue(int state) const {
    const int ab = layout_.offset(StateBlock::kAccelBias);
    const int am = layout_.offset(StateBlock::kAccelMatrix);
    const int gb = layout_.offset(StateBlock::kGyroBias);
    const int gm = layout_.offset(StateBlock::kGyroMatrix);
    const int lever = layout_.offset(StateBlock::kLeverArm);
    if (state >= lever) return lever_(state - lever);
    if (state >= gm) {
      const auto [r, c] = layout_.gyro().matrix_entries[state - gm];
      return gyro_.e(r, c);
    }
    if (state >= gb) return gyro_.bias(state - gb);
    if (state >= am) {
      const auto [r, c] = layout_.accel().matrix_entries[state - am];
      return accel_.e(r, c);
    }
    if (state >= ab) return accel_.bias(state - ab);
    return 0.0;
  }

  const Eigen::MatrixXd& covariance() const { return p_; }
  const Eigen::MatrixXd& initial_covariance() const { return p_initial_; }
  const SensorEstimate& accel() const { return accel_; }
  const SensorEstimate& gyro() const { return gyro_; }

 private:
  void Accumulate(const StrapdownStep& s) {
    const double dt = s.dt;
    const Mat3 ka = s.attitude_mid * accel_.inverse;
    const Mat3 kg = s.attitude_mid * gyro_.inverse;
    NavigationStep step;
    step.dt = dt;
    step.velocity_from_attitude = dt * Skew(s.attitude_mid * s.specific_force_mid);
    const Vec3& w_ie = strapdown_.earth_rate();
    if (w_ie.squaredNorm() > 0.0) {
      step.earth_rate = true;
      step.attitude_attitude = Mat3::Identity() - dt * Skew(w_ie);
      step.velocity_velocity = Mat3::Identity() - 2.0 * dt * Skew(w_ie);
    }
    step.Apply(&a_);
    step.Apply(&b_);
    step.Apply(&q_);
    q_.transposeInPlace();
    step.Apply(&q_);
    // Sensor columns of this step: B += B_k.
    const int ab = layout_.offset(StateBlock::kAccelBias) - 9;
    const int am = layout_.offset(StateBlock::kAccelMatrix) - 9;
    const int gb = layout_.offset(StateBlock::kGyroBias) - 9;
    const int gm = layout_.offset(StateBlock::kGyroMatrix) - 9;
    b_.block<3, 3>(3, ab) -= dt * ka;
    for (size_t j = 0; j < layout_.accel().matrix_entries.size(); ++j) {
      const auto [r, c] = layout_.accel().matrix_entries[j];
      b_.block<3, 1>(3, am + static_cast<int>(j)) -= (dt * s.specific_force_mid(c)) * ka.col(r);
    }
    b_.block<3, 3>(0, gb) += dt * kg;
    for (size_t j = 0; j < layout_.gyro().matrix_entries.size(); ++j) {
      const auto [r, c] = layout_.gyro().matrix_entries[j];
      b_.block<3, 1>(0, gm + static_cast<int>(j)) += (dt * s.rate_mid(c)) * kg.col(r);
    }
    const double ga = options_.accel_noise_density;
    const double gg = options_.gyro_noise_density;
    q_.topLeftCorner<3, 3>().noalias() += (gg * gg * dt) * kg * kg.transpose();
    q_.block<3, 3>(3, 3).noalias() += (ga * ga * dt) * ka * ka.transpose();
  }

  void Feedback(const Eigen::VectorXd& x) {
    NavigationState nav = strapdown_.state();
    nav.attitude = RotationVectorToQuaternion(x.head<3>()) * nav.attitude;
    nav.velocity -= x.segment<3>(3);
    nav.position -= x.segment<3>(6);
    strapdown_.SetState(nav);
    accel_.bias -= x.segment<3>(layout_.offset(StateBlock::kAccelBias));
    gyro_.bias -= x.segment<3>(layout_.offset(StateBlock::kGyroBias));
    const int am = layout_.offset(StateBlock::kAccelMatrix);
    for (size_t j = 0; j < layout_.accel().matrix_entries.size(); ++j) {
      const auto [r, c] = layout_.accel().matrix_entries[j];
      accel_.e(r, c) -= x(am + static_cast<int>(j));
    }
    const int gm = layout_.offset(StateBlock::kGyroMatrix);
    for (size_t j = 0; j < layout_.gyro().matrix_entries.size(); ++j) {
      const auto [r, c] = layout_.gyro().matrix_entries[j];
      gyro_.e(r, c) -= x(gm + static_cast<int>(j));
    }
    if (layout_.block_size(StateBlock::kLeverArm) > 0) {
      lever_ -= x.segment<3>(layout_.offset(StateBlock::kLeverArm));
    }
    accel_.Refresh();
    gyro_.Refresh();
  }

  const HandheldKalmanOptions& options_;
  const ErrorStateLayout& layout_;
  Strapdown strapdown_;
  SensorEstimate accel_;
  SensorEstimate gyro_;
  Eigen::MatrixXd p_;
  Eigen::MatrixXd p_initial_;
  Eigen::MatrixXd joseph_;
  Eigen::Matrix<double, 6, Eigen::Dynamic> h_;
  // Lever arm estimate (zero when not estimated) and the latest corrected
  // body rate.
  Vec3 lever_ = Vec3::Zero();
  Vec3 rate_ = Vec3::Zero();
  // Accumulated since the last epoch: navigation transition, navigation <-
  // sensor transition, navigation process noise.
  Mat9 a_;
  Mat9X b_;
  Mat9 q_;
  double elapsed_ = 0.0;
};

// The motion that excites a sensor error, for the warning.
std::string MissingMotion(const std::string& name) {
  const bool accel = name.rfind("accel", 0) == 0;
  const char axis = name.back();
  std::string others;
  for (int i = 0; i < 3; ++i) {
    if (kAxes[i] != axis)
      others += others.empty() ? std::string(1, kAxes[i]) : std::string(" or ") + kAxes[i];
  }
  std::ostringstream s;
  if (name.rfind("lever_arm", 0) == 0) {
    s << "turns about the axes other than " << axis;
  } else if (name.find("_cross_") != std::string::npos) {
    s << "rotations about all three axes while each is horizontal";
  } else if (accel) {
    s << "the " << axis << " axis pointing up and down: turn the unit about its " << others
      << " axis while that axis is horizontal";
  } else if (name.find("_scale_") != std::string::npos) {
    s << "turns about the " << axis << " axis while it is horizontal: turn the unit about its "
      << axis << " axis while that axis is horizontal (turns about the vertical do not count)";
  } else {
    s << "the " << axis << " axis horizontal for a while (turn the unit about its " << others
      << " axis while that axis is horizontal)";
  }
  return s.str();
}

std::string Format(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}

// Fills the convergence report from the first pass's history (criterion in
// HandheldKalmanOptions) and warns about each state the motion did not
// determine; returns their names.
std::vector<std::string> ReportConvergence(const Filter& filter, const ErrorStateLayout& layout,
                                           const HandheldKalmanOptions& options, Calibration* c) {
  const Eigen::MatrixXd& p = filter.covariance();
  const Eigen::MatrixXd& p0 = filter.initial_covariance();
  const int n = layout.size();
  std::ostringstream criterion;
  criterion << "on the first (causal) filter pass: converged at the first epoch from which on "
               "both the distance of the estimate from its final value and its standard "
               "deviation stay below "
            << options.convergence_fraction
            << " times the prior standard deviation; a state whose final standard deviation is "
               "above that is not determined";
  c->convergence.criterion = criterion.str();
  const EstimateHistory& history = c->history;
  const int first_sensor = layout.offset(StateBlock::kAccelBias);
  const size_t rows = history.rows();
  const size_t cols = history.columns.size();
  std::vector<std::string> unexcited;
  for (int j = first_sensor; j < n; ++j) {
    ConvergenceEntry e;
    e.name = layout.names()[j];
    const bool bias = e.name.find("_bias_") != std::string::npos;
    const bool accel = e.name.rfind("accel", 0) == 0;
    const bool lever = e.name.rfind("lever_arm", 0) == 0;
    e.unit = lever ? "m" : bias ? (accel ? "m/s^2" : "rad/s") : "fraction";
    e.value = filter.SensorValue(j);
    e.sigma_initial = std::sqrt(p0(j, j));
    e.sigma_final = std::sqrt(std::max(p(j, j), 0.0));
    const bool excited = e.sigma_final <= options.convergence_fraction * e.sigma_initial;
    if (excited) {
      const size_t col = 1 + 2 * static_cast<size_t>(j - first_sensor);
      // On the first (causal) pass, against its own final value.
      const double* last = &history.values[(rows - 1) * cols];
      const double tolerance = options.convergence_fraction * e.sigma_initial;
      size_t first_good = rows;
      while (first_good > 0) {
        const double* row = &history.values[(first_good - 1) * cols];
        const bool inside =
            std::fabs(row[col] - last[col]) <= tolerance && row[col + 1] <= tolerance;
        if (!inside) break;
        --first_good;
      }
      e.converged = first_good < rows;
      if (e.converged) e.time = history.values[first_good * cols];
    } else {
      unexcited.push_back(e.name);
      std::ostringstream s;
      s << e.name << " not determined: its standard deviation only went from "
        << Format(e.sigma_initial) << " to " << Format(e.sigma_final) << " " << e.unit
        << " (the reported value is mostly the prior); the recording lacks "
        << MissingMotion(e.name);
      c->warnings.push_back(s.str());
    }
    c->convergence.entries.push_back(e);
  }
  return unexcited;
}

// One sensor's result in the calibration models: f = s (I + E)^-1 (v - b / s)
// is a = M (v - b_raw) with M = s (I + E)^-1 and b_raw = b / s (same for the
// gyroscope). Jacobians: db_raw/db = 1 / s, dM/dE_rc = -(1/s) M e_r e_c^T M.
// Entries of M that no estimated entry of E moves get NaN std.
struct SensorResult {
  Vec3 bias;
  Mat3 matrix;
  Vec3 bias_std;
  Mat3 matrix_std;
  Eigen::MatrixXd covariance;
  std::vector<std::string> names;
};

SensorResult ToCalibrationModel(const SensorEstimate& est, double scale, int bias_offset,
                                int matrix_offset, const SensorErrorTerms& terms,
                                const Eigen::MatrixXd& p) {
  SensorResult out;
  out.bias = est.bias / scale;
  out.matrix = scale * est.inverse;
  const int ne = static_cast<int>(terms.matrix_entries.size());
  // Which entries of M move: all those reached by some estimated entry.
  bool moves[3][3] = {};
  for (const auto& [r, col] : terms.matrix_entries) {
    for (int i = 0; i < 3; ++i) {
      for (int k = 0; k < 3; ++k) {
        if (out.matrix(i, r) != 0.0 && out.matrix(col, k) != 0.0) moves[i][k] = true;
      }
    }
  }
  std::vector<std::pair<int, int>> outputs;
  out.names.clear();
  for (int i = 0; i < 3; ++i) out.names.push_back(std::string("bias_") + kAxes[i]);
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) {
      if (moves[i][k]) {
        outputs.emplace_back(i, k);
        out.names.push_back(std::string("m_") + kAxes[i] + kAxes[k]);
      }
    }
  }
  const int no = 3 + static_cast<int>(outputs.size());
  Eigen::MatrixXd jac = Eigen::MatrixXd::Zero(no, 3 + ne);
  jac.topLeftCorner<3, 3>() = Mat3::Identity() / scale;
  for (size_t o = 0; o < outputs.size(); ++o) {
    const auto [i, k] = outputs[o];
    for (int e = 0; e < ne; ++e) {
      const auto [r, col] = terms.matrix_entries[e];
      jac(3 + static_cast<int>(o), 3 + e) = -out.matrix(i, r) * out.matrix(col, k) / scale;
    }
  }
  Eigen::MatrixXd source(3 + ne, 3 + ne);
  std::vector<int> index;
  for (int i = 0; i < 3; ++i) index.push_back(bias_offset + i);
  for (int e = 0; e < ne; ++e) index.push_back(matrix_offset + e);
  for (int a = 0; a < 3 + ne; ++a) {
    for (int b = 0; b < 3 + ne; ++b) source(a, b) = p(index[a], index[b]);
  }
  out.covariance = jac * source * jac.transpose();
  for (int i = 0; i < 3; ++i) out.bias_std(i) = std::sqrt(out.covariance(i, i));
  out.matrix_std.setConstant(NAN);
  for (size_t o = 0; o < outputs.size(); ++o) {
    out.matrix_std(outputs[o].first, outputs[o].second) =
        std::sqrt(out.covariance(3 + static_cast<int>(o), 3 + static_cast<int>(o)));
  }
  return out;
}

}  // namespace

bool HandheldKalmanOptions::IsValid(std::string* error) const {
  auto positive = [&](const char* key, double v) {
    if (std::isfinite(v) && v > 0.0) return true;
    *error = std::string("key '") + key + "': must be positive";
    return false;
  };
  auto non_negative = [&](const char* key, double v) {
    if (std::isfinite(v) && v >= 0.0) return true;
    *error = std::string("key '") + key + "': must be zero or positive";
    return false;
  };
  if (!positive("nominal_scale", accel_nominal_scale) ||
      !positive("gyro_nominal_scale", gyro_nominal_scale) ||
      !positive("hk_still_seconds", still_seconds) ||
      !positive("hk_update_interval", update_interval) ||
      !positive("hk_velocity_noise", velocity_noise) ||
      !positive("hk_position_noise", position_noise) ||
      !positive("hk_accel_noise_density", accel_noise_density) ||
      !positive("hk_gyro_noise_density", gyro_noise_density) ||
      !non_negative("hk_accel_bias_walk", accel_bias_walk) ||
      !non_negative("hk_gyro_bias_walk", gyro_bias_walk) ||
      !positive("hk_accel_bias_std", accel_bias_std) ||
      !positive("hk_accel_scale_std", accel_scale_std) ||
      !positive("hk_gyro_bias_std", gyro_bias_std) ||
      !positive("hk_gyro_scale_std", gyro_scale_std) ||
      !positive("hk_cross_axis_std", cross_axis_std) ||
      !positive("hk_initial_attitude_std", initial_attitude_std) ||
      !positive("hk_lever_arm_std", lever_arm_std) ||
      !positive("hk_convergence_fraction", convergence_fraction)) {
    return false;
  }
  if (passes < 1 || passes > 5) {
    *error = "key 'hk_passes': must be from 1 to 5";
    return false;
  }
  if (convergence_fraction >= 1.0) {
    *error = "key 'hk_convergence_fraction': must be below 1";
    return false;
  }
  if (!gravity.IsValid(error) || !accel_terms.IsValid(error) || !gyro_terms.IsValid(error)) {
    return false;
  }
  if (earth_rate && !std::isfinite(gravity.latitude)) {
    *error = "key 'hk_earth_rate': the Earth rate needs the key 'latitude'";
    return false;
  }
  return true;
}

bool CalibrateHandheld(const ImuLog& log, const HandheldKalmanOptions& options,
                       Calibration* calibration) {
  CHECK(calibration != nullptr);
  const auto clock_start = std::chrono::steady_clock::now();
  *calibration = Calibration();
  Calibration& c = *calibration;
  std::string error;
  if (!options.IsValid(&error)) {
    c.message = error;
    return false;
  }
  if (!log.Validate(&error)) {
    c.message = error;
    return false;
  }
  if (!log.has_gyro()) {
    c.message = log.source +
                ": the handheld_kalman method needs a gyroscope (columns gx, gy, gz, or "
                "gyro_path)";
    return false;
  }
  if (!ResolveCalibrationGravity(options.gravity, calibration)) return false;
  const size_t count = log.size();
  const double duration = count > 1 ? log.t.back() - log.t.front() : 0.0;
  // The still window, and enough log after it for at least a few updates.
  size_t still_end = 0;
  while (still_end < count && log.t[still_end] - log.t.front() <= options.still_seconds) {
    ++still_end;
  }
  if (still_end < 10 || duration < options.still_seconds + 2.0 * options.update_interval) {
    std::ostringstream s;
    s << log.source << ": " << count << " samples over " << duration
      << " s is too short for the handheld_kalman method: it needs the still period ("
      << options.still_seconds << " s, at least 10 samples) and the turns after it";
    c.message = s.str();
    return false;
  }
  const double sa = options.accel_nominal_scale;
  const double sg = options.gyro_nominal_scale;
  Vec3 f_mean = Vec3::Zero();
  Vec3 w_mean = Vec3::Zero();
  for (size_t i = 0; i < still_end; ++i) {
    f_mean += sa * log.accel[i];
    w_mean += sg * log.gyro[i];
  }
  f_mean /= static_cast<double>(still_end);
  w_mean /= static_cast<double>(still_end);
  double f_dev = 0.0;
  double w_dev = 0.0;
  for (size_t i = 0; i < still_end; ++i) {
    f_dev += (sa * log.accel[i] - f_mean).squaredNorm();
    w_dev += (sg * log.gyro[i] - w_mean).squaredNorm();
  }
  f_dev = std::sqrt(f_dev / static_cast<double>(still_end));
  w_dev = std::sqrt(w_dev / static_cast<double>(still_end));
  if (!(f_mean.norm() > 0.3 * c.gravity && f_mean.norm() < 3.0 * c.gravity)) {
    std::ostringstream s;
    s << log.source << ": the mean specific force over the first " << options.still_seconds
      << " s is " << f_mean.norm() << " m/s^2 after nominal_scale, far from gravity " << c.gravity
      << ": check nominal_scale (m/s^2 per raw unit)";
    c.message = s.str();
    return false;
  }
  if (f_dev > kStillAccelRms || w_dev > kStillGyroRms) {
    std::ostringstream s;
    s << "the first " << options.still_seconds << " s do not look still (accelerometer rms "
      << Format(f_dev) << " m/s^2, gyroscope rms " << Format(w_dev)
      << " rad/s): the initial roll and pitch may be off; start with the unit held still";
    c.warnings.push_back(s.str());
  }

  const ErrorStateLayout layout(options.accel_terms, options.gyro_terms,
                                options.estimate_lever_arm);
  const int n = layout.size();
  const int first_sensor = layout.offset(StateBlock::kAccelBias);
  const int sensor_count = layout.offset(StateBlock::kLeverArm) - first_sensor;
  // History: t, then value and std of each sensor state.
  EstimateHistory& history = c.history;
  history.columns.push_back("t");
  for (int j = first_sensor; j < n; ++j) {
    history.columns.push_back(layout.names()[j]);
    history.columns.push_back(layout.names()[j] + "_std");
  }
  const double nominal_dt = duration / static_cast<double>(count - 1);
  double largest_gap = 0.0;
  double gap_time = 0.0;
  for (size_t i = 1; i < count; ++i) {
    const double dt = log.t[i] - log.t[i - 1];
    if (dt > largest_gap) {
      largest_gap = dt;
      gap_time = log.t[i - 1] - log.t.front();
    }
  }

  // One pass of the filter over the log from the given sensor estimates.
  // The first pass records the history.
  double nis_sum = 0.0;
  int epochs = 0;
  auto run_pass = [&](Filter* filter, const SensorEstimate& accel, const SensorEstimate& gyro,
                      bool record_history) {
    filter->Initialize(f_mean, accel, gyro);
    nis_sum = 0.0;
    epochs = 0;
    auto record = [&](double t) {
      if (!record_history) return;
      history.values.push_back(t - log.t.front());
      const Eigen::MatrixXd& p = filter->covariance();
      for (int j = first_sensor; j < n; ++j) {
        history.values.push_back(filter->SensorValue(j));
        history.values.push_back(std::sqrt(std::max(p(j, j), 0.0)));
      }
    };
    record(log.t.front());
    for (size_t i = 1; i < count; ++i) {
      filter->Step(log.t[i] - log.t[i - 1], sa * log.accel[i - 1], sg * log.gyro[i - 1],
                   sa * log.accel[i], sg * log.gyro[i]);
      if (filter->elapsed() >= options.update_interval * (1.0 - 1e-9) || i + 1 == count) {
        filter->Propagate();
        nis_sum += filter->Update();
        ++epochs;
        if (!filter->Healthy()) {
          std::ostringstream s;
          s << log.source << ": the filter diverged at t = " << log.t[i] - log.t.front()
            << " s: check nominal_scale, gyro_nominal_scale and the noise settings";
          c.message = s.str();
          c.not_converged = true;
          return false;
        }
        record(log.t[i]);
      }
    }
    return true;
  };
  // Later passes start from the previous pass's sensor estimates (the prior
  // covariance is the same, centred there): the levelling and the error
  // model are then linearised close to the truth. The levelling's tilt
  // error b_h / g otherwise leaves a second-order error |b_h|^2 / (2 g) in
  // the vertical channel during the still period that the first pass
  // attributes to the vertical accelerometer bias and scale.
  std::unique_ptr<Filter> filter;
  SensorEstimate accel_start;
  SensorEstimate gyro_start;
  for (int pass = 0; pass < options.passes; ++pass) {
    auto next = std::make_unique<Filter>(options, c.gravity, layout);
    if (!run_pass(next.get(), accel_start, gyro_start, pass == 0)) return false;
    filter = std::move(next);
    accel_start = filter->accel();
    gyro_start = filter->gyro();
  }
  if (largest_gap > kGapFactor * nominal_dt) {
    std::ostringstream s;
    s << "the log has a gap of " << Format(largest_gap) << " s at t = " << Format(gap_time)
      << " s: the navigation runs blind across it and the estimates may be off";
    c.warnings.push_back(s.str());
  }
  const double chi2_per_dof = nis_sum / (6.0 * epochs);
  if (chi2_per_dof > 3.0) {
    std::ostringstream s;
    // Two causes give the same symptom: motion beyond the pseudo-measurement
    // noise, or sensor errors outside the model (cross-axis terms above all:
    // on a 0.005 rad misaligned simulated IMU the diagonal model is 10-40
    // sigma off and this statistic is 7-24). Either way the standard
    // deviations assume a model the data reject, so say both.
    s << "the innovations are " << Format(chi2_per_dof)
      << " times their expected size (chi2 per degree of freedom), so the standard deviations "
         "are too small: either the unit moved more than the pseudo-measurements allow (keep it "
         "in place, or raise hk_velocity_noise and hk_position_noise) or the sensor has errors "
         "outside the model ("
      << (options.gyro_terms.matrix_entries.size() > 3 ? "" : "try hk_cross_axis: true; ")
      << (options.estimate_lever_arm ? "" : "try hk_lever_arm: true; ")
      << "gravcal discover on a multi-position session names other effects)";
    c.warnings.push_back(s.str());
  }

  const std::vector<std::string> unexcited = ReportConvergence(*filter, layout, options, &c);
  const Eigen::MatrixXd& p = filter->covariance();
  const SensorResult accel =
      ToCalibrationModel(filter->accel(), sa, layout.offset(StateBlock::kAccelBias),
                         layout.offset(StateBlock::kAccelMatrix), layout.accel(), p);
  c.accel.bias_std = accel.bias_std;
  c.accel.matrix_std = accel.matrix_std;
  c.accel.covariance = accel.covariance;
  c.accel.covariance_names = accel.names;
  const Vec3& accel_bias = accel.bias;
  const Mat3& accel_matrix = accel.matrix;
  // Diagonal E: the `scale` model; upper-triangular E (the accelerometer
  // axes define the body frame): `scale_misalignment`; otherwise `affine`.
  const bool accel_upper =
      accel_matrix.isUpperTriangular(0.0) && accel_matrix.diagonal().minCoeff() > 0.0;
  if (accel_upper) {
    c.accel.model.parameterization = accel_matrix.isDiagonal(0.0)
                                         ? AccelParameterization::kScale
                                         : AccelParameterization::kScaleMisalignment;
    c.accel.model.bias = accel_bias;
    c.accel.model.upper = accel_matrix;
    c.accel.model.rotation.setIdentity();
  } else if (!AccelModel::FromMatrix(accel_bias, accel_matrix, AccelParameterization::kAffine,
                                     &c.accel.model)) {
    c.message = log.source + ": the estimated accelerometer matrix is singular";
    return false;
  }
  const SensorResult gyro =
      ToCalibrationModel(filter->gyro(), sg, layout.offset(StateBlock::kGyroBias),
                         layout.offset(StateBlock::kGyroMatrix), layout.gyro(), p);
  c.gyro.estimated = true;
  c.gyro.model.bias = gyro.bias;
  c.gyro.model.matrix = gyro.matrix;
  c.gyro.bias_std = gyro.bias_std;
  c.gyro.matrix_std = gyro.matrix_std;
  c.gyro.covariance = gyro.covariance;
  c.gyro.covariance_names = gyro.names;

  // |a| - g over the initial still period, before (nominal scale) and after.
  const double before = f_mean.norm() - c.gravity;
  const double after = filter->accel().Correct(f_mean).norm() - c.gravity;
  c.residual_nominal = {std::fabs(before), std::fabs(before)};
  c.residual_refined = {std::fabs(after), std::fabs(after)};
  c.residual_coarse = c.residual_nominal;

  RefinementResult& summary = c.refinement;
  summary.iterations = epochs;
  summary.converged = unexcited.empty();
  summary.termination = "end of log";
  summary.chi2 = nis_sum;
  summary.dof = 6 * epochs;
  summary.num_parameters = sensor_count;
  summary.solve_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  std::ostringstream m;
  m << "handheld Kalman filter: " << n << " states, " << epochs << " updates over "
    << Format(duration) << " s; ";
  if (unexcited.empty()) {
    m << "all " << sensor_count << " sensor errors determined";
  } else {
    m << unexcited.size() << " of " << sensor_count
      << " sensor errors not determined by the motion (see warnings)";
  }
  summary.message = m.str();
  c.solver_name = "error-state Kalman filter";
  c.message = m.str();
  c.success = true;
  return true;
}

}  // namespace gravcal
