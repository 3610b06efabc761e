#include "core/sensor_checks.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/QR>
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

// The warning for one extreme `value` of axis `axis` of `x`, or "".
std::string SaturatedAt(const std::string& sensor, const std::vector<Eigen::Vector3d>& x, int axis,
                        double value, double band, const char* which) {
  size_t at = 0, near = 0, runs = 0, longest = 0, longest_begin = 0, first_begin = 0;
  for (size_t i = 0; i < x.size();) {
    const double v = x[i][axis];
    if (v != value) {
      if (std::abs(v - value) <= band) ++near;
      ++i;
      continue;
    }
    const size_t begin = i;
    while (i < x.size() && x[i][axis] == value) ++i;
    at += i - begin;
    if (runs++ == 0) first_begin = begin;
    if (i - begin > longest) {
      longest = i - begin;
      longest_begin = begin;
    }
  }
  if (at < 3 || longest < 2 || at <= near) return "";
  return sensor + " " + kAxis[axis] + ": " + std::to_string(at) + " samples in " +
         std::to_string(runs) + " run" + (runs == 1 ? "" : "s") + " sit at its " + which +
         " value " + Num(value) + " (first at sample " + std::to_string(first_begin) +
         ", longest samples " + std::to_string(longest_begin) + "-" +
         std::to_string(longest_begin + longest) +
         "): the axis looks saturated (clipped at its full scale), and the poses or turns "
         "with those samples are wrong; record with a larger range or turn more slowly";
}

void CheckSensor(const std::string& sensor, const std::vector<Eigen::Vector3d>& x,
                 std::vector<std::string>* warnings) {
  if (x.size() < 3) return;
  for (int axis = 0; axis < 3; ++axis) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Eigen::Vector3d& v : x) {
      lo = std::min(lo, v[axis]);
      hi = std::max(hi, v[axis]);
    }
    if (!(hi > lo) || !std::isfinite(hi - lo)) continue;
    const double band = 0.01 * (hi - lo);
    for (const std::string& w : {SaturatedAt(sensor, x, axis, hi, band, "largest"),
                                 SaturatedAt(sensor, x, axis, lo, band, "smallest")}) {
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

}  // namespace internal
}  // namespace gravcal
