#include "gravcal/core/accel_model.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>

namespace gravcal {
namespace {

TEST(AccelModel, DefaultIsIdentity) {
  const AccelModel model;
  const Eigen::Vector3d v(1.0, -2.0, 3.0);
  EXPECT_EQ(model.Apply(v), v);
  EXPECT_EQ(model.matrix(), Eigen::Matrix3d::Identity());
}

TEST(AccelModel, ApplyInvertRoundTrip) {
  std::mt19937_64 rng(3);
  for (AccelParameterization p :
       {AccelParameterization::kScale, AccelParameterization::kScaleMisalignment,
        AccelParameterization::kAffine}) {
    const AccelModel model = AccelModel::Random(p, 9.80665 / 16384, 0.02, 0.01, 300, &rng);
    const Eigen::Vector3d f(3.0, -8.0, 4.5);
    EXPECT_LT((model.Apply(model.Invert(f)) - f).norm(), 1e-12) << ToString(p);
    EXPECT_EQ(model.upper(1, 0), 0.0);
    if (p == AccelParameterization::kScale) EXPECT_EQ(model.upper(0, 1), 0.0);
    if (p != AccelParameterization::kAffine) {
      EXPECT_EQ(model.rotation, Eigen::Matrix3d::Identity());
    }
  }
}

TEST(AccelModel, FromMatrixDecomposesIntoRotationAndUpper) {
  Eigen::Matrix3d m;
  m << 1.01, 0.02, -0.01, -0.015, 0.98, 0.03, 0.01, -0.02, 1.03;
  AccelModel model;
  ASSERT_TRUE(
      AccelModel::FromMatrix(Eigen::Vector3d(1, 2, 3), m, AccelParameterization::kAffine, &model));
  EXPECT_LT((model.matrix() - m).norm(), 1e-14);
  EXPECT_LT((model.rotation.transpose() * model.rotation - Eigen::Matrix3d::Identity()).norm(),
            1e-14);
  EXPECT_NEAR(model.rotation.determinant(), 1.0, 1e-14);
  EXPECT_GT(model.upper.diagonal().minCoeff(), 0.0);
  EXPECT_EQ(model.upper(1, 0), 0.0);
  EXPECT_EQ(model.upper(2, 0), 0.0);
  EXPECT_EQ(model.upper(2, 1), 0.0);
}

TEST(AccelModel, FromMatrixRejectsReflectionAndSingular) {
  AccelModel model;
  Eigen::Matrix3d reflection = Eigen::Matrix3d::Identity();
  reflection(2, 2) = -1.0;
  EXPECT_FALSE(AccelModel::FromMatrix(Eigen::Vector3d::Zero(), reflection,
                                      AccelParameterization::kAffine, &model));
  EXPECT_FALSE(AccelModel::FromMatrix(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero(),
                                      AccelParameterization::kAffine, &model));
}

TEST(AccelModel, UpperPacking) {
  AccelModel model;
  const double u[6] = {1, 2, 3, 4, 5, 6};
  model.SetUpper(u);
  double back[6];
  model.GetUpper(back);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(back[i], u[i]);
  EXPECT_EQ(model.upper(1, 2), 5.0);
  EXPECT_EQ(model.upper(2, 1), 0.0);
}

TEST(AccelModel, ParameterizationNames) {
  for (AccelParameterization p :
       {AccelParameterization::kScale, AccelParameterization::kScaleMisalignment,
        AccelParameterization::kAffine}) {
    AccelParameterization back;
    ASSERT_TRUE(FromString(ToString(p), &back));
    EXPECT_EQ(back, p);
  }
  AccelParameterization p;
  EXPECT_FALSE(FromString("full", &p));
  EXPECT_EQ(NumParameters(AccelParameterization::kScale), 6);
  EXPECT_EQ(NumParameters(AccelParameterization::kScaleMisalignment), 9);
  EXPECT_EQ(NumParameters(AccelParameterization::kAffine), 12);
}

}  // namespace
}  // namespace gravcal
