#include "gravcal/estimation/coarse_fit.h"

#include <gtest/gtest.h>

#include "test_util.h"

namespace gravcal {
namespace {

using testing_util::kCountScale;
using testing_util::MakePositions;
using testing_util::TwelveDirections;

std::vector<Eigen::Vector3d> SixDirections() {
  auto d = TwelveDirections();
  d.resize(6);
  return d;
}

TEST(CoarseFit, SixPositionExactWithPerfectPlacement) {
  std::mt19937_64 rng(1);
  const AccelModel truth =
      AccelModel::Random(AccelParameterization::kAffine, kCountScale, 0.02, 0.01, 400, &rng);
  const auto positions =
      MakePositions(truth, SixDirections(), kStandardGravity, 0.0, 0.0, 100, true, &rng);
  std::vector<int> up;
  for (const Position& p : positions) up.push_back(p.nominal_up);
  Eigen::Vector3d b;
  Eigen::Matrix3d m;
  std::string error;
  ASSERT_TRUE(SixPositionFit(positions, up, kStandardGravity, &b, &m, &error)) << error;
  EXPECT_LT((b - truth.bias).norm(), 1e-6);
  EXPECT_LT((m - truth.matrix()).norm() / truth.matrix().norm(), 1e-10);
}

TEST(CoarseFit, EllipsoidExactOnNoiseFreeArbitraryPoses) {
  std::mt19937_64 rng(2);
  const AccelModel truth = AccelModel::Random(AccelParameterization::kScaleMisalignment,
                                              kCountScale, 0.02, 0.01, 400, &rng);
  std::vector<Eigen::Vector3d> directions;
  for (int k = 0; k < 15; ++k) directions.push_back(testing_util::RandomDirection(&rng));
  const auto positions =
      MakePositions(truth, directions, kStandardGravity, 0.0, 0.0, 100, false, &rng);
  AccelModel fit;
  std::string error;
  ASSERT_TRUE(EllipsoidFit(positions, false, kStandardGravity, &fit, &error)) << error;
  EXPECT_LT((fit.bias - truth.bias).norm(), 1e-6 * truth.bias.norm() + 1e-6);
  EXPECT_LT((fit.upper - truth.upper).norm() / truth.upper.norm(), 1e-9);
}

TEST(CoarseFit, DiagonalEllipsoidNeedsSixPositions) {
  std::mt19937_64 rng(3);
  const AccelModel truth =
      AccelModel::Random(AccelParameterization::kScale, 1.0, 0.02, 0.0, 0.3, &rng);
  std::vector<Eigen::Vector3d> directions;
  for (int k = 0; k < 8; ++k) directions.push_back(testing_util::RandomDirection(&rng));
  auto positions = MakePositions(truth, directions, kStandardGravity, 0.0, 0.0, 100, false, &rng);
  AccelModel fit;
  std::string error;
  ASSERT_TRUE(EllipsoidFit(positions, true, kStandardGravity, &fit, &error)) << error;
  EXPECT_LT((fit.upper - truth.upper).norm(), 1e-9);
  EXPECT_LT((fit.bias - truth.bias).norm(), 1e-9);
  positions.resize(5);
  EXPECT_FALSE(EllipsoidFit(positions, true, kStandardGravity, &fit, &error));
  EXPECT_NE(error.find("at least 6 positions, found 5"), std::string::npos) << error;
}

TEST(CoarseFit, AssignsNominalAxesInAnyUnits) {
  for (double scale : {kCountScale, 1.0}) {
    std::mt19937_64 rng(4);
    const AccelModel truth =
        AccelModel::Random(AccelParameterization::kAffine, scale, 0.02, 0.01, 0.3 / scale, &rng);
    const auto positions = MakePositions(truth, TwelveDirections(), kStandardGravity,
                                         3.0 * M_PI / 180.0, 0.02, 500, false, &rng);
    std::vector<int> up;
    AssignNominalAxes(positions, nullptr, 20.0, &up);
    for (int k = 0; k < 6; ++k) EXPECT_EQ(up[k], k) << "scale " << scale;
    for (int k = 6; k < 12; ++k) EXPECT_EQ(up[k], -1) << "scale " << scale;
  }
}

TEST(CoarseFit, ChoosesSixPositionWhenAllFacesPresentElseEllipsoid) {
  std::mt19937_64 rng(5);
  const AccelModel truth =
      AccelModel::Random(AccelParameterization::kAffine, kCountScale, 0.02, 0.01, 400, &rng);
  const auto twelve =
      MakePositions(truth, TwelveDirections(), kStandardGravity, 0.02, 0.02, 500, false, &rng);
  CoarseFitResult result;
  ASSERT_TRUE(CoarseFit(twelve, kStandardGravity, AccelParameterization::kScaleMisalignment,
                        CoarseFitOptions(), &result))
      << result.message;
  EXPECT_EQ(result.method, CoarseMethod::kSixPosition);
  EXPECT_EQ(result.axis_positions, 6);
  std::vector<Eigen::Vector3d> directions;
  for (int k = 0; k < 12; ++k) directions.push_back(testing_util::RandomDirection(&rng));
  const auto random =
      MakePositions(truth, directions, kStandardGravity, 0.0, 0.02, 500, false, &rng);
  ASSERT_TRUE(CoarseFit(random, kStandardGravity, AccelParameterization::kScaleMisalignment,
                        CoarseFitOptions(), &result))
      << result.message;
  EXPECT_EQ(result.method, CoarseMethod::kEllipsoid);
  // A useful start: scale within 1 %.
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(result.model.upper(i, i) / truth.upper(i, i), 1.0, 0.01);
  }
}

TEST(CoarseFit, TooFewPositionsIsAnError) {
  std::mt19937_64 rng(6);
  const AccelModel truth =
      AccelModel::Random(AccelParameterization::kAffine, kCountScale, 0.02, 0.01, 400, &rng);
  auto positions =
      MakePositions(truth, TwelveDirections(), kStandardGravity, 0.0, 0.02, 500, false, &rng);
  positions.resize(3);
  CoarseFitResult result;
  EXPECT_FALSE(CoarseFit(positions, kStandardGravity, AccelParameterization::kScaleMisalignment,
                         CoarseFitOptions(), &result));
  EXPECT_FALSE(result.message.empty());
  CoarseFitOptions bad;
  bad.axis_tolerance_deg = 50;
  EXPECT_FALSE(CoarseFit(positions, kStandardGravity, AccelParameterization::kScale, bad, &result));
  EXPECT_NE(result.message.find("axis_tolerance_deg"), std::string::npos);
}

}  // namespace
}  // namespace gravcal
