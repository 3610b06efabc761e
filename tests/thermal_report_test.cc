// The temperature section of the calibration report (issue 35 part 6): the
// thermal terms against temperature with their bands, and the residual
// after compensation with heating and cooling apart.
#include "workflows/report/thermal_report.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <string>

#include "cli_runner.h"
#include "gravcal/core/calibration.h"
#include "gravcal/workflows/report.h"

namespace gravcal {
namespace {

using testing_util::Count;

// A 400 s session at 10 Hz: 10 -> 50 degC in the first half, back in the
// second; eight static poses of 40 s; the raw accelerometer carries a cubic
// thermal bias, which the calibration's thermal model holds exactly.
struct ThermalSession {
  Calibration calibration;
  ImuLog log;
};

ThermalSession MakeSession() {
  ThermalSession s;
  Calibration& c = s.calibration;
  c.success = true;
  c.gravity = 9.80665;
  ThermalModel& m = c.thermal;
  m.reference_temperature = 30.0;
  m.min_temperature = 10.0;
  m.max_temperature = 50.0;
  ThermalPolynomial& bias = m.accel.bias;
  bias.Resize(3, 3);
  bias.coefficients << 2e-3, 4e-5, -8e-7, -1.5e-3, 2e-5, 5e-7, 3e-3, -6e-5, 1e-6;
  // Covariance of [c_i0, c_i1, c_i2, c_i3]: a band that grows away from
  // T_ref.
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector4d sd(1e-4, 5e-6, 2e-7, 1e-8);
    bias.covariance.push_back(sd.cwiseAbs2().asDiagonal());
  }
  ThermalPolynomial& scale = m.accel.scale;
  scale.Resize(3, 1);
  scale.coefficients << 1e-4, -1e-4, 5e-5;
  for (int i = 0; i < 3; ++i) scale.covariance.push_back(Eigen::Vector2d(1e-8, 1e-12).asDiagonal());
  // The scale's first coefficient undetermined: no band, and said so.
  scale.determined(1, 0) = false;
  scale.coefficients(1, 0) = 0.0;
  const double rate = 10.0;
  for (int k = 0; k < 4000; ++k) {
    const double t = k / rate;
    const double temp = t < 200.0 ? 10.0 + 0.2 * t : 50.0 - 0.2 * (t - 200.0);
    const int pose = static_cast<int>(t / 50.0);
    Eigen::Vector3d up = Eigen::Vector3d::Zero();
    up[pose % 3] = pose % 2 ? -1.0 : 1.0;
    const double x = std::min(std::max(temp, 10.0), 50.0) - 30.0;
    Eigen::Vector3d raw;
    for (int i = 0; i < 3; ++i) {
      raw[i] = bias.Value(i, x) + (1.0 + scale.Value(i, x)) * 9.80665 * up[i];
    }
    s.log.t.push_back(t);
    s.log.accel.push_back(raw);
    s.log.temperature.push_back(temp);
  }
  for (int pose = 0; pose < 8; ++pose) {
    PositionReport p;
    p.position.t_begin = pose * 50.0 + 5.0;
    p.position.t_end = pose * 50.0 + 45.0;
    p.position.raw_mean = s.log.accel[static_cast<size_t>(pose * 500 + 250)];
    p.position.temperature = s.log.temperature[static_cast<size_t>(pose * 500 + 250)];
    c.positions.push_back(p);
  }
  return s;
}

TEST(ThermalReport, BranchesFollowTheTemperatureSlope) {
  const ThermalSession s = MakeSession();
  const std::vector<internal::ThermalBranch> b = internal::ThermalBranches(s.log);
  ASSERT_EQ(b.size(), s.log.size());
  EXPECT_EQ(b[1000], internal::ThermalBranch::kHeating);  // 12 degC/min up
  EXPECT_EQ(b[3000], internal::ThermalBranch::kCooling);
  ImuLog flat = s.log;
  for (double& t : flat.temperature) t = 25.0;
  EXPECT_EQ(internal::ThermalBranches(flat)[1000], internal::ThermalBranch::kSteady);
}

TEST(ThermalReport, TermsWithBandsAndResidualsByBranch) {
  const ThermalSession s = MakeSession();
  const std::string html = CalibrationToHtml(s.calibration, s.log, "thermal session");
  EXPECT_NE(html.find("id='thermal'"), std::string::npos);
  EXPECT_EQ(Count(html, "plot plot-thermal thermal-accel-bias"), 1u);
  EXPECT_EQ(Count(html, "plot plot-thermal thermal-accel-scale"), 1u);
  // Bands: three for the bias; two for the scale (its y term undetermined).
  EXPECT_EQ(Count(html, "class='thermal-band'"), 5u);
  EXPECT_NE(html.find("undetermined terms read as 0"), std::string::npos);
  // Residual: heating and cooling samples drawn apart, beside the
  // uncompensated ones.
  EXPECT_NE(html.find("plot-thermal-residual"), std::string::npos);
  EXPECT_GT(Count(html, "class='thermal-residual branch-heating'"), 100u);
  EXPECT_GT(Count(html, "class='thermal-residual branch-cooling'"), 100u);
  EXPECT_GT(Count(html, "class='thermal-uncompensated'"), 200u);
  // Without a thermal model the section is absent.
  ThermalSession plain = MakeSession();
  plain.calibration.thermal = ThermalModel();
  EXPECT_EQ(CalibrationToHtml(plain.calibration, plain.log, "plain").find("id='thermal'"),
            std::string::npos);
}

}  // namespace
}  // namespace gravcal
