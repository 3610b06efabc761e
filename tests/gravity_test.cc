#include "gravcal/core/gravity.h"

#include <gtest/gtest.h>

namespace gravcal {
namespace {

TEST(Gravity, NormalGravityMatchesWgs84) {
  // WGS84 normal gravity on the ellipsoid at the equator and the poles.
  EXPECT_NEAR(NormalGravity(0.0, 0.0), 9.7803253359, 1e-9);
  EXPECT_NEAR(NormalGravity(90.0, 0.0), 9.8321849378, 1e-8);
  EXPECT_NEAR(NormalGravity(-90.0, 0.0), 9.8321849378, 1e-8);
  // Free-air gradient about -3.086e-6 s^-2 at mid latitude.
  const double gradient = (NormalGravity(45.0, 1000.0) - NormalGravity(45.0, 0.0)) / 1000.0;
  EXPECT_NEAR(gradient, -3.086e-6, 0.01e-6);
}

TEST(Gravity, ResolveChoosesGivenThenLatitudeThenStandard) {
  GravityOptions options;
  double g;
  std::string source, error;
  ASSERT_TRUE(ResolveGravity(options, &g, &source, &error));
  EXPECT_EQ(g, kStandardGravity);
  EXPECT_EQ(source, "standard");
  options.latitude = 45.4;
  options.height = 20.0;
  ASSERT_TRUE(ResolveGravity(options, &g, &source, &error));
  EXPECT_EQ(g, NormalGravity(45.4, 20.0));
  EXPECT_NE(source.find("latitude"), std::string::npos);
  options.gravity = 9.81744;
  ASSERT_TRUE(ResolveGravity(options, &g, &source, &error));
  EXPECT_EQ(g, 9.81744);
  EXPECT_EQ(source, "given");
}

TEST(Gravity, RejectsImplausibleValues) {
  double g;
  std::string source, error;
  GravityOptions options;
  options.gravity = 1.0;
  EXPECT_FALSE(ResolveGravity(options, &g, &source, &error));
  EXPECT_NE(error.find("gravity"), std::string::npos);
  options = GravityOptions();
  options.latitude = 91.0;
  EXPECT_FALSE(ResolveGravity(options, &g, &source, &error));
  EXPECT_NE(error.find("latitude"), std::string::npos);
}

}  // namespace
}  // namespace gravcal
