// Issue 14: the per-pose variance of the twelve-position fit
// (src/methods/pose_variance.h). Positions are drawn with white noise of the
// mean plus a per-pose disturbance of the specific force (placement, mount
// flex, tremor between poses) that the samples cannot show, sized so the
// white-noise fit's chi2 / dof is about 5 as on the real recordings.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "gravcal/methods/twelve_position.h"
#include "sigma_check.h"
#include "test_util.h"

namespace gravcal {
namespace {

using testing_util::FreeParameters;
using testing_util::SigmaCheck;

constexpr double kGravity = 9.80665;
constexpr double kNoise = 0.02;          // m/s^2 per sample
constexpr int kSamples = 1000;           // sigma of the mean 6.3e-4 m/s^2
constexpr double kDisturbance = 1.3e-3;  // m/s^2 per axis: chi2 / dof ~ 1 + (1.3 / 0.63)^2 = 5

AccelModel RandomScaleSensor(std::mt19937_64* rng, double misalignment) {
  std::normal_distribution<double> n(0.0, 1.0);
  AccelModel m;
  m.bias = Eigen::Vector3d(0.1 * n(*rng), 0.1 * n(*rng), 0.1 * n(*rng));
  m.upper = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 3; ++i) m.upper(i, i) = 1.0 + 0.01 * n(*rng);
  m.upper(0, 1) = misalignment;
  m.upper(0, 2) = -misalignment;
  m.upper(1, 2) = misalignment;
  return m;
}

// `copies` times the twelve directions, each pose disturbed by `disturbance`.
std::vector<Position> PoseSession(const AccelModel& truth, int copies, double disturbance,
                                  std::mt19937_64* rng) {
  std::vector<Eigen::Vector3d> directions;
  for (int i = 0; i < copies; ++i) {
    for (const Eigen::Vector3d& d : testing_util::TwelveDirections()) directions.push_back(d);
  }
  std::vector<Position> positions = testing_util::MakePositions(
      truth, directions, kGravity, 2.0 * M_PI / 180.0, kNoise, kSamples, true, rng);
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Matrix3d minv = truth.matrix().inverse();
  for (Position& p : positions) {
    p.raw_mean += minv * Eigen::Vector3d(n(*rng), n(*rng), n(*rng)) * disturbance;
  }
  return positions;
}

CalibrationOptions ScaleOptions(bool pose_variance) {
  CalibrationOptions o;
  o.gravity.gravity = kGravity;
  o.refinement.parameterization = AccelParameterization::kScale;
  o.refinement.estimate_pose_variance = pose_variance;
  return o;
}

void AddErrors(const Calibration& c, const AccelModel& truth, const std::string& prefix,
               SigmaCheck* check) {
  const Eigen::VectorXd e = FreeParameters(c.accel.model, AccelParameterization::kScale) -
                            FreeParameters(truth, AccelParameterization::kScale);
  for (int i = 0; i < e.size(); ++i) {
    check->Add(prefix + c.refinement.parameter_names[i], e(i),
               std::sqrt(c.refinement.covariance(i, i)));
  }
}

// Over 1000 seeds of 24 disturbed poses (18 dof): with the variance component
// every parameter's error / sigma has rms in the SigmaCheck band (and in
// [0.8, 1.25]); the white-noise sigmas on the same sessions are printed for
// contrast and are about sqrt(5) too small.
TEST(PoseVariance, HonestSigmasWithPerPoseDisturbances) {
  SigmaCheck with, white;
  double chi2_per_dof = 0.0, s_sum = 0.0;
  int not_absorbed = 0;
  const int seeds = 1000;
  for (int seed = 0; seed < seeds; ++seed) {
    std::mt19937_64 rng(7000 + seed);
    const AccelModel truth = RandomScaleSensor(&rng, 0.0);
    const std::vector<Position> positions = PoseSession(truth, 2, kDisturbance, &rng);
    Calibration c, w;
    ASSERT_TRUE(CalibrateFromPositions(positions, ScaleOptions(true), &c)) << c.message;
    ASSERT_TRUE(CalibrateFromPositions(positions, ScaleOptions(false), &w)) << w.message;
    AddErrors(c, truth, "", &with);
    AddErrors(w, truth, "", &white);
    chi2_per_dof += w.refinement.chi2 / w.refinement.dof / seeds;
    s_sum += std::sqrt(c.accel.pose_variance.variance) / seeds;
    // The structure test at level 1e-3 may claim the excess for a seed or
    // two in 1000 (its false-alarm rate); those keep the white sigmas.
    if (!c.accel.pose_variance.absorbed && !c.accel.pose_variance.at_boundary) ++not_absorbed;
  }
  std::printf("white-noise fit chi2/dof %.2f, mean s %.2e (true %.2e)\n", chi2_per_dof, s_sum,
              kDisturbance);
  std::printf("with the variance component:\n%swhite-noise sigmas:\n%s", with.Table().c_str(),
              white.Table().c_str());
  EXPECT_LT(not_absorbed, 10);
  EXPECT_GT(chi2_per_dof, 3.0);
  EXPECT_LT(chi2_per_dof, 7.0);
  // Not SigmaCheck::ExpectHonest: its band assumes exact sigmas, while s^2
  // is itself estimated from 18 dof. Before the Student inflation
  // (variance_component.h) that made error / sigma heavier-tailed than
  // N(0, 1), rms 1.03-1.09 over 1000 seeds; with it 0.97-1.03. The issue's
  // band [0.8, 1.25] is asserted.
  for (const std::string& name : with.Names()) {
    EXPECT_GT(with.Rms(name), 0.8) << name;
    EXPECT_LT(with.Rms(name), 1.25) << name;
    EXPECT_GT(white.Rms(name), 1.6) << name << ": the white sigmas should be too small here";
  }
}

// Without disturbances the component sits at the boundary for most seeds and
// the standard deviations are the white-noise ones.
TEST(PoseVariance, WhiteNoiseSessionsAreMostlyUnchanged) {
  int boundary = 0;
  for (int seed = 0; seed < 50; ++seed) {
    std::mt19937_64 rng(9000 + seed);
    const AccelModel truth = RandomScaleSensor(&rng, 0.0);
    const std::vector<Position> positions = PoseSession(truth, 1, 0.0, &rng);
    Calibration c;
    ASSERT_TRUE(CalibrateFromPositions(positions, ScaleOptions(true), &c)) << c.message;
    if (c.accel.pose_variance.at_boundary) ++boundary;
  }
  EXPECT_GT(boundary, 20);
}

// A sensor with non-orthogonality calibrated with the scale model: the
// excess is the missing term's, so it still warns, names the term and
// points to discover, and does not report inflated sigmas.
TEST(PoseVariance, NonOrthogonalityIsNotAbsorbedAsNoise) {
  std::mt19937_64 rng(42);
  const AccelModel truth = RandomScaleSensor(&rng, 0.003);
  const std::vector<Position> positions = PoseSession(truth, 1, 0.0, &rng);
  Calibration c, w;
  ASSERT_TRUE(CalibrateFromPositions(positions, ScaleOptions(true), &c)) << c.message;
  ASSERT_TRUE(CalibrateFromPositions(positions, ScaleOptions(false), &w)) << w.message;
  EXPECT_TRUE(c.accel.pose_variance.estimated);
  EXPECT_FALSE(c.accel.pose_variance.absorbed);
  bool names_term = false, chi2_warning = false;
  for (const std::string& s : c.warnings) {
    if (s.find("non-orthogonality") != std::string::npos &&
        s.find("gravcal discover") != std::string::npos) {
      names_term = true;
    }
    if (s.find("times the noise level") != std::string::npos) chi2_warning = true;
  }
  EXPECT_TRUE(names_term);
  EXPECT_TRUE(chi2_warning);
  for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(c.accel.bias_std(i), w.accel.bias_std(i));
}

bool NamesNonOrthogonality(const Calibration& c) {
  for (const std::string& s : c.warnings) {
    if (s.find("non-orthogonality") != std::string::npos &&
        s.find("gravcal discover") != std::string::npos) {
      return true;
    }
  }
  return false;
}

// The prior read as what it claims: an independent estimate of s^2 on
// `dof` degrees of freedom, s^2 chi2(dof) / dof (methods/pose_variance.h).
void DrawPrior(double s, double dof, std::mt19937_64* rng, CalibrationOptions* o) {
  std::chi_squared_distribution<double> chi2(dof);
  o->refinement.pose_disturbance_prior = s * std::sqrt(chi2(*rng) / dof);
  o->refinement.pose_disturbance_prior_dof = dof;
}

// The structure test with the prior pooled into its denominator is
// F(3, dof_rich + nu0) when the prior is the truth: on twelve disturbed
// poses (dof_rich = 3) of a sensor without non-orthogonality, with a prior
// on 11 dof drawn as above, it names the term in about structure_test_level
// of the seeds. Tested at level 0.05 (at 1e-3 a rate needs 10^5 seeds):
// 2000 seeds, expected 100, binomial sd 9.7; the band is 3 sd each side.
// The prior's white part is a constant where the F assumes it random, which
// makes the test slightly conservative (header), hence a rate a little
// below 0.05 is expected: measured 78 of 2000.
TEST(PoseVariance, PooledStructureTestHoldsItsLevelWhenThePriorIsTrue) {
  const int seeds = 2000;
  int named = 0, set_aside = 0;
  for (int seed = 0; seed < seeds; ++seed) {
    std::mt19937_64 rng(30000 + seed);
    const AccelModel truth = RandomScaleSensor(&rng, 0.0);
    const std::vector<Position> positions = PoseSession(truth, 1, kDisturbance, &rng);
    CalibrationOptions o = ScaleOptions(true);
    o.refinement.structure_test_level = 0.05;
    DrawPrior(kDisturbance, 11.0, &rng, &o);
    Calibration c;
    ASSERT_TRUE(CalibrateFromPositions(positions, o, &c)) << c.message;
    if (NamesNonOrthogonality(c)) ++named;
    if (c.accel.pose_variance.prior_set_aside) ++set_aside;
  }
  std::printf("false alarms at level 0.05: %d of %d (prior set aside in %d)\n", named, seeds,
              set_aside);
  EXPECT_GT(named, 100 - 29);
  EXPECT_LT(named, 100 + 29);
  // The upper tail at 0.01, the lower at 1e-4: about 1 % of the seeds.
  EXPECT_LT(set_aside, 50);
}

// The prior is what gives the test power with few poses: twelve disturbed
// poses of a sensor with non-orthogonality 0.002 (the size that makes the
// `scale` fit's chi2 / dof about 3 on the real AHRS unit), prior at the
// truth on 11 dof, default level 1e-3. Without the prior the test rests on
// dof_rich = 3 and rarely reaches the level; with it, most seeds name the
// term and keep the white sigmas instead of absorbing the excess.
TEST(PoseVariance, PriorGivesTheStructureTestPowerWithTwelvePoses) {
  const int seeds = 200;
  int with_prior = 0, without = 0;
  for (int seed = 0; seed < seeds; ++seed) {
    std::mt19937_64 rng(40000 + seed);
    const AccelModel truth = RandomScaleSensor(&rng, 0.002);
    const std::vector<Position> positions = PoseSession(truth, 1, kDisturbance, &rng);
    CalibrationOptions o = ScaleOptions(true);
    Calibration plain, pooled;
    ASSERT_TRUE(CalibrateFromPositions(positions, o, &plain)) << plain.message;
    DrawPrior(kDisturbance, 11.0, &rng, &o);
    ASSERT_TRUE(CalibrateFromPositions(positions, o, &pooled)) << pooled.message;
    if (NamesNonOrthogonality(plain)) ++without;
    if (NamesNonOrthogonality(pooled)) {
      ++with_prior;
      EXPECT_FALSE(pooled.accel.pose_variance.absorbed);
    }
  }
  std::printf("non-orthogonality named: %d of %d without the prior, %d with it\n", without, seeds,
              with_prior);
  EXPECT_GT(with_prior, seeds / 2);
  EXPECT_GT(with_prior, 2 * without);
}

// A prior ten times too large or too small (in s) must not size the
// sigmas: 24 disturbed poses (18 residual dof) show the conflict, the prior
// is set aside with a kPoseScatter warning, and error / sigma keeps rms in
// [0.8, 1.25]. The same sessions with the check switched off (level 1e-300)
// are printed for contrast: the prior then pulls s^2 towards itself.
TEST(PoseVariance, WrongPriorIsSetAside) {
  for (double factor : {10.0, 0.1}) {
    SigmaCheck checked, unchecked;
    int set_aside = 0;
    const int seeds = 300;
    for (int seed = 0; seed < seeds; ++seed) {
      std::mt19937_64 rng(50000 + seed);
      const AccelModel truth = RandomScaleSensor(&rng, 0.0);
      const std::vector<Position> positions = PoseSession(truth, 2, kDisturbance, &rng);
      CalibrationOptions o = ScaleOptions(true);
      o.refinement.pose_disturbance_prior = factor * kDisturbance;
      o.refinement.pose_disturbance_prior_dof = 11.0;
      Calibration c, off;
      ASSERT_TRUE(CalibrateFromPositions(positions, o, &c)) << c.message;
      o.refinement.prior_conflict_level = 1e-300;
      ASSERT_TRUE(CalibrateFromPositions(positions, o, &off)) << off.message;
      AddErrors(c, truth, "", &checked);
      AddErrors(off, truth, "", &unchecked);
      if (!c.accel.pose_variance.prior_set_aside) continue;
      ++set_aside;
      bool warned = false;
      for (size_t i = 0; i < c.warnings.size(); ++i) {
        warned |= c.warning_codes[i] == WarningCode::kPoseScatter &&
                  c.warnings[i].find("prior is set aside") != std::string::npos;
      }
      EXPECT_TRUE(warned) << "seed " << seed;
    }
    std::printf("prior %.1f x the truth: set aside in %d of %d\nchecked:\n%sunchecked:\n%s", factor,
                set_aside, seeds, checked.Table().c_str(), unchecked.Table().c_str());
    EXPECT_GT(set_aside, seeds * 9 / 10) << factor;
    for (const std::string& name : checked.Names()) {
      EXPECT_GT(checked.Rms(name), 0.8) << name << " prior x " << factor;
      EXPECT_LT(checked.Rms(name), 1.25) << name << " prior x " << factor;
    }
  }
}

}  // namespace
}  // namespace gravcal
