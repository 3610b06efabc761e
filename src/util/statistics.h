// Private: small statistics helpers.
#ifndef GRAVCAL_SRC_UTIL_STATISTICS_H_
#define GRAVCAL_SRC_UTIL_STATISTICS_H_

#include <vector>

namespace gravcal {
namespace internal {

// P(X > x) for X ~ chi-square with `dof` degrees of freedom (regularised
// upper incomplete gamma function, series / continued fraction).
double ChiSquareUpperTail(double x, int dof);

// The density of a chi-square with `dof` degrees of freedom (need not be
// whole) at x >= 0.
double ChiSquareDensity(double x, double dof);

// The standard normal quantile: P(Z <= z) = p (bisection of erfc).
double NormalQuantile(double p);

// The chi-square quantile: P(X <= x) = p for X with `dof` degrees of
// freedom (need not be whole: an equivalent dof).
double ChiSquareQuantile(double p, double dof);

// P(X > f) for X ~ F(d1, d2) (regularised incomplete beta function,
// continued fraction). The degrees of freedom need not be whole (a prior's
// weight is one).
double FUpperTail(double f, double d1, double d2);

// Median of the values (copy taken).
double Median(std::vector<double> values);

// Root mean square and largest absolute value.
double Rms(const std::vector<double>& values);
double MaxAbs(const std::vector<double>& values);

}  // namespace internal

}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_STATISTICS_H_
