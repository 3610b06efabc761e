#include "gravcal/estimation/refinement.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <cstdio>

#include "estimation/newton_solver.h"
#include "gravcal/core/calibration.h"
#include "gravcal/estimation/coarse_fit.h"
#include "gravcal/estimation/observability.h"
#include "gravcal/residuals/gravity_magnitude_residual.h"
#include "sigma_check.h"
#include "test_util.h"

namespace gravcal {
namespace {

using internal::NewtonOptions;
using internal::NewtonRefine;
using testing_util::FreeParameters;

using testing_util::kCountScale;
using testing_util::MakePositions;
using testing_util::TwelveDirections;

constexpr double kTilt = 2.0 * M_PI / 180.0;

AccelModel Truth(std::mt19937_64* rng, double scale = kCountScale) {
  return AccelModel::Random(AccelParameterization::kAffine, scale, 0.02, 0.01, 0.3 / scale, rng);
}

AccelModel Coarse(const std::vector<Position>& positions, AccelParameterization p) {
  CoarseFitResult coarse;
  EXPECT_TRUE(CoarseFit(positions, kStandardGravity, p, CoarseFitOptions(), &coarse))
      << coarse.message;
  return coarse.model;
}

TEST(Refinement, AnalyticJacobianMatchesAutodiffResidual) {
  std::mt19937_64 rng(11);
  const AccelModel truth = Truth(&rng);
  const auto positions =
      MakePositions(truth, TwelveDirections(), kStandardGravity, kTilt, 0.02, 1000, false, &rng);
  AccelModel at = truth;
  at.bias += Eigen::Vector3d(5, -3, 2);
  const std::vector<double> sigmas = MagnitudeSigmas(positions, at);
  const Eigen::MatrixXd analytic = MagnitudeJacobian(positions, at, sigmas);
  double bias[3] = {at.bias(0), at.bias(1), at.bias(2)};
  double upper[6];
  at.GetUpper(upper);
  for (size_t k = 0; k < positions.size(); ++k) {
    std::unique_ptr<ceres::CostFunction> cost(
        GravityMagnitudeResidual::Create(positions[k].raw_mean, kStandardGravity, sigmas[k]));
    double residual;
    double jb[3], ju[6];
    double* jacobians[2] = {jb, ju};
    const double* params[2] = {bias, upper};
    ASSERT_TRUE(cost->Evaluate(params, &residual, jacobians));
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(jb[i], analytic(k, i), 1e-9 * std::fabs(analytic(k, i)) + 1e-12);
    for (int i = 0; i < 6; ++i)
      EXPECT_NEAR(ju[i], analytic(k, 3 + i), 1e-9 * std::fabs(analytic(k, 3 + i)) + 1e-12);
    // And a central difference on the bias.
    const double h = 1e-3;
    double bp[3] = {bias[0] + h, bias[1], bias[2]};
    double bm[3] = {bias[0] - h, bias[1], bias[2]};
    double rp, rm;
    const double* pp[2] = {bp, upper};
    const double* pm[2] = {bm, upper};
    cost->Evaluate(pp, &rp, nullptr);
    cost->Evaluate(pm, &rm, nullptr);
    EXPECT_NEAR((rp - rm) / (2 * h), analytic(k, 0), 1e-6 * std::fabs(analytic(k, 0)) + 1e-9);
  }
}

TEST(Refinement, TwelveColumnJacobianHasRankNine) {
  std::mt19937_64 rng(12);
  for (int trial = 0; trial < 5; ++trial) {
    const AccelModel truth = Truth(&rng);
    const auto positions =
        MakePositions(truth, TwelveDirections(), kStandardGravity, kTilt, 0.02, 1000, false, &rng);
    const std::vector<double> sigmas(positions.size(), 1.0);
    // At the truth and at a point away from it.
    for (double offset : {0.0, 20.0}) {
      const Eigen::MatrixXd j = FullMagnitudeJacobian(
          positions, truth.bias + Eigen::Vector3d::Constant(offset), truth.matrix(), sigmas);
      const ObservabilityReport report = AnalyzeObservability(j, FullMagnitudeParameterNames());
      EXPECT_EQ(report.columns, 12);
      EXPECT_EQ(report.rank, 9);
    }
    // The gauge-free 9-parameter Jacobian is full rank.
    const ObservabilityReport nine =
        AnalyzeObservability(MagnitudeJacobian(positions, truth, sigmas),
                             MagnitudeParameterNames(AccelParameterization::kScaleMisalignment));
    EXPECT_EQ(nine.rank, 9);
  }
}

// How far apart, in standard deviations, two solvers of the same cost may
// stop. In units of sigma the cost near its minimum C* is C* + |z|^2 / 2, and
// Ceres stops once a step lowers it by less than function_tolerance (1e-14)
// times C: it can stop up to |z| = sqrt(2 * 1e-14 * C*) from the optimum,
// 1.7e-7 for C* = dof / 2 = 1.5 (12 positions, 9 parameters); Newton's step
// tolerance (1e-12 relative, quadratic convergence) leaves far less. 1e-6
// is six times that bound, and a millionth of what the calibration reports
// as its uncertainty.
constexpr double kAgreement = 1e-6;

TEST(Refinement, CeresAndNewtonReachTheSameOptimum) {
  std::mt19937_64 rng(13);
  for (int trial = 0; trial < 10; ++trial) {
    const AccelModel truth = Truth(&rng);
    for (double noise : {0.0, 0.02}) {
      auto positions = MakePositions(truth, TwelveDirections(), kStandardGravity, kTilt, noise,
                                     1000, false, &rng);
      if (noise == 0.0) {
        // The sigmas must still be positive: give the clean positions a nominal covariance.
        for (Position& p : positions) p.raw_mean_cov = 1e-4 * Eigen::Matrix3d::Identity();
      }
      const AccelModel start = Coarse(positions, AccelParameterization::kScaleMisalignment);
      RefinementResult ceres_result, newton_result;
      ASSERT_TRUE(Refine(positions, start, kStandardGravity, RefinementOptions(), &ceres_result));
      NewtonOptions newton;
      newton.residual =
          noise == 0.0 ? NewtonResidual::kSquaredMagnitude : NewtonResidual::kMagnitude;
      ASSERT_TRUE(NewtonRefine(positions, start, kStandardGravity, newton, &newton_result));
      ASSERT_TRUE(ceres_result.converged) << ceres_result.message;
      ASSERT_TRUE(newton_result.converged) << newton_result.message;
      ASSERT_TRUE(ceres_result.covariance_available);
      const auto p = AccelParameterization::kScaleMisalignment;
      const Eigen::VectorXd a = FreeParameters(ceres_result.model, p);
      const Eigen::VectorXd b = FreeParameters(newton_result.model, p);
      // The two optima agree to kAgreement standard deviations of each
      // parameter (the refinement's own (J^T J)^-1 of the whitened
      // residuals), a scale set by the problem's conditioning rather than
      // by the parameter's value: a tolerance relative to |a_i| is
      // meaningless for a bias or an off-diagonal entry near zero, and
      // failed on such a draw (2e-7 apart).
      for (int i = 0; i < a.size(); ++i) {
        const double sigma = std::sqrt(ceres_result.covariance(i, i));
        EXPECT_LT(std::fabs(a(i) - b(i)), kAgreement * sigma)
            << "parameter " << i << " noise " << noise << " trial " << trial << ": "
            << std::fabs(a(i) - b(i)) / sigma << " sigma apart";
      }
      if (noise == 0.0) {
        EXPECT_LT((ceres_result.model.upper - truth.upper).norm() / truth.upper.norm(), 1e-9);
      }
    }
  }
}

// The reported standard deviations match the spread of the errors over many
// seeds: error / sigma inside SigmaCheck's band for every parameter.
void CheckCalibratedUncertainty(AccelParameterization p, double unit_scale) {
  const int kSeeds = 200;
  const int n = p == AccelParameterization::kScale ? 6 : 9;
  const std::vector<std::string> names = MagnitudeParameterNames(p);
  testing_util::SigmaCheck check;
  double coarse_err = 0.0, refined_err = 0.0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    std::mt19937_64 rng(1000 + seed);
    AccelModel truth =
        AccelModel::Random(p == AccelParameterization::kScale ? p : AccelParameterization::kAffine,
                           unit_scale, 0.02, 0.01, 0.3 / unit_scale, &rng);
    const auto positions =
        MakePositions(truth, TwelveDirections(), kStandardGravity, kTilt, 0.02, 1000, false, &rng);
    const AccelModel start = Coarse(positions, p);
    RefinementOptions options;
    options.parameterization = p;
    RefinementResult result;
    ASSERT_TRUE(Refine(positions, start, kStandardGravity, options, &result));
    ASSERT_TRUE(result.converged);
    ASSERT_TRUE(result.covariance_available);
    const Eigen::VectorXd err = FreeParameters(result.model, p) - FreeParameters(truth, p);
    for (int i = 0; i < n; ++i) check.Add(names[i], err(i), std::sqrt(result.covariance(i, i)));
    coarse_err += (start.upper - truth.upper).squaredNorm();
    refined_err += (result.model.upper - truth.upper).squaredNorm();
  }
  check.ExpectHonest("refinement");
  // With 2 degrees of placement error the magnitude fit beats the coarse fit.
  EXPECT_LT(refined_err, 0.1 * coarse_err);
}

TEST(Refinement, StandardDeviationMatchesSpreadScaleMisalignmentCounts) {
  CheckCalibratedUncertainty(AccelParameterization::kScaleMisalignment, kCountScale);
}

TEST(Refinement, StandardDeviationMatchesSpreadScaleSi) {
  CheckCalibratedUncertainty(AccelParameterization::kScale, 1.0);
}

// A trial succeeds when all nine parameters are within 3 sigma of the truth.
// Nine parameters each within 3 sigma fails by chance in about 2.4 % of
// correct fits; beyond that, a start corrupted by the pushes sometimes leads
// the graduated robust solve into a wrong basin. Measured on trials
// 100000-100999 (not the test's): the robust fit succeeds in 952 of 1000,
// plain least squares in 0 of 1000. The test states p = 0.93 for the robust
// fit (the one-sided 99.9 % lower confidence bound of 952 / 1000) and at
// most p = 0.005 for plain least squares (0 of 1000: the 99.5 % upper bound),
// and takes its thresholds from the binomial tails at those p.
TEST(Refinement, RobustLossResistsDisturbedPositions) {
  int robust_ok = 0, plain_ok = 0;
  const int kTrials = 100;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::mt19937_64 rng(300 + trial);
    const AccelModel truth = Truth(&rng);
    auto directions = TwelveDirections();
    for (int k = 0; k < 6; ++k) directions.push_back(testing_util::RandomDirection(&rng));
    auto positions =
        MakePositions(truth, directions, kStandardGravity, kTilt, 0.02, 1000, false, &rng);
    // An unmodelled 0.3 m/s^2 push on two of the eighteen positions, along
    // the specific force (a push across it barely changes the magnitude).
    // Neither is a position that alone pins a direction of the model (a
    // disturbed high-leverage position cannot be told from a good one by any
    // loss).
    for (int k : {8, 14}) {
      const Eigen::Vector3d f = truth.Apply(positions[k].raw_mean);
      const double sign = (k == 8) ? 1.0 : -1.0;
      positions[k].raw_mean = truth.Invert(f + sign * 0.3 * f.normalized());
    }
    const AccelModel start = Coarse(positions, AccelParameterization::kScaleMisalignment);
    for (LossType loss : {LossType::kNone, LossType::kCauchy}) {
      RefinementOptions options;
      options.loss = loss;
      RefinementResult result;
      ASSERT_TRUE(Refine(positions, start, kStandardGravity, options, &result));
      const Eigen::VectorXd err = FreeParameters(result.model, options.parameterization) -
                                  FreeParameters(truth, options.parameterization);
      bool within = result.covariance_available;
      for (int i = 0; i < err.size() && within; ++i) {
        within = std::fabs(err(i)) < 3.0 * std::sqrt(result.covariance(i, i));
      }
      (loss == LossType::kNone ? plain_ok : robust_ok) += within;
    }
  }
  std::printf("robust within 3 sigma in %d of %d, plain in %d\n", robust_ok, kTrials, plain_ok);
  EXPECT_GE(robust_ok, testing_util::RequiredSuccesses(kTrials, 0.93))  // 84
      << robust_ok << " of " << kTrials;
  EXPECT_LE(plain_ok, testing_util::AllowedSuccesses(kTrials, 0.005))  // 4
      << plain_ok << " of " << kTrials;
}

TEST(Refinement, RankDeficientPositionsWarnInsteadOfCrashing) {
  std::mt19937_64 rng(14);
  const AccelModel truth = Truth(&rng);
  // Every position has z horizontal: bias_z and the z column are not seen.
  std::vector<Eigen::Vector3d> directions;
  for (int k = 0; k < 12; ++k) {
    const double a = 2 * M_PI * k / 12;
    directions.emplace_back(std::cos(a), std::sin(a), 0.0);
  }
  const auto positions =
      MakePositions(truth, directions, kStandardGravity, 0.0, 0.02, 1000, false, &rng);
  RefinementResult result;
  ASSERT_TRUE(Refine(positions, truth, kStandardGravity, RefinementOptions(), &result));
  bool warned = false;
  for (const std::string& w : result.warnings)
    warned |= w.find("do not determine") != std::string::npos;
  EXPECT_TRUE(warned);
  bool names_bias_z = false;
  for (const std::string& name : result.observability.undetermined)
    names_bias_z |= name == "bias_z";
  EXPECT_TRUE(names_bias_z);
}

TEST(Refinement, InvalidOptionsAndTooFewPositions) {
  std::mt19937_64 rng(15);
  const AccelModel truth = Truth(&rng);
  auto positions =
      MakePositions(truth, TwelveDirections(), kStandardGravity, kTilt, 0.02, 1000, false, &rng);
  RefinementOptions options;
  options.loss_scale = -1;
  RefinementResult result;
  EXPECT_FALSE(Refine(positions, truth, kStandardGravity, options, &result));
  EXPECT_NE(result.message.find("loss_scale"), std::string::npos);
  positions.resize(8);
  EXPECT_FALSE(Refine(positions, truth, kStandardGravity, RefinementOptions(), &result));
  EXPECT_NE(result.message.find("at least 9"), std::string::npos) << result.message;
  EXPECT_NE(result.message.find("found 8"), std::string::npos) << result.message;
}

TEST(Refinement, LossNames) {
  for (const char* name : {"none", "huber", "cauchy", "soft_l1", "arctan", "tukey"}) {
    LossType loss;
    ASSERT_TRUE(FromString(name, &loss));
    EXPECT_STREQ(ToString(loss), name);
  }
  LossType loss;
  EXPECT_FALSE(FromString("l2", &loss));
}

}  // namespace
}  // namespace gravcal
