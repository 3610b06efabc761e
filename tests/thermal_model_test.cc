#include "gravcal/core/thermal_model.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_corrector.h"
#include "gravcal/io/calibration_io.h"

namespace gravcal {
namespace {

// A model with every term of both sensors at order 2 or 3.
ThermalModel SampleThermalModel() {
  ThermalModel m;
  m.reference_temperature = 20.0;
  m.min_temperature = -10.0;
  m.max_temperature = 60.0;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  for (ThermalSensor s : {ThermalSensor::kAccel, ThermalSensor::kGyro}) {
    ThermalSensorModel* sensor = m.MutableSensor(s);
    const double sizes[3] = {1e-2, 1e-5, 1e-5};
    const ThermalQuantity qs[3] = {ThermalQuantity::kBias, ThermalQuantity::kScale,
                                   ThermalQuantity::kMisalignment};
    for (int t = 0; t < 3; ++t) {
      ThermalPolynomial* p = sensor->MutableTerm(qs[t]);
      p->Resize(ThermalComponents(s, qs[t]), t == 0 ? 3 : 2);
      for (int i = 0; i < p->coefficients.rows(); ++i) {
        for (int k = 0; k < p->order; ++k) {
          p->coefficients(i, k) = sizes[t] * n(rng) / std::pow(10.0, k);
        }
      }
    }
  }
  return m;
}

TEST(ThermalModel, HornerEqualsPowerSum) {
  const double c[6] = {0.5, -0.25, 0.125, 2.0, 0.0, -1.0};  // 2 components, order 3
  double out[2];
  EvaluateThermalPolynomial(c, 2, 3, 1.5, out);
  EXPECT_NEAR(out[0], 0.5 * 1.5 - 0.25 * 2.25 + 0.125 * 3.375, 1e-15);
  EXPECT_NEAR(out[1], 2.0 * 1.5 - 3.375, 1e-15);
  EvaluateThermalPolynomial<double, double>(nullptr, 2, 3, 1.5, out);
  EXPECT_EQ(out[0], 0.0);
}

TEST(ThermalModel, OffsetClampsAndLags) {
  ThermalModel m;
  m.reference_temperature = 25.0;
  m.min_temperature = 10.0;
  m.max_temperature = 40.0;
  bool clamped = true;
  EXPECT_DOUBLE_EQ(m.Offset(30.0, NAN, &clamped), 5.0);
  EXPECT_FALSE(clamped);
  EXPECT_DOUBLE_EQ(m.Offset(55.0, NAN, &clamped), 15.0);
  EXPECT_TRUE(clamped);
  EXPECT_DOUBLE_EQ(m.Offset(-5.0, NAN, &clamped), -15.0);
  EXPECT_TRUE(clamped);
  EXPECT_EQ(m.Offset(NAN, NAN, &clamped), 0.0);
  m.lag_time_constant = 60.0;
  // Warming at 0.05 degC/s: the element is 3 degC behind the sensor.
  EXPECT_DOUBLE_EQ(m.Offset(30.0, 0.05, nullptr), 2.0);
  EXPECT_FALSE(m.InRange(41.0));
  EXPECT_TRUE(m.InRange(25.0));
}

TEST(ThermalModel, CorrectionInvertsTheSensorModel) {
  const ThermalModel m = SampleThermalModel();
  std::string error;
  ASSERT_TRUE(m.IsValid(&error)) << error;
  AccelModel accel;
  accel.bias = Eigen::Vector3d(120.0, -80.0, 40.0);
  accel.upper << 9.81 / 16384, 1e-6, -2e-6, 0.0, 9.79 / 16384, 3e-6, 0.0, 0.0, 9.83 / 16384;
  const Eigen::Vector3d s(1.0, -3.0, 9.0);
  for (double temperature : {-5.0, 20.0, 47.0}) {
    const double x = m.Offset(temperature, NAN, nullptr);
    // v = b + db(x) + U^-1 (I + D(x)) s.
    const ThermalBlocks<double> b = m.Blocks(ThermalSensor::kAccel);
    Eigen::Vector3d y = s;
    b.ApplyScale(x, y.data());
    double db[3];
    b.BiasChange(x, db);
    const Eigen::Vector3d v =
        accel.bias + Eigen::Vector3d(db[0], db[1], db[2]) + accel.upper.inverse() * y;
    EXPECT_LT((CorrectAccelThermal(m, accel.bias, accel.upper, v, x) - s).norm(), 1e-10);
    // The corrector gives the same (R = I, no effects).
    ImuCorrector corrector;
    corrector.accel = accel;
    corrector.thermal = m;
    Eigen::Vector3d a;
    ASSERT_TRUE(corrector.CorrectAccel(v, temperature, 0.0, &a));
    EXPECT_LT((a - s).norm(), 1e-10);
    // Gyroscope: u = b_g + db_g + M_g^-1 (I + D_g) w, full off-diagonal.
    GyroModel gyro;
    gyro.bias = Eigen::Vector3d(0.01, -0.02, 0.005);
    gyro.matrix << 1.01, 0.002, -0.001, 0.003, 0.99, 0.002, -0.002, 0.001, 1.02;
    const Eigen::Vector3d w(0.3, -0.1, 0.7);
    const ThermalBlocks<double> g = m.Blocks(ThermalSensor::kGyro);
    Eigen::Vector3d yg = w;
    g.ApplyScale(x, yg.data());
    g.BiasChange(x, db);
    const Eigen::Vector3d u =
        gyro.bias + Eigen::Vector3d(db[0], db[1], db[2]) + gyro.matrix.inverse() * yg;
    EXPECT_LT((CorrectGyroThermal(m, gyro.bias, gyro.matrix, u, x) - w).norm(), 1e-12);
    corrector.has_gyro = true;
    corrector.gyro = gyro;
    EXPECT_LT((corrector.CorrectGyro(u, a, temperature, 0.0) - w).norm(), 1e-12);
  }
}

TEST(ThermalModel, EvaluatesWithJets) {
  using Jet = ceres::Jet<double, 4>;
  // d/dc of p(x) = c1 x + c2 x^2 + c3 x^3 is (x, x^2, x^3); d/dx is p'(x).
  Jet c[3] = {Jet(0.5, 0), Jet(-0.25, 1), Jet(0.125, 2)};
  const Jet x(2.0, 3);
  Jet out;
  EvaluateThermalPolynomial(c, 1, 3, x, &out);
  EXPECT_NEAR(out.a, 1.0 - 1.0 + 1.0, 1e-15);
  EXPECT_NEAR(out.v[0], 2.0, 1e-15);
  EXPECT_NEAR(out.v[1], 4.0, 1e-15);
  EXPECT_NEAR(out.v[2], 8.0, 1e-15);
  EXPECT_NEAR(out.v[3], 0.5 - 0.5 * 2.0 + 3 * 0.125 * 4.0, 1e-15);
}

TEST(ThermalModel, StdFromCovarianceAndUndeterminedTerms) {
  ThermalPolynomial p;
  p.Resize(3, 2);
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(3, 3);
  c.diagonal() << 4.0, 1.0, 0.25;
  p.covariance.assign(3, c);
  // Var(c0 + c1 x + c2 x^2) at x = 2: 4 + 4 + 0.25 * 16.
  EXPECT_NEAR(p.Std(0, 2.0, true), std::sqrt(12.0), 1e-12);
  EXPECT_NEAR(p.Std(0, 2.0, false), std::sqrt(8.0), 1e-12);
  p.determined(1, 1) = false;
  EXPECT_TRUE(std::isnan(p.Std(1, 2.0, false)));
  EXPECT_FALSE(p.Determined(1, 2));
  EXPECT_TRUE(p.Determined(1, 1));
}

TEST(ThermalModel, CalibrationJsonRoundTrip) {
  Calibration c;
  c.success = true;
  c.gyro.estimated = true;
  c.thermal = SampleThermalModel();
  c.thermal.accel.bias.determined(0, 2) = false;
  c.thermal.accel.bias.coefficients(0, 2) = 0.0;
  c.thermal.accel.bias.max_order = 3;
  c.thermal.accel.bias.selection = "aicc";
  Eigen::MatrixXd cov = Eigen::MatrixXd::Identity(4, 4) * 1e-6;
  c.thermal.accel.bias.covariance.assign(3, cov);
  c.thermal.lag_time_constant = 42.0;
  c.thermal.notes.push_back("a note");
  const std::string text = CalibrationToJson(c, false);
  LoadedCalibration loaded;
  std::string error;
  ASSERT_TRUE(CalibrationFromJson(text, "c.json", &loaded, &error)) << error;
  const ThermalModel& t = loaded.corrector.thermal;
  EXPECT_EQ(t.reference_temperature, 20.0);
  EXPECT_EQ(t.min_temperature, -10.0);
  EXPECT_EQ(t.max_temperature, 60.0);
  EXPECT_EQ(t.lag_time_constant, 42.0);
  EXPECT_EQ(t.accel.bias.order, 3);
  EXPECT_EQ(t.accel.bias.selection, "aicc");
  EXPECT_FALSE(t.accel.bias.Determined(0, 3));
  EXPECT_TRUE(t.accel.bias.Determined(0, 2));
  ASSERT_EQ(t.accel.bias.covariance.size(), 3u);
  EXPECT_EQ(t.accel.bias.covariance[1](2, 2), 1e-6);
  for (ThermalSensor s : {ThermalSensor::kAccel, ThermalSensor::kGyro}) {
    for (ThermalQuantity q :
         {ThermalQuantity::kBias, ThermalQuantity::kScale, ThermalQuantity::kMisalignment}) {
      EXPECT_EQ(t.Sensor(s).Term(q).coefficients, c.thermal.Sensor(s).Term(q).coefficients)
          << ToString(s) << " " << ToString(q);
    }
  }
  EXPECT_EQ(t.notes, c.thermal.notes);
  // The undetermined coefficient is written as null.
  EXPECT_NE(text.find("null"), std::string::npos);
}

TEST(ThermalModel, BadSectionsAreRefusedNamingTheKey) {
  Calibration c;
  c.thermal = SampleThermalModel();
  const std::string good = CalibrationToJson(c, false);
  auto error_of = [](std::string text) {
    LoadedCalibration loaded;
    std::string error;
    EXPECT_FALSE(CalibrationFromJson(text, "c.json", &loaded, &error));
    return error;
  };
  auto replace = [&good](const std::string& from, const std::string& to) {
    std::string text = good;
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  EXPECT_NE(error_of(replace("\"order\": 3", "\"order\": 9")).find("thermal.accel.bias.order"),
            std::string::npos);
  EXPECT_NE(
      error_of(replace("\"order\": 3", "\"order\": 2")).find("thermal.accel.bias.coefficients"),
      std::string::npos);
  EXPECT_NE(error_of(replace("\"reference_temperature\": 20.0", "\"reference_temperature\": \"x\""))
                .find("thermal.reference_temperature"),
            std::string::npos);
  // The gyroscope terms need a gyroscope model (this calibration has none).
  EXPECT_NE(error_of(good).find("thermal.gyro"), std::string::npos);
}

}  // namespace
}  // namespace gravcal
