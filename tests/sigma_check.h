// The one error/sigma accumulator of the tests, and the bands that say when
// a reported standard deviation matches the spread seen over many seeds.
//
// For N seeds with honest sigmas, z = (estimate - truth) / sigma is N(0, 1),
// so
//   mean(z) ~ N(0, 1/N)                    -> |mean z| < q / sqrt(N),
//   N rms(z)^2 ~ chi-square with N dof     -> rms z in [sqrt(c_lo / N), sqrt(c_hi / N)],
// with q the two-sided normal quantile and c_lo, c_hi the chi-square
// quantiles at the same probability. The band is a statement of probability
// (kSigmaBandProbability, the same in every test), not a number read off a
// run: sigmas twice too large give rms 0.5 and fail for N >= 30, sigmas
// twice too small give rms 2 and fail for N >= 10.
#ifndef GRAVCAL_TESTS_SIGMA_CHECK_H_
#define GRAVCAL_TESTS_SIGMA_CHECK_H_

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "util/statistics.h"

namespace gravcal {
namespace testing_util {

// Two-sided probability that an honest estimator passes one check.
constexpr double kSigmaBandProbability = 0.999;

// The standard normal quantile (Acklam's rational approximation refined by
// one Halley step; |error| < 1e-12 over (0, 1)).
inline double NormalQuantile(double p) {
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  double x;
  if (p < 0.02425) {
    const double q = std::sqrt(-2.0 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  } else if (p > 1.0 - 0.02425) {
    const double q = std::sqrt(-2.0 * std::log(1.0 - p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  } else {
    const double q = p - 0.5;
    const double r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  }
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
  const double u = e * std::sqrt(2.0 * M_PI) * std::exp(x * x / 2.0);
  return x - u / (1.0 + x * u / 2.0);
}

// Chi-square quantile with `dof` degrees of freedom: the x whose lower tail
// is p, by bisection on the library's upper tail (util/statistics.h).
inline double ChiSquareQuantile(double p, int dof) {
  double lo = 0.0;
  double hi = dof + 20.0 * std::sqrt(2.0 * dof) + 50.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (1.0 - internal::ChiSquareUpperTail(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// The band for rms(z) over n honest draws at `probability` (two-sided).
struct SigmaBand {
  double mean_bound = 0.0;  // |mean z| must be below this
  double rms_low = 0.0;
  double rms_high = 0.0;
};

inline SigmaBand SigmaBandFor(int n, double probability = kSigmaBandProbability) {
  const double tail = 0.5 * (1.0 - probability);
  SigmaBand band;
  band.mean_bound = NormalQuantile(1.0 - tail) / std::sqrt(static_cast<double>(n));
  band.rms_low = std::sqrt(ChiSquareQuantile(tail, n) / n);
  band.rms_high = std::sqrt(ChiSquareQuantile(1.0 - tail, n) / n);
  return band;
}

// z = error / sigma per named parameter, accumulated over seeds.
class SigmaCheck {
 public:
  void Add(const std::string& name, double error, double sigma) {
    Entry& e = entries_[name];
    if (!(sigma > 0.0) || !std::isfinite(error)) {
      ++e.missing;
      return;
    }
    const double z = error / sigma;
    e.z.push_back(z);
  }

  int Count(const std::string& name) const {
    auto it = entries_.find(name);
    return it == entries_.end() ? 0 : static_cast<int>(it->second.z.size());
  }
  double Mean(const std::string& name) const {
    const std::vector<double>& z = entries_.at(name).z;
    double s = 0.0;
    for (double v : z) s += v;
    return s / z.size();
  }
  double Rms(const std::string& name) const {
    const std::vector<double>& z = entries_.at(name).z;
    double s = 0.0;
    for (double v : z) s += v * v;
    return std::sqrt(s / z.size());
  }
  std::vector<std::string> Names() const {
    std::vector<std::string> names;
    for (const auto& [name, entry] : entries_) names.push_back(name);
    return names;
  }

  // Every parameter: no seed without a sigma, |mean z| and rms z inside the
  // band for its count. `context` names the method in failure messages.
  void ExpectHonest(const std::string& context, double probability = kSigmaBandProbability) const {
    for (const auto& [name, e] : entries_) {
      EXPECT_EQ(e.missing, 0) << context << " " << name << ": " << e.missing
                              << " seeds without a finite sigma";
      if (e.z.empty()) continue;
      const SigmaBand band = SigmaBandFor(static_cast<int>(e.z.size()), probability);
      const double mean = Mean(name);
      const double rms = Rms(name);
      EXPECT_LT(std::abs(mean), band.mean_bound)
          << context << " " << name << ": mean error/sigma " << mean << " over " << e.z.size()
          << " seeds (biased)";
      EXPECT_GT(rms, band.rms_low) << context << " " << name << ": rms error/sigma " << rms
                                   << " below " << band.rms_low << " (sigma too large)";
      EXPECT_LT(rms, band.rms_high) << context << " " << name << ": rms error/sigma " << rms
                                    << " above " << band.rms_high << " (sigma too small)";
    }
  }

  // One line per parameter: name, n, mean z, rms z, band.
  std::string Table() const {
    std::ostringstream s;
    for (const auto& [name, e] : entries_) {
      if (e.z.empty()) continue;
      const SigmaBand band = SigmaBandFor(static_cast<int>(e.z.size()));
      s << name << " n=" << e.z.size() << " mean=" << Mean(name) << " rms=" << Rms(name)
        << " band=[" << band.rms_low << ", " << band.rms_high << "] |mean|<" << band.mean_bound
        << "\n";
    }
    return s.str();
  }

 private:
  struct Entry {
    std::vector<double> z;
    int missing = 0;
  };
  std::map<std::string, Entry> entries_;
};

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_SIGMA_CHECK_H_
