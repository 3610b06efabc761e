// The multi-IMU calibration's timing and checks (methods/multi_imu.h):
// the gyroscopes' time offsets from the turns, the permuted-axes check and
// the moved-unit check.
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "gravcal/methods/multi_imu.h"
#include "methods/multi_imu_internal.h"

namespace gravcal {
namespace internal {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

double RotationAngleDeg(const Eigen::Matrix3d& r) {
  const double c = std::clamp((r.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * kRadToDeg;
}

// A signal sampled at increasing times, interpolated by the cubic Hermite
// spline with centred-difference slopes (Catmull-Rom on uneven steps).
class Spline {
 public:
  Spline(std::vector<double> t, std::vector<Eigen::Vector3d> v)
      : t_(std::move(t)), v_(std::move(v)) {}
  bool Covers(double t) const { return t_.size() >= 4 && t >= t_[1] && t <= t_[t_.size() - 2]; }
  // Value and time derivative at t (Covers(t)).
  void At(double t, Eigen::Vector3d* value, Eigen::Vector3d* rate) const {
    size_t j = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin();
    j = std::clamp<size_t>(j, 2, t_.size() - 2) - 1;  // t in [t_j, t_{j+1}]
    const double h = t_[j + 1] - t_[j];
    const Eigen::Vector3d m0 = (v_[j + 1] - v_[j - 1]) / (t_[j + 1] - t_[j - 1]) * h;
    const Eigen::Vector3d m1 = (v_[j + 2] - v_[j]) / (t_[j + 2] - t_[j]) * h;
    const double s = (t - t_[j]) / h;
    const double s2 = s * s, s3 = s2 * s;
    *value = (2 * s3 - 3 * s2 + 1) * v_[j] + (s3 - 2 * s2 + s) * m0 +
             (-2 * s3 + 3 * s2) * v_[j + 1] + (s3 - s2) * m1;
    *rate = ((6 * s2 - 6 * s) * v_[j] + (3 * s2 - 4 * s + 1) * m0 + (-6 * s2 + 6 * s) * v_[j + 1] +
             (3 * s2 - 2 * s) * m1) /
            h;
  }

 private:
  std::vector<double> t_;
  std::vector<Eigen::Vector3d> v_;
};

// The calibrated rate in the plate frame, C M_g (u - b_g), of samples
// [begin, end) of the log.
void PlateRates(const ImuLog& log, const PlateImuParameters& p, size_t begin, size_t end,
                std::vector<double>* t, std::vector<Eigen::Vector3d>* w) {
  const Eigen::Matrix3d m = p.Rotation() * p.GyroMatrix();
  const Eigen::Vector3d b(p.gyro_bias[0], p.gyro_bias[1], p.gyro_bias[2]);
  for (size_t k = begin; k < end; ++k) {
    t->push_back(log.t[k]);
    w->push_back(m * (log.gyro[k] - b));
  }
}

// The binomial low-pass of order 8 (9 taps, a Gaussian of sigma sqrt(2)
// samples), renormalised at the ends. Both signals of a timing get it: the
// spline of a white-noise sequence has less variance between samples than
// at them, which pulls an offset towards half a sample; the smoothed
// sequence's variance barely changes between samples, and a symmetric
// filter shifts no time.
std::vector<Eigen::Vector3d> Smooth(const std::vector<Eigen::Vector3d>& w) {
  constexpr double kTaps[9] = {1, 8, 28, 56, 70, 56, 28, 8, 1};
  std::vector<Eigen::Vector3d> out(w.size());
  const long n = static_cast<long>(w.size());
  for (long k = 0; k < n; ++k) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double weight = 0.0;
    for (long j = -4; j <= 4; ++j) {
      if (k + j < 0 || k + j >= n) continue;
      sum += kTaps[j + 4] * w[k + j];
      weight += kTaps[j + 4];
    }
    out[k] = sum / weight;
  }
  return out;
}

double MeanInterval(const ImuLog& log) {
  return log.size() > 1 ? (log.t.back() - log.t.front()) / static_cast<double>(log.size() - 1)
                        : 1.0;
}

size_t IndexAt(const ImuLog& log, double t) {
  return std::lower_bound(log.t.begin(), log.t.end(), t) - log.t.begin();
}

// One turn's offset: tau minimising sum |w_0(t) - w_i(t + tau)|^2 over the
// reference's samples (both smoothed), by a grid then Gauss-Newton; its
// variance (s0^2 + si^2) / sum |w_i'|^2 from the white noise per axis of
// the two rates (s0, si, rad/s per sample). False when the turn cannot time.
bool TurnOffset(const std::vector<double>& t0, const std::vector<Eigen::Vector3d>& w0,
                const Spline& wi, double max_offset, double step, double noise_variance,
                double* tau, double* var) {
  auto cost = [&](double x, double* s, double* jj, double* jr, int* n) {
    *s = *jj = *jr = 0.0;
    *n = 0;
    for (size_t k = 0; k < t0.size(); ++k) {
      if (!wi.Covers(t0[k] + x)) continue;
      Eigen::Vector3d v, d;
      wi.At(t0[k] + x, &v, &d);
      const Eigen::Vector3d r = w0[k] - v;
      *s += r.squaredNorm();
      *jj += d.squaredNorm();
      *jr += d.dot(r);
      ++*n;
    }
  };
  const size_t needed = t0.size() * 9 / 10;
  double best = -1.0, best_cost = 0.0;
  for (double x = -max_offset; x <= max_offset + 1e-12; x += step) {
    double s, jj, jr;
    int n;
    cost(x, &s, &jj, &jr, &n);
    if (static_cast<size_t>(n) < needed) continue;
    if (best < 0.0 || s < best_cost) {
      best_cost = s;
      best = 0.0;
      *tau = x;
    }
  }
  if (best < 0.0) return false;
  double s = 0.0, jj = 0.0, jr = 0.0;
  int n = 0;
  for (int it = 0; it < 20; ++it) {
    cost(*tau, &s, &jj, &jr, &n);
    if (!(jj > 0.0)) return false;
    const double dx = jr / jj;
    *tau += dx;
    if (std::abs(dx) < 1e-9) break;
  }
  cost(*tau, &s, &jj, &jr, &n);
  if (n < 8 || !(jj > 0.0)) return false;
  *var = noise_variance / jj;
  return std::isfinite(*tau) && std::abs(*tau) <= max_offset;
}

}  // namespace

void EstimateTimeOffsets(const std::vector<PlateImuData>& data,
                         const std::vector<PlateImuParameters>& params, int reference,
                         const MultiImuOptions& options, MultiImuResult* result) {
  const size_t n = data.size();
  result->time_offset_covariance = Eigen::MatrixXd::Zero(n, n);
  const PlateImuData& ref = data[reference];
  PlateImuResult& ref_result = result->imus[reference];
  ref_result.time_offset = 0.0;
  ref_result.time_offset_std = 0.0;
  if (!ref.has_gyro) {
    result->undetermined.push_back("the reference has no gyroscope: no time offsets");
    return;
  }
  const ImuLog& ref_log = ref.imu->log;
  const double t_first = ref_log.t.front();
  std::vector<double> sigma_noise(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    if (static_cast<int>(i) == reference) continue;
    PlateImuResult& r = result->imus[i];
    if (!data[i].has_gyro) {
      result->undetermined.push_back(r.name + " has no gyroscope: its time offset is undetermined");
      continue;
    }
    const ImuLog& log = data[i].imu->log;
    // The offset is a sum over the reference's samples; IMU i's noise
    // enters through its rate smoothed and interpolated at them, which for
    // the slow rate of a turn carries its noise density: per reference
    // sample s_i^2 h_i / h_0 (h the sample intervals; two logs at
    // different rates).
    const double scaled_noise =
        data[i].gyro_noise * std::sqrt(MeanInterval(log) / MeanInterval(ref_log));
    const double step = std::max(
        1e-4, 0.25 * (log.t.back() - log.t.front()) / std::max<double>(1.0, log.size() - 1.0));
    std::vector<double> times, taus, vars;
    for (size_t k = 0; k < ref.turns.size(); ++k) {
      const GyroRotationData& turn = ref.turns[k];
      if (turn.t.size() < 2 || data[i].turns[k].t.size() < 2) continue;
      const double a = turn.t.front() - options.timing_margin;
      const double b = turn.t.back() + options.timing_margin;
      std::vector<double> t0, ti;
      std::vector<Eigen::Vector3d> w0, wi;
      PlateRates(ref_log, params[reference], IndexAt(ref_log, a), IndexAt(ref_log, b), &t0, &w0);
      const double pad = options.max_time_offset + 0.05;
      PlateRates(log, params[i], IndexAt(log, a - pad), IndexAt(log, b + pad), &ti, &wi);
      // A turn with no motion above the noise cannot time.
      double peak = 0.0;
      for (const Eigen::Vector3d& w : w0) peak = std::max(peak, w.norm());
      if (peak < 20.0 * ref.gyro_noise) continue;
      double tau = 0.0, var = 0.0;
      const double noise_variance = ref.gyro_noise * ref.gyro_noise + scaled_noise * scaled_noise;
      if (!TurnOffset(t0, Smooth(w0), Spline(ti, Smooth(wi)), options.max_time_offset, step,
                      noise_variance, &tau, &var)) {
        continue;
      }
      times.push_back(0.5 * (a + b));
      taus.push_back(tau);
      vars.push_back(var);
    }
    r.timed_turns = static_cast<int>(taus.size());
    if (taus.empty()) {
      result->undetermined.push_back(r.name +
                                     ": no turn could be timed: its time offset is undetermined");
      continue;
    }
    // tau(t) = a + b (t - tbar), weighted; tbar the weighted mean time.
    double sw = 0.0, st = 0.0, sa = 0.0;
    for (size_t k = 0; k < taus.size(); ++k) {
      const double w = 1.0 / vars[k];
      sw += w;
      st += w * times[k];
      sa += w * taus[k];
    }
    const double tbar = st / sw, mean = sa / sw;
    double stt = 0.0, sty = 0.0;
    for (size_t k = 0; k < taus.size(); ++k) {
      const double w = 1.0 / vars[k];
      stt += w * (times[k] - tbar) * (times[k] - tbar);
      sty += w * (times[k] - tbar) * (taus[k] - mean);
    }
    const bool line = taus.size() >= 3 && stt > 0.0;
    const double slope = line ? sty / stt : 0.0;
    double chi2_const = 0.0, chi2_line = 0.0;
    for (size_t k = 0; k < taus.size(); ++k) {
      chi2_const += std::pow(taus[k] - mean, 2) / vars[k];
      chi2_line += std::pow(taus[k] - mean - slope * (times[k] - tbar), 2) / vars[k];
    }
    const double m = static_cast<double>(taus.size());
    const double scale_line = line && m > 2 ? std::max(1.0, chi2_line / (m - 2)) : 1.0;
    if (line) {
      r.clock_drift = slope;
      r.clock_drift_std = std::sqrt(scale_line / stt);
    }
    const bool drifting = line && std::abs(slope) > options.drift_factor * r.clock_drift_std &&
                          std::abs(slope) > options.drift_min;
    if (drifting) {
      r.time_offset = mean + slope * (t_first - tbar);
      r.time_offset_std =
          std::sqrt(scale_line / sw + std::pow(t_first - tbar, 2) / stt * scale_line);
      std::ostringstream s;
      s.precision(3);
      s << r.name << "'s clock drifts against " << data[reference].imu->name
        << "'s: " << slope * 1e6 << " +- " << r.clock_drift_std * 1e6 << " ppm ("
        << slope * (times.back() - times.front()) * 1e3 << " ms over the session's turns)";
      result->warnings.push_back(s.str());
    } else {
      const double scale_const = m > 1 ? std::max(1.0, chi2_const / (m - 1)) : 1.0;
      r.time_offset = mean;
      r.time_offset_std = std::sqrt(scale_const / sw);
    }
    sigma_noise[i] = scaled_noise;
  }
  // The offsets share the reference's noise: correlated.
  const double s0 = ref.gyro_noise * ref.gyro_noise;
  for (size_t i = 0; i < n; ++i) {
    const double si = result->imus[i].time_offset_std;
    if (static_cast<int>(i) == reference || !std::isfinite(si)) continue;
    for (size_t l = 0; l < n; ++l) {
      const double sl = result->imus[l].time_offset_std;
      if (static_cast<int>(l) == reference || !std::isfinite(sl)) continue;
      if (l == i) {
        result->time_offset_covariance(i, i) = si * si;
        continue;
      }
      const double rho = s0 / std::sqrt((s0 + sigma_noise[i] * sigma_noise[i]) *
                                        (s0 + sigma_noise[l] * sigma_noise[l]));
      result->time_offset_covariance(i, l) = rho * si * sl;
    }
  }
}

void CheckMountings(const std::vector<PlateImuData>& data,
                    const std::vector<PlateImuParameters>& params, int reference,
                    const MultiImuOptions& options, MultiImuResult* result) {
  const Eigen::Matrix3d& q_ref = data[reference].imu->stated_mounting;
  for (size_t i = 0; i < data.size(); ++i) {
    if (static_cast<int>(i) == reference) continue;
    const Eigen::Matrix3d expected = q_ref.transpose() * data[i].imu->stated_mounting;
    const Eigen::Matrix3d deviation = expected.transpose() * params[i].Rotation();
    const double off = RotationAngleDeg(deviation);
    double angle = 0.0;
    const Eigen::Matrix3d p = NearestAxisRotation(deviation, &angle);
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(1);
    if (!p.isIdentity(1e-9) && angle <= options.permutation_tolerance_deg) {
      s << data[i].imu->name << " looks " << DescribeAxisRotation(p) << " from "
        << data[reference].imu->name << " (beyond its stated mounting; " << angle
        << " deg from that turn): permuted or flipped axes?";
      result->warnings.push_back(s.str());
    } else if (off > options.mounting_warning_deg) {
      s << data[i].imu->name << "'s rotation to " << data[reference].imu->name << " is " << off
        << " deg from its stated mounting";
      result->warnings.push_back(s.str());
    }
  }
}

int FindMovedUnit(const std::vector<PlateImuData>& data,
                  const std::vector<PlateImuParameters>& params, const MultiImuOptions& options,
                  int* split, MultiImuResult* result) {
  const size_t n = data.size();
  const size_t poses = data.empty() ? 0 : data[0].poses.size();
  if (n < 2 || poses < 6) return -1;
  std::vector<std::vector<Eigen::Vector3d>> dirs(n);
  for (size_t i = 0; i < n; ++i) {
    for (const PlatePoseData& pose : data[i].poses) dirs[i].push_back(params[i].Direction(pose));
  }
  auto spans = [](const std::vector<Eigen::Vector3d>& y) {
    Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& v : y) s += v * v.transpose();
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(s);
    return svd.singularValues()[1] / static_cast<double>(y.size()) > 0.02;
  };
  auto fit = [](const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y,
                Eigen::Matrix3d* r) {
    *r = Wahba(x, y);
    double c = 0.0;
    for (size_t k = 0; k < x.size(); ++k) c += (x[k] - *r * y[k]).squaredNorm();
    return c;
  };
  struct PairFlag {
    size_t i, l;
    int split;
    double angle;
  };
  std::vector<PairFlag> flags;
  for (size_t i = 0; i < n; ++i) {
    for (size_t l = i + 1; l < n; ++l) {
      Eigen::Matrix3d r_all;
      const double all = fit(dirs[l], dirs[i], &r_all);
      double best = all;
      int best_split = -1;
      double best_angle = 0.0;
      for (size_t s = 3; s + 3 <= poses; ++s) {
        std::vector<Eigen::Vector3d> xb(dirs[l].begin(), dirs[l].begin() + s),
            yb(dirs[i].begin(), dirs[i].begin() + s), xa(dirs[l].begin() + s, dirs[l].end()),
            ya(dirs[i].begin() + s, dirs[i].end());
        if (!spans(yb) || !spans(ya)) continue;
        Eigen::Matrix3d rb, ra;
        const double c = fit(xb, yb, &rb) + fit(xa, ya, &ra);
        if (c < best) {
          best = c;
          best_split = static_cast<int>(s);
          best_angle = RotationAngleDeg(rb.transpose() * ra);
        }
      }
      const double dof = 2.0 * poses - 6.0;
      if (best_split < 0 || dof <= 0.0) continue;
      const double f = ((all - best) / 3.0) / std::max(best / dof, 1e-300);
      if (f > options.slip_factor * options.slip_factor && best_angle > options.slip_min_deg) {
        flags.push_back({i, l, best_split, best_angle});
      }
    }
  }
  if (flags.empty()) return -1;
  std::vector<int> count(n, 0);
  for (const PairFlag& f : flags) {
    ++count[f.i];
    ++count[f.l];
  }
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(2);
  if (n == 2) {
    const PairFlag& f = flags[0];
    const int moved = result->reference == 0 ? 1 : 0;
    *split = f.split;
    s << data[0].imu->name << " and " << data[1].imu->name
      << " disagree: one of them moved on the plate between pose " << f.split - 1 << " and pose "
      << f.split << " (" << f.angle
      << " deg); two IMUs cannot tell which; the rotation after the move is estimated on its own";
    result->warnings.push_back(s.str());
    return moved;
  }
  const int moved = static_cast<int>(std::max_element(count.begin(), count.end()) - count.begin());
  const int others = static_cast<int>(flags.size()) - count[moved];
  if (count[moved] * 4 < 3 * static_cast<int>(n - 1) ||
      others * 4 > static_cast<int>(flags.size())) {
    s << "the IMUs' poses disagree in " << flags.size()
      << " pairs, not attributable to one unit: the plate is not rigid, or several units moved";
    result->warnings.push_back(s.str());
    return -1;
  }
  std::vector<int> splits;
  double angle = 0.0;
  for (const PairFlag& f : flags) {
    if (static_cast<int>(f.i) != moved && static_cast<int>(f.l) != moved) continue;
    splits.push_back(f.split);
    angle = std::max(angle, f.angle);
  }
  std::nth_element(splits.begin(), splits.begin() + splits.size() / 2, splits.end());
  *split = splits[splits.size() / 2];
  s << data[moved].imu->name
    << " moved on the plate during the session: its poses disagree with the others' (its "
       "rotation changes by about "
    << angle << " deg between pose " << *split - 1 << " and pose " << *split
    << "); its rotation after the move is estimated on its own";
  result->warnings.push_back(s.str());
  return moved;
}

}  // namespace internal

Eigen::Matrix3d NearestAxisRotation(const Eigen::Matrix3d& rotation, double* angle_deg) {
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  Eigen::Matrix3d best = Eigen::Matrix3d::Identity();
  double best_angle = 1e300;
  for (const auto& p : perms) {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
      for (int r = 0; r < 3; ++r) m(r, p[r]) = (signs >> r) & 1 ? -1.0 : 1.0;
      if (m.determinant() < 0.0) continue;
      const double a = internal::RotationAngleDeg(m.transpose() * rotation);
      if (a < best_angle) {
        best_angle = a;
        best = m;
      }
    }
  }
  if (angle_deg != nullptr) *angle_deg = best_angle;
  return best;
}

std::string DescribeAxisRotation(const Eigen::Matrix3d& rotation) {
  const Eigen::AngleAxisd aa(rotation);
  const double angle = aa.angle() * 180.0 / M_PI;
  if (angle < 1e-6) return "not rotated";
  std::ostringstream s;
  s << "rotated " << std::lround(angle) << " degrees about ";
  const Eigen::Vector3d axis = aa.axis();
  const char* names = "xyz";
  for (int j = 0; j < 3; ++j) {
    if (std::abs(std::abs(axis[j]) - 1.0) < 1e-6) {
      s << (axis[j] < 0 ? "-" : "") << names[j];
      return s.str();
    }
  }
  s.precision(2);
  s.setf(std::ios::fixed);
  s << "(" << axis.x() << ", " << axis.y() << ", " << axis.z() << ")";
  return s.str();
}

}  // namespace gravcal
