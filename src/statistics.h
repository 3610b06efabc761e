// Private: small statistics helpers.
#ifndef GRAVCAL_SRC_STATISTICS_H_
#define GRAVCAL_SRC_STATISTICS_H_

#include <vector>

namespace gravcal {

// P(X > x) for X ~ chi-square with `dof` degrees of freedom (regularised
// upper incomplete gamma function, series / continued fraction).
double ChiSquareUpperTail(double x, int dof);

// Median of the values (copy taken).
double Median(std::vector<double> values);

// Root mean square and largest absolute value.
double Rms(const std::vector<double>& values);
double MaxAbs(const std::vector<double>& values);

}  // namespace gravcal

#endif  // GRAVCAL_SRC_STATISTICS_H_
