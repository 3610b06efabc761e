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
std::vector<Position> Session(const AccelModel& truth, int copies, double disturbance,
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
    const std::vector<Position> positions = Session(truth, 2, kDisturbance, &rng);
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
    const std::vector<Position> positions = Session(truth, 1, 0.0, &rng);
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
  const std::vector<Position> positions = Session(truth, 1, 0.0, &rng);
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

}  // namespace
}  // namespace gravcal
