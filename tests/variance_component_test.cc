// The REML variance component (src/estimation/variance_component.h) on
// linear-Gaussian data: r = (I - H) y with y = J beta + e, e_k ~ N(0,
// sigma_k^2 + s^2), so the truth of s^2 is known.
#include "estimation/variance_component.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <Eigen/QR>
#include <cmath>
#include <cstdio>
#include <random>

#include "util/statistics.h"

namespace gravcal {
namespace {

struct Draw {
  Eigen::VectorXd residuals, sigmas;
  Eigen::MatrixXd jacobian;
  // Residual sum of squares of the unweighted fit (equal sigmas only).
  double rss = 0.0;
  // The white-weighted estimate (the truth is 0).
  Eigen::VectorXd beta;
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
  draw.beta = beta;
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

// error / sigma of the fitted parameters when s^2 is estimated and added to
// every variance. With equal sigmas (1) the refit with 1 + s^2 gives the same
// beta as the white fit (MakeDraw's, truth 0) and the covariance
// f (1 + s^2) (J^T J)^-1, f the Student inflation (1 for `plain`). Returns the
// rms of beta_j / sigma_j over every parameter and seed.
// A prior with dof > 0 is drawn per seed as an estimate of s2 from that many
// degrees of freedom (s2 chi2_dof / dof), which is what its dof claim.
double RmsZ(int n, int p, double s2, const internal::VariancePrior& given, bool inflate) {
  double sum = 0.0;
  int count = 0;
  std::mt19937 rng(77);
  for (int seed = 0; seed < 2000; ++seed) {
    const Draw d = MakeDraw(n, p, s2, 1.0, 1.0, 20000 + seed);
    internal::VariancePrior prior = given;
    if (prior.dof > 0.0) {
      std::chi_squared_distribution<double> chi2(prior.dof);
      prior.variance = s2 * chi2(rng) / prior.dof;
    }
    VarianceComponent vc;
    EXPECT_TRUE(internal::EstimateVarianceComponent(d.residuals, d.sigmas, d.jacobian, &vc, prior));
    const double f = inflate ? internal::StudentInflation(vc, 1.0, nullptr) : 1.0;
    const Eigen::MatrixXd cov =
        f * (1.0 + vc.variance) * (d.jacobian.transpose() * d.jacobian).inverse();
    for (int j = 0; j < p; ++j) {
      sum += d.beta(j) * d.beta(j) / cov(j, j);
      ++count;
    }
  }
  return std::sqrt(sum / count);
}

// Twelve residuals and eight parameters (m = 4), the excess 25 times the
// white variance: error / sigma is Student t with about 4 dof, rms sqrt(2)
// = 1.41 with the estimated s^2 alone; the inflation nu / (nu - 2) brings it
// to 1 (2000 seeds x 8 parameters, correlated within a seed: +-0.05).
TEST(VarianceComponent, StudentInflationMakesErrorOverSigmaUnitVariance) {
  const double plain = RmsZ(12, 8, 25.0, internal::VariancePrior(), false);
  const double inflated = RmsZ(12, 8, 25.0, internal::VariancePrior(), true);
  std::printf("m = 4: rms error/sigma %.3f without, %.3f with the inflation\n", plain, inflated);
  EXPECT_GT(plain, 1.25);
  EXPECT_NEAR(inflated, 1.0, 0.1);
}

// Ten residuals and nine parameters (m = 1, as ten_position): the
// likelihood alone cannot size s^2; a prior that is itself an estimate on 4
// dof can, and the inflation then counts 1 + 4 dof. (A prior exactly at the
// truth is worth more than its dof: rms 0.81 here, conservative.)
TEST(VarianceComponent, PriorSizesTheExcessWithOneDegreeOfFreedom) {
  internal::VariancePrior prior;
  prior.variance = 25.0;
  prior.dof = 4.0;
  const double inflated = RmsZ(10, 9, 25.0, prior, true);
  std::printf("m = 1 with a prior on 4 dof: rms error/sigma %.3f\n", inflated);
  EXPECT_NEAR(inflated, 1.0, 0.15);
  internal::VariancePrior bad;
  bad.dof = 2.0;
  VarianceComponent vc;
  const Draw d = MakeDraw(10, 9, 1.0, 1.0, 1.0, 1);
  EXPECT_FALSE(internal::EstimateVarianceComponent(d.residuals, d.sigmas, d.jacobian, &vc, bad))
      << "a prior with dof but no variance must be refused";
}

TEST(VarianceComponent, RejectsNoDegreesOfFreedom) {
  const Draw d = MakeDraw(6, 6, 1.0, 1.0, 1.0, 1);
  VarianceComponent vc;
  EXPECT_FALSE(internal::EstimateVarianceComponent(d.residuals, d.sigmas, d.jacobian, &vc));
  EXPECT_FALSE(vc.estimated);
}

}  // namespace
}  // namespace gravcal

namespace gravcal {
namespace {

// The whitened form with a diagonal shape is the diagonal form: residuals
// r_k / sigma_k, Jacobian rows / sigma_k and shape diag(1 / sigma_k^2) give
// the same s^2 and standard deviation. Rows the extra variance does not
// enter (shape zero, as for priors) are not counted, and leave s^2 alone
// when their residual is made huge.
TEST(VarianceComponent, WhitenedFormAgreesAndIgnoresRowsOutsideTheShape) {
  const Draw d = MakeDraw(30, 4, 2.0, 0.5, 1.5, 7);
  VarianceComponent diagonal, whitened;
  ASSERT_TRUE(internal::EstimateVarianceComponent(d.residuals, d.sigmas, d.jacobian, &diagonal));
  const Eigen::VectorXd w = d.sigmas.cwiseInverse();
  const Eigen::MatrixXd shape = w.array().square().matrix().asDiagonal();
  ASSERT_TRUE(internal::EstimateWhitenedVarianceComponent(
      w.asDiagonal() * d.residuals, w.asDiagonal() * d.jacobian, shape, &whitened));
  EXPECT_GT(diagonal.variance, 0.0);
  EXPECT_NEAR(whitened.variance, diagonal.variance, 1e-6 * diagonal.variance);
  EXPECT_NEAR(whitened.variance_std, diagonal.variance_std, 1e-6 * diagonal.variance_std);
  EXPECT_EQ(whitened.dof, diagonal.dof);

  // Two more rows, each the only row of a parameter of its own (as a prior
  // on an attitude): they leave no free direction, so any residual there
  // changes nothing.
  const int n = 32, p = 6;
  Eigen::VectorXd r = Eigen::VectorXd::Zero(n);
  r.head(30) = w.asDiagonal() * d.residuals;
  r(30) = 1e3;
  r(31) = -1e3;
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(n, p);
  j.topLeftCorner(30, 4) = w.asDiagonal() * d.jacobian;
  j(30, 4) = 1.0;
  j(31, 5) = 1.0;
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(n, n);
  s.topLeftCorner(30, 30) = shape;
  VarianceComponent with_priors;
  ASSERT_TRUE(internal::EstimateWhitenedVarianceComponent(r, j, s, &with_priors));
  EXPECT_NEAR(with_priors.variance, diagonal.variance, 1e-6 * diagonal.variance);
  EXPECT_EQ(with_priors.dof, diagonal.dof);
}

}  // namespace
}  // namespace gravcal

namespace gravcal {
namespace {

// The prior predictive tail of chi2 (variance_component.h): where the
// scatter dominates the white noise it is the F(dof, nu0) tail of the
// ratio, and where it does not it is still exact: chi2 drawn as its
// derivation says (s^2 from the prior, chi2 = (1 + s^2 h) chi2(dof)) falls
// below 0.05 in 5 % of 4000 draws (binomial sd 14, band 3 sd), for a
// scatter half the white variance, where the plain F ratio is off.
TEST(VarianceComponent, PriorPredictiveTailIsFWhereScatterDominatesAndExactElsewhere) {
  internal::VariancePrior prior;
  prior.variance = 1.0;
  prior.dof = 11.0;
  const double h = 1e6;
  for (double ratio : {0.3, 1.0, 2.5, 6.0}) {
    const double chi2 = ratio * 4.0 * (1.0 + h);
    EXPECT_NEAR(internal::PriorPredictiveUpperTail(chi2, 4, prior, h),
                internal::FUpperTail(ratio, 4.0, 11.0), 1e-4)
        << ratio;
  }
  std::mt19937 rng(11);
  std::chi_squared_distribution<double> x(prior.dof), y(3.0);
  const double half = 0.5;  // s0^2 h
  int low = 0, high = 0;
  const int draws = 4000;
  for (int i = 0; i < draws; ++i) {
    const double s2h = prior.dof * half / x(rng);
    const double chi2 = (1.0 + s2h) * y(rng);
    const double tail = internal::PriorPredictiveUpperTail(chi2, 3, prior, half);
    if (tail < 0.05) ++high;
    if (tail > 0.95) ++low;
  }
  std::printf("prior predictive tails below 0.05: %d, above 0.95: %d of %d\n", high, low, draws);
  EXPECT_NEAR(high, 200, 42);
  EXPECT_NEAR(low, 200, 42);
  internal::VariancePrior none;
  EXPECT_EQ(internal::PriorPredictiveUpperTail(10.0, 3, none, half), 1.0);
}

}  // namespace
}  // namespace gravcal
