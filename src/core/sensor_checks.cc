#include "core/sensor_checks.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace gravcal {
namespace internal {
namespace {

constexpr const char* kAxis[3] = {"x", "y", "z"};

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

// The samples of one axis at one of its extreme values: how many, in how
// many runs (of consecutive samples), the first and the longest run, and
// how many other samples are near it (within `band`).
struct ExtremeRuns {
  double value = 0.0, band = 0.0;
  size_t at = 0, near = 0, runs = 0, longest = 0, longest_begin = 0, first_begin = 0;
  size_t run_begin = 0;
  bool in_run = false;

  void Add(double v, size_t i) {
    if (v == value) {
      if (!in_run) {
        in_run = true;
        run_begin = i;
        if (runs++ == 0) first_begin = i;
      }
      ++at;
      return;
    }
    End(i);
    if (std::abs(v - value) <= band) ++near;
  }
  void End(size_t i) {
    if (!in_run) return;
    in_run = false;
    if (i - run_begin > longest) {
      longest = i - run_begin;
      longest_begin = run_begin;
    }
  }
};

// The warning for one extreme of axis `axis` (counted in `e`), or "".
std::string SaturatedAt(const std::string& sensor, int axis, const ExtremeRuns& e,
                        const char* which) {
  if (e.at < 3 || e.longest < 2 || e.at <= e.near) return "";
  return sensor + " " + kAxis[axis] + ": " + std::to_string(e.at) + " samples in " +
         std::to_string(e.runs) + " run" + (e.runs == 1 ? "" : "s") + " sit at its " + which +
         " value " + Num(e.value) + " (first at sample " + std::to_string(e.first_begin) +
         ", longest samples " + std::to_string(e.longest_begin) + "-" +
         std::to_string(e.longest_begin + e.longest) +
         "): the axis looks saturated (clipped at its full scale), and the poses or turns "
         "with those samples are wrong; record with a larger range or turn more slowly";
}

// Two passes over the samples: the extremes of each axis, then their runs
// (every axis and both extremes at once).
void CheckSensor(const std::string& sensor, const std::vector<Eigen::Vector3d>& x,
                 std::vector<std::string>* warnings) {
  if (x.size() < 3) return;
  double lo[3], hi[3];
  for (int axis = 0; axis < 3; ++axis) {
    lo[axis] = std::numeric_limits<double>::infinity();
    hi[axis] = -lo[axis];
  }
  for (const Eigen::Vector3d& v : x) {
    for (int axis = 0; axis < 3; ++axis) {
      lo[axis] = std::min(lo[axis], v[axis]);
      hi[axis] = std::max(hi[axis], v[axis]);
    }
  }
  // [axis][0]: the largest value, [axis][1]: the smallest.
  ExtremeRuns extremes[3][2];
  bool checked[3];
  for (int axis = 0; axis < 3; ++axis) {
    checked[axis] = hi[axis] > lo[axis] && std::isfinite(hi[axis] - lo[axis]);
    const double band = checked[axis] ? 0.01 * (hi[axis] - lo[axis]) : 0.0;
    extremes[axis][0].value = hi[axis];
    extremes[axis][1].value = lo[axis];
    extremes[axis][0].band = extremes[axis][1].band = band;
  }
  // A block of samples none of which is near an extreme (the distance Add
  // computes above twice the band, so never near nor at it) only ends the
  // runs at its first sample, as Add would.
  double reach[3];
  for (int axis = 0; axis < 3; ++axis) {
    reach[axis] =
        checked[axis] ? 2.0 * extremes[axis][0].band : -std::numeric_limits<double>::infinity();
  }
  constexpr size_t kBlock = 16;
  const double* const p = x[0].data();  // contiguous: 3 doubles per sample
  for (size_t b = 0; b < x.size(); b += kBlock) {
    const size_t e = std::min(x.size(), b + kBlock);
    bool near = false;
    for (size_t i = b; i < e; ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        const double v = p[3 * i + axis];
        near |= (hi[axis] - v <= reach[axis]) | (v - lo[axis] <= reach[axis]);
      }
    }
    if (!near) {
      for (int axis = 0; axis < 3; ++axis) {
        extremes[axis][0].End(b);
        extremes[axis][1].End(b);
      }
      continue;
    }
    for (size_t i = b; i < e; ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        if (!checked[axis]) continue;
        extremes[axis][0].Add(x[i][axis], i);
        extremes[axis][1].Add(x[i][axis], i);
      }
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (!checked[axis]) continue;
    for (int k = 0; k < 2; ++k) {
      extremes[axis][k].End(x.size());
      const std::string w =
          SaturatedAt(sensor, axis, extremes[axis][k], k == 0 ? "largest" : "smallest");
      if (!w.empty()) warnings->push_back(w);
    }
  }
}

}  // namespace

std::vector<std::string> SaturationWarnings(const ImuLog& log) {
  std::vector<std::string> warnings;
  CheckSensor("accelerometer", log.accel, &warnings);
  CheckSensor("gyroscope", log.gyro, &warnings);
  return warnings;
}

std::string HandednessWarning(const std::string& sensor, const Eigen::Matrix3d& m) {
  const double det = m.determinant();
  if (!(det < 0.0)) return "";
  // Candidates: flip raw axis i (negate column i), or swap raw axes i and j.
  double best = std::numeric_limits<double>::infinity();
  std::string cause;
  auto score = [](const Eigen::Matrix3d& c) {
    Eigen::Matrix3d n = c;
    for (int k = 0; k < 3; ++k) n.col(k) /= std::max(n.col(k).norm(), 1e-300);
    return (n - Eigen::Matrix3d::Identity()).norm();
  };
  for (int i = 0; i < 3; ++i) {
    Eigen::Matrix3d c = m;
    c.col(i) = -c.col(i);
    const double s = score(c);
    if (s < best) {
      best = s;
      cause = std::string("its raw ") + kAxis[i] +
              " axis looks flipped (the opposite sign convention to the other axes and the "
              "accelerometer)";
    }
    for (int j = i + 1; j < 3; ++j) {
      Eigen::Matrix3d p = m;
      p.col(i).swap(p.col(j));
      const double sp = score(p);
      if (sp < best) {
        best = sp;
        cause = std::string("its raw ") + kAxis[i] + " and " + kAxis[j] + " axes look swapped";
      }
    }
  }
  std::string message =
      "the fitted " + sensor + " matrix is left-handed (determinant " + Num(det) + "): ";
  if (best < 0.5) {
    return message + cause +
           "; fix the axis in the logger or the reader (or negate or swap those columns) and "
           "calibrate again, or the calibration carries the mirror image";
  }
  return message +
         "no single flipped axis or swapped pair explains it; check the axis conventions of "
         "the columns";
}

std::string GyroLooksLikeAccelerometer(const std::vector<StaticInterval>& intervals) {
  const size_t n = intervals.size();
  if (n < 6) return "";
  std::vector<double> norms;
  for (const StaticInterval& s : intervals) norms.push_back(s.gyro_mean.norm());
  std::vector<double> sorted = norms;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double median = sorted[n / 2];
  if (!(median > 0.0)) return "";
  for (double v : norms) {
    if (std::abs(v - median) > 0.15 * median) return "";
  }
  double widest = 0.0;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < i; ++j) {
      const Eigen::Vector3d& a = intervals[i].gyro_mean;
      const Eigen::Vector3d& b = intervals[j].gyro_mean;
      widest = std::max(widest, std::atan2(a.cross(b).norm(), a.dot(b)));
    }
  }
  if (widest < 60.0 * M_PI / 180.0) return "";
  // g_k = A a_k + c by least squares: rows (a_k^T, 1).
  Eigen::MatrixXd x(n, 4), y(n, 3);
  for (size_t k = 0; k < n; ++k) {
    x.row(k) << intervals[k].accel_mean.transpose(), 1.0;
    y.row(k) = intervals[k].gyro_mean.transpose();
  }
  const Eigen::MatrixXd coef = x.colPivHouseholderQr().solve(y);
  const double residual = (x * coef - y).squaredNorm();
  const double spread = (y.rowwise() - y.colwise().mean()).squaredNorm();
  if (!(residual < 0.01 * spread)) return "";
  return "the gyroscope columns look like accelerometer data: in the " + std::to_string(n) +
         " still intervals their means have one norm (" + Num(median) +
         ") and turn with the accelerometer's (a linear map explains " +
         Num(100.0 * (1.0 - residual / spread)) +
         " % of their spread), as gravity does; check which columns are gx, gy, gz";
}

namespace {

// The centre of the sphere the samples x lie on (least squares on
// |x|^2 = 2 c.x + (r^2 - |c|^2), linear in c), or zero when the samples do
// not span enough directions to tell (a poorly conditioned system).
Eigen::Vector3d SphereCentre(const std::vector<Eigen::Vector3d>& x) {
  if (x.size() < 10) return Eigen::Vector3d::Zero();
  Eigen::MatrixXd a(x.size(), 4);
  Eigen::VectorXd b(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    a.row(i) << 2.0 * x[i].transpose(), 1.0;
    b(i) = x[i].squaredNorm();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  if (!(sv(3) > 1e-3 * sv(0))) return Eigen::Vector3d::Zero();
  const Eigen::VectorXd c = svd.solve(b);
  return c.head<3>();
}

// The signed permutation number `code` (0..47): row i of M has sign
// sign_i at column perm[i].
Eigen::Matrix3d SignedPermutation(int code) {
  static const int kPerms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                   {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  const int* perm = kPerms[code / 8];
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) m(i, perm[i]) = (code >> i) & 1 ? -1.0 : 1.0;
  return m;
}

// What M says about the raw gyroscope axes, in words; `brief`: without the
// explanation in brackets.
std::string DescribeMapping(const Eigen::Matrix3d& m, bool brief) {
  int flipped = 0, flipped_axis = -1, moved = 0;
  for (int i = 0; i < 3; ++i) {
    if (m(i, i) == 0.0) ++moved;
    for (int j = 0; j < 3; ++j) {
      if (m(i, j) < 0.0) {
        ++flipped;
        flipped_axis = j;
      }
    }
  }
  if (moved == 0 && flipped == 0) return "the columns as given";
  if (moved == 0 && flipped == 1) {
    return std::string("its raw ") + kAxis[flipped_axis] + " axis looks flipped" +
           (brief ? ""
                  : " (the opposite sign convention to the other axes and the "
                    "accelerometer)");
  }
  if (moved == 0 && flipped == 2) {
    const int kept = m(0, 0) > 0.0 ? 0 : m(1, 1) > 0.0 ? 1 : 2;
    return std::string("its raw ") + kAxis[(kept + 1) % 3] + " and " + kAxis[(kept + 2) % 3] +
           " axes both look flipped" +
           (brief ? ""
                  : std::string(" (a half turn about ") + kAxis[kept] +
                        " against the accelerometer's axes)");
  }
  if (moved == 0 && flipped == 3) {
    return std::string("its raw x, y and z axes all look flipped") +
           (brief ? "" : " (the columns read minus the rate: a mirror image)");
  }
  if (moved == 2 && flipped == 0) {
    int i = 0;
    while (m(i, i) != 0.0) ++i;
    int j = i + 1;
    while (m(j, j) != 0.0) ++j;
    return std::string("its raw ") + kAxis[i] + " and " + kAxis[j] + " axes look swapped";
  }
  std::string text = "its axes fit the accelerometer's as";
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (m(i, j) != 0.0) {
        text += std::string(i ? "," : "") + " " + kAxis[i] + " = " + (m(i, j) < 0 ? "-" : "+") +
                "raw " + kAxis[j];
      }
    }
  }
  return text;
}

}  // namespace

std::string GyroAxisConventionWarning(const ImuLog& log) {
  const size_t n = std::min(log.accel.size(), log.gyro.size());
  if (n < 50 || log.t.size() < n) return "";
  // Means over bins of kBin seconds of time (host time stamps come in
  // bursts: a count of samples is no measure of time), and their times.
  // The bins are long enough that the differences of f are mostly turning:
  // on the sunsided MPU-6050 hand-held logs the mapping that fits explains
  // 68 % and 88 % of df/dt over 0.05 s bins (the rest is the accelerometer's
  // noise and the hand's tremor, amplified by differencing) and 84 % and 95 %
  // over 0.1 s, while a central difference over two bins of a 250 deg/s
  // turn shortens df/dt only by sin(x)/x = 0.97.
  constexpr double kBin = 0.1;
  std::vector<Eigen::Vector3d> f, w;
  std::vector<double> t;
  for (size_t i = 0; i < n;) {
    const double start = log.t[i];
    if (!std::isfinite(start)) return "";
    Eigen::Vector3d a = Eigen::Vector3d::Zero(), g = Eigen::Vector3d::Zero();
    double s = 0.0;
    size_t k = i;
    for (; k < n && log.t[k] >= start && log.t[k] < start + kBin; ++k) {
      a += log.accel[k];
      g += log.gyro[k];
      s += log.t[k];
    }
    if (k == i) return "";  // time going backwards: not this check's to judge
    const double count = static_cast<double>(k - i);
    f.push_back(a / count);
    w.push_back(g / count);
    t.push_back(s / count);
    i = k;
  }
  if (f.size() < 40) return "";
  const Eigen::Vector3d centre = SphereCentre(f);
  for (Eigen::Vector3d& v : f) v -= centre;
  // The gyroscope's offset: its median per axis (the unit is still part of
  // the time in most logs; a turn's rate is far above it anyway).
  Eigen::Vector3d bias;
  for (int a = 0; a < 3; ++a) {
    std::vector<double> v;
    for (const Eigen::Vector3d& x : w) v.push_back(x(a));
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    bias(a) = v[v.size() / 2];
  }
  std::vector<double> norms, rates;
  for (size_t i = 0; i < f.size(); ++i) {
    norms.push_back(f[i].norm());
    rates.push_back((w[i] - bias).norm());
  }
  std::vector<double> sorted = norms;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double g = sorted[sorted.size() / 2];
  sorted = rates;
  std::nth_element(sorted.begin(), sorted.begin() + 9 * sorted.size() / 10, sorted.end());
  const double fast = sorted[9 * sorted.size() / 10];
  if (!(g > 0.0) || !(fast > 0.0)) return "";
  // Central differences at the moving samples with |f| near g.
  std::vector<Eigen::Vector3d> d, fm, wm;
  double turning = 0.0;
  for (size_t i = 1; i + 1 < f.size(); ++i) {
    const double span = t[i + 1] - t[i - 1];
    if (!(span > 0.0) || span > 4.0 * kBin) continue;
    if (std::abs(norms[i] - g) > 0.1 * g || rates[i] < 0.2 * fast) continue;
    d.push_back((f[i + 1] - f[i - 1]) / span);
    fm.push_back(f[i]);
    wm.push_back(w[i] - bias);
    turning += 0.5 * span;
  }
  if (turning < 2.0 || d.size() < 20) return "";
  double total = 0.0;
  for (const Eigen::Vector3d& v : d) total += v.squaredNorm();
  // For each mapping M, c_i = f_i x (M w_i), cd = sum c_i.d_i and
  // cc = sum |c_i|^2, from sums over the samples taken once: with the
  // triple product (f x v).d = v.(d x f) and |M w| = |w| (M is a signed
  // permutation),
  //   cd = sum_rc M_rc S_rc,                S = sum (d_i x f_i) w_i^T,
  //   cc = sum |f_i|^2 |w_i|^2 - m^T Q m,   Q = sum p_i p_i^T,
  // m and p_i the 9 entries of M and of f_i w_i^T.
  Eigen::Matrix3d sum_s = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 9, 9> sum_q = Eigen::Matrix<double, 9, 9>::Zero();
  double sum_norms = 0.0;
  for (size_t i = 0; i < d.size(); ++i) {
    sum_s += d[i].cross(fm[i]) * wm[i].transpose();
    const Eigen::Matrix3d p = fm[i] * wm[i].transpose();
    const Eigen::Map<const Eigen::Matrix<double, 9, 1>> pv(p.data());
    sum_q.noalias() += pv * pv.transpose();
    sum_norms += fm[i].squaredNorm() * wm[i].squaredNorm();
  }
  double best = INFINITY, second = INFINITY, identity = INFINITY;
  int best_code = 0, second_code = 0;
  for (int code = 0; code < 48; ++code) {
    const Eigen::Matrix3d m = SignedPermutation(code);
    const Eigen::Map<const Eigen::Matrix<double, 9, 1>> mv(m.data());
    const double cd = m.cwiseProduct(sum_s).sum();
    const double cc = sum_norms - mv.dot(sum_q * mv);
    if (!(cc > 0.0)) continue;
    const double k = std::max(cd / cc, 0.0);
    const double residual = total - 2.0 * k * cd + k * k * cc;
    if (code == 0) identity = residual;
    if (residual < best) {
      second = best;
      second_code = best_code;
      best = residual;
      best_code = code;
    } else if (residual < second) {
      second = residual;
      second_code = code;
    }
  }
  // The best mapping must explain a fair part of the turning (hand turns
  // carry linear accelerations too), and the columns as given less than
  // half of what it explains.
  const double explained = 1.0 - best / total;
  const double as_given = std::max(0.0, 1.0 - identity / total);
  if (best_code == 0 || !(explained > 0.3) || !(as_given < 0.5 * explained)) return "";
  // Each raw axis's own signed gain, the best mapping's permutation kept:
  // d_i = sum_j s_j (f_i x e_j) v_ij, v_i = |M| w_i, by least squares
  // (normal equations A s = b with (f x e_j).(f x e_k) = |f|^2 delta_jk -
  // f_j f_k and (f x e_j).d = e_j.(d x f)). The signs say which axes are
  // flipped one by one; the mean |s_j| is the column unit in rad/s.
  const Eigen::Matrix3d best_m = SignedPermutation(best_code);
  const Eigen::Matrix3d permutation = best_m.cwiseAbs();
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < d.size(); ++i) {
    const Eigen::Vector3d v = permutation * wm[i];
    const Eigen::Matrix3d ff =
        fm[i].squaredNorm() * Eigen::Matrix3d::Identity() - fm[i] * fm[i].transpose();
    normal.noalias() += v.asDiagonal() * ff * v.asDiagonal();
    rhs += v.cwiseProduct(d[i].cross(fm[i]));
  }
  const Eigen::Vector3d gain = normal.ldlt().solve(rhs);
  const double fitted = total - gain.dot(rhs);
  const double unit = gain.cwiseAbs().mean();
  std::string gains;
  for (int c = 0; c < 3; ++c) {
    int row = 0;
    while (permutation(row, c) == 0.0) ++row;
    const double g_c = unit > 0.0 ? gain(row) / unit : 0.0;
    gains += std::string(c == 0   ? ""
                         : c == 1 ? ", "
                                  : " and ") +
             kAxis[c] + " " + (g_c >= 0.0 ? "+" : "") + Num(std::round(100.0 * g_c) / 100.0);
    // What this axis's sign is worth: the share of the turning lost when
    // it alone is negated. An axis the unit barely turned about is named.
    Eigen::Vector3d other = gain;
    other(row) = -other(row);
    const double worth =
        (total - 2.0 * other.dot(rhs) + other.dot(normal * other) - fitted) / total;
    if (worth < 0.1) {
      gains += " (barely turned about: its sign is worth " + Num(std::round(100.0 * worth)) +
               " % of the turning)";
    }
  }
  const double runner_up = std::max(0.0, 1.0 - second / total);
  return "the gyroscope's axes disagree with the accelerometer's: while the unit turns, the "
         "specific force turns as the gyroscope says only with another axis convention: " +
         DescribeMapping(best_m, false) + ". Fitted one by one, the raw axes' rates enter as " +
         gains + " times the column (one column unit is " + Num(unit) +
         " rad/s, 0.01745 for deg/s); that mapping explains " + Num(std::round(100.0 * explained)) +
         " % of the turning, the next best (" +
         DescribeMapping(SignedPermutation(second_code), true) + ") " +
         Num(std::round(100.0 * runner_up)) + " %, the columns as given " +
         Num(std::round(100.0 * as_given)) +
         " % (the rest is linear acceleration and noise). Fix the axes in the logger or the "
         "reader (negate or swap those columns), or a gyroscope calibration carries the mirror "
         "image";
}

}  // namespace internal
}  // namespace gravcal
