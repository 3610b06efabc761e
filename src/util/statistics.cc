#include "util/statistics.h"

#include <algorithm>
#include <cmath>

namespace gravcal {
namespace internal {
namespace {

// log Gamma(a). std::lgamma also writes the global `signgam`, a data race
// when units are calibrated on several threads (ThreadSanitizer found it in
// gravcal batch); lgamma_r returns the sign instead, same value.
double LogGamma(double a) {
  int sign = 0;
  return lgamma_r(a, &sign);
}

// Regularised lower incomplete gamma P(a, x) by its series (x < a + 1).
double GammaSeries(double a, double x) {
  double sum = 1.0 / a;
  double term = sum;
  for (int n = 1; n < 1000; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::fabs(term) < std::fabs(sum) * 1e-15) break;
  }
  return sum * std::exp(-x + a * std::log(x) - LogGamma(a));
}

// Regularised upper incomplete gamma Q(a, x) by Lentz's continued fraction
// (x >= a + 1).
double GammaContinuedFraction(double a, double x) {
  const double tiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / tiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - LogGamma(a)) * h;
}

// Continued fraction of the regularised incomplete beta I_x(a, b), Lentz's
// method: 1 / (1 + d1 / (1 + d2 / (1 + ...))) with
// d_2m+1 = -(a + m)(a + b + m) x / ((a + 2m)(a + 2m + 1)),
// d_2m = m (b - m) x / ((a + 2m - 1)(a + 2m)).
double BetaContinuedFraction(double a, double b, double x) {
  const double tiny = 1e-300;
  double c = 1.0;
  double d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::fabs(d) < tiny) d = tiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m < 1000; ++m) {
    const double m2 = 2.0 * m;
    double an = m * (b - m) * x / ((a + m2 - 1.0) * (a + m2));
    d = 1.0 + an * d;
    if (std::fabs(d) < tiny) d = tiny;
    c = 1.0 + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    h *= d * c;
    an = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0));
    d = 1.0 + an * d;
    if (std::fabs(d) < tiny) d = tiny;
    c = 1.0 + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::fabs(delta - 1.0) < 1e-15) break;
  }
  return h;
}

// I_x(a, b).
double RegularizedBeta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  const double front =
      std::exp(LogGamma(a + b) - LogGamma(a) - LogGamma(b) + a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * BetaContinuedFraction(a, b, x) / a;
  return 1.0 - front * BetaContinuedFraction(b, a, 1.0 - x) / b;
}

}  // namespace

double FUpperTail(double f, double d1, double d2) {
  if (!(d1 > 0.0) || !(d2 > 0.0) || !(f > 0.0)) return 1.0;
  return RegularizedBeta(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f));
}

double ChiSquareUpperTail(double x, int dof) {
  if (dof <= 0) return 1.0;
  if (!(x > 0.0)) return 1.0;
  const double a = 0.5 * dof;
  const double hx = 0.5 * x;
  if (hx < a + 1.0) return 1.0 - GammaSeries(a, hx);
  return GammaContinuedFraction(a, hx);
}

double ChiSquareDensity(double x, double dof) {
  if (!(x > 0.0) || !(dof > 0.0)) return 0.0;
  const double a = 0.5 * dof;
  return std::exp((a - 1.0) * std::log(x) - 0.5 * x - a * std::log(2.0) - LogGamma(a));
}

// The standard normal quantile by bisection of erfc (for confidence levels:
// a few calls per curve point).
double NormalQuantile(double p) {
  double lo = -40.0, hi = 40.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// The chi-square quantile: P(X <= x) = p for X with `dof` degrees of
// freedom. Up to 100 dof, bisection on the exact tail with dof rounded (the
// edf is an approximation to begin with); above, Wilson and Hilferty's cube
// root approximation, accurate to well under 1 % there.
double ChiSquareQuantile(double p, double dof) {
  if (dof > 100.0) {
    const double a = 2.0 / (9.0 * dof);
    const double c = 1.0 - a + NormalQuantile(p) * std::sqrt(a);
    return dof * c * c * c;
  }
  const int k = std::max(1, static_cast<int>(std::lround(dof)));
  double lo = 0.0, hi = k + 40.0 * std::sqrt(2.0 * k) + 60.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (1.0 - ChiSquareUpperTail(mid, k) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi) * dof / k;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  double m = values[mid];
  if (values.size() % 2 == 0) {
    m = 0.5 * (m + *std::max_element(values.begin(), values.begin() + mid));
  }
  return m;
}

double Rms(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double s = 0.0;
  for (double v : values) s += v * v;
  return std::sqrt(s / values.size());
}

double MaxAbs(const std::vector<double>& values) {
  double m = 0.0;
  for (double v : values) m = std::max(m, std::fabs(v));
  return m;
}

}  // namespace internal
}  // namespace gravcal
