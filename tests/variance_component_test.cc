// The REML variance component (src/estimation/variance_component.h) on
// linear-Gaussian data: r = (I - H) y with y = J beta + e, e_k ~ N(0,
// sigma_k^2 + s^2), so the truth of s^2 is known.
#include "estimation/variance_component.h"

#include <gtest/gtest.h>

#include <Eigen/QR>
#include <cmath>
#include <cstdio>
#include <random>

namespace gravcal {
namespace {

struct Draw {
  Eigen::VectorXd residuals, sigmas;
  Eigen::MatrixXd jacobian;
  // Residual sum of squares of the unweighted fit (equal sigmas only).
  double rss = 0.0;
};

// n residuals of a p-parameter weighted least-squares fit; sigma_k drawn in
// [sigma_low, sigma_high].
Draw MakeDraw(int n, int p, double s2, double sigma_low, double sigma_high, int seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(sigma_low, sigma_high);
  Draw draw;
  draw.jacobian = Eigen::MatrixXd(n, p);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < p; ++j) draw.jacobian(i, j) = normal(rng) * (j + 1);
  }
  draw.sigmas = Eigen::VectorXd(n);
  Eigen::VectorXd y(n);
  for (int i = 0; i < n; ++i) {
    draw.sigmas(i) = uniform(rng);
    y(i) = std::sqrt(draw.sigmas(i) * draw.sigmas(i) + s2) * normal(rng);
  }
  // The fit weights by the white sigmas only (as the calibration does first).
  const Eigen::VectorXd w = draw.sigmas.cwiseInverse();
  const Eigen::MatrixXd jw = w.asDiagonal() * draw.jacobian;
  const Eigen::VectorXd beta = jw.colPivHouseholderQr().solve(w.asDiagonal() * y);
  draw.residuals = y - draw.jacobian * beta;
  draw.rss = draw.residuals.squaredNorm();
  return draw;
}

TEST(VarianceComponent, RemlIsUnbiasedWhereMlIsLowByPOverN) {
  const int n = 40, p = 10, seeds = 400;
  const double s2 = 4.0;  // sigma = 1: total variance 5
  double reml_sum = 0.0, ml_sum = 0.0;
  for (int seed = 0; seed < seeds; ++seed) {
    const Draw d = MakeDraw(n, p, s2, 1.0, 1.0, seed);
    VarianceComponent vc;
    ASSERT_TRUE(internal::EstimateVarianceComponent(d.residuals, d.sigmas, d.jacobian, &vc))
        << vc.message;
    EXPECT_EQ(vc.dof, n - p);
    reml_sum += vc.variance;
    // Plain ML with equal sigmas: the total variance is RSS / n.
    ml_sum += std::max(0.0, d.rss / n - 1.0);
  }
  const double reml_mean = reml_sum / seeds, ml_mean = ml_sum / seeds;
  // REML: std of one estimate sqrt(2 * 25 / 30) = 1.29, of the mean 0.065.
  EXPECT_NEAR(reml_mean, s2, 4.0 * 0.065) << "REML mean " << reml_mean;
  // ML: E = (n - p) / n * 5 - 1 = 2.75, low by p/n of the total variance.
  EXPECT_NEAR(ml_mean, (n - p) * 5.0 / n - 1.0, 4.0 * 0.065) << "ML mean " << ml_mean;
  EXPECT_LT(ml_mean, s2 - 1.0);
}

// The reported std(s^2) against the spread of s^2 over seeds. Not a z
// test: s^2 is a scaled chi-square (skewness sqrt(8 / m) = 0.4 here) and its
// std is evaluated at the estimate, so (estimate - truth) / std has a mean
// near -0.24 by construction while the std itself is right. The empirical
// std over N = 400 seeds has a relative standard error of about
// sqrt((kurtosis - 1) / 4N) = 0.04: the band is 3 of those.
TEST(VarianceComponent, SigmaMatchesTheSpreadWithUnequalSigmas) {
  const int n = 60, p = 9, seeds = 400;
  const double s2 = 2.0;
  double sum = 0.0, sum2 = 0.0, reported2 = 0.0;
  for (int seed = 0; seed < seeds; ++seed) {
    const Draw d = MakeDraw(n, p, s2, 0.5, 1.5, 1000 + seed);
    VarianceComponent vc;
    ASSERT_TRUE(internal::EstimateVarianceComponent(d.residuals, d.sigmas, d.jacobian, &vc));
    sum += vc.variance;
    sum2 += vc.variance * vc.variance;
    reported2 += vc.variance_std * vc.variance_std;
  }
  const double mean = sum / seeds;
  const double spread = std::sqrt(sum2 / seeds - mean * mean);
  const double reported = std::sqrt(reported2 / seeds);
  EXPECT_NEAR(mean, s2, 4.0 * spread / std::sqrt(seeds)) << "REML mean " << mean;
  EXPECT_NEAR(reported / spread, 1.0, 0.12)
      << "reported std " << reported << ", spread over seeds " << spread;
  std::printf("s2 = %.3f: mean %.3f, spread %.3f, reported std %.3f\n", s2, mean, spread, reported);
}

TEST(VarianceComponent, NoExcessGivesTheBoundaryMostOfTheTime) {
  int boundary = 0;
  for (int seed = 0; seed < 200; ++seed) {
    const Draw d = MakeDraw(12, 6, 0.0, 0.5, 1.5, 5000 + seed);
    VarianceComponent vc;
    ASSERT_TRUE(internal::EstimateVarianceComponent(d.residuals, d.sigmas, d.jacobian, &vc));
    EXPECT_GE(vc.variance, 0.0);
    if (vc.at_boundary) ++boundary;
  }
  // With no excess, d l_R / d s^2 at 0 is negative about half the time (more
  // with few dof): a positive s^2 for every seed would be a biased estimator.
  EXPECT_GT(boundary, 80);
}

TEST(VarianceComponent, RejectsNoDegreesOfFreedom) {
  const Draw d = MakeDraw(6, 6, 1.0, 1.0, 1.0, 1);
  VarianceComponent vc;
  EXPECT_FALSE(internal::EstimateVarianceComponent(d.residuals, d.sigmas, d.jacobian, &vc));
  EXPECT_FALSE(vc.estimated);
}

}  // namespace
}  // namespace gravcal
