#include "io/thermal_export.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "util/numbers.h"

namespace gravcal {
namespace internal {

namespace {

// ArduPilot's fixed reference temperature (degC) and the factor its TCAL
// coefficients are stored with (AP_InertialSensor_tempcal.cpp).
constexpr double kArduPilotReference = 35.0;
constexpr double kArduPilotScale = 1e6;
// Both targets hold a cubic.
constexpr int kTargetOrder = 3;
// Points of the even grid over the range (fits and truncation maxima).
constexpr int kGridPoints = 101;

double Clamp(double t, double lo, double hi) { return std::min(std::max(t, lo), hi); }

double GridPoint(double lo, double hi, int i) {
  return lo + (hi - lo) * static_cast<double>(i) / (kGridPoints - 1);
}

double Binomial(int n, int k) {
  double b = 1.0;
  for (int i = 1; i <= k; ++i) b = b * (n - k + i) / i;
  return b;
}

// The curve's columns 0..3 (zero where it has none). Order <= 3 checked by
// the caller.
PolynomialCoefficients Cubic(const ThermalCurve& c) {
  PolynomialCoefficients p = PolynomialCoefficients::Zero(3, kTargetOrder + 1);
  p.leftCols(c.coefficients.cols()) = c.coefficients;
  return p;
}

bool CheckCurve(const ThermalCurve& c, const char* target, const char* sensor, std::string* error) {
  if (!(std::isfinite(c.t_min) && std::isfinite(c.t_max) && std::isfinite(c.t_ref) &&
        c.t_max > c.t_min && c.coefficients.allFinite())) {
    *error = std::string(target) + ": the " + sensor +
             " thermal model has no valid temperature range (T_min " + ExactNumber(c.t_min) +
             ", T_max " + ExactNumber(c.t_max) + ")";
    return false;
  }
  if (c.Order() > kTargetOrder) {
    *error = std::string(target) + ": the " + sensor + " thermal bias is of order " +
             std::to_string(c.Order()) + "; the target holds a cubic (reduce it first)";
    return false;
  }
  return true;
}

}  // namespace

Eigen::Vector3d ThermalCurve::At(double temperature) const {
  const double d = Clamp(temperature, t_min, t_max) - t_ref;
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (Eigen::Index k = coefficients.cols() - 1; k >= 0; --k) v = v * d + coefficients.col(k);
  return v;
}

bool ThermalCurve::Varies() const {
  return coefficients.cols() > 1 &&
         (coefficients.rightCols(coefficients.cols() - 1).array() != 0.0).any();
}

PolynomialCoefficients ShiftPolynomial(const PolynomialCoefficients& p, double shift) {
  // p(x) = sum_k c_k x^k with x = y + shift: q_j = sum_{k >= j} c_k C(k, j) shift^(k - j).
  PolynomialCoefficients q = PolynomialCoefficients::Zero(3, p.cols());
  for (int j = 0; j < p.cols(); ++j) {
    for (int k = j; k < p.cols(); ++k) {
      q.col(j) += p.col(k) * Binomial(k, j) * std::pow(shift, k - j);
    }
  }
  return q;
}

ThermalCurve ReduceOrder(const ThermalCurve& curve, int max_order, double* max_error) {
  *max_error = 0.0;
  if (curve.Order() <= max_order) return curve;
  if (!(curve.t_max > curve.t_min)) {
    *max_error = NAN;  // no range to fit over (the exports refuse it)
    return curve;
  }
  // Least squares on the grid over the powers 1..max_order (the value at
  // t_ref stays the base model's), in x = (T - t_ref) / half-width for
  // conditioning, then back to powers of (T - t_ref).
  const double half = 0.5 * (curve.t_max - curve.t_min);
  const double scale = half > 0.0 ? half : 1.0;
  Eigen::MatrixXd a(kGridPoints, max_order);
  Eigen::MatrixXd b(kGridPoints, 3);
  for (int i = 0; i < kGridPoints; ++i) {
    const double t = GridPoint(curve.t_min, curve.t_max, i);
    const double x = (t - curve.t_ref) / scale;
    for (int k = 1; k <= max_order; ++k) a(i, k - 1) = std::pow(x, k);
    b.row(i) = curve.At(t).transpose();
  }
  const Eigen::MatrixXd solution = a.colPivHouseholderQr().solve(b);  // max_order x 3
  ThermalCurve reduced = curve;
  reduced.coefficients = PolynomialCoefficients::Zero(3, max_order + 1);
  for (int k = 1; k <= max_order; ++k) {
    reduced.coefficients.col(k) = solution.row(k - 1).transpose() / std::pow(scale, k);
  }
  for (int i = 0; i < kGridPoints; ++i) {
    const double t = GridPoint(curve.t_min, curve.t_max, i);
    *max_error = std::max(*max_error, (reduced.At(t) - curve.At(t)).cwiseAbs().maxCoeff());
  }
  return reduced;
}

bool Px4ThermalLines(
    const AutopilotThermal& thermal,
    const std::function<std::string(const std::string&, const std::string&, bool)>& line,
    std::string* text, std::string* error) {
  std::string s;
  struct Sensor {
    const ThermalCurve* curve;
    int64_t id;
    const char* enable;  // TC_A_ENABLE
    const char* prefix;  // TC_A0_
    const char* flag;
    const char* vehicle_id;
    const char* name;
  };
  std::vector<Sensor> sensors = {{&thermal.accel, thermal.accel_device_id, "TC_A_ENABLE", "TC_A0_",
                                  "--accel_device_id", "CAL_ACC0_ID", "accelerometer"}};
  if (thermal.has_gyro) {
    sensors.push_back({&thermal.gyro, thermal.gyro_device_id, "TC_G_ENABLE", "TC_G0_",
                       "--gyro_device_id", "CAL_GYRO0_ID", "gyroscope"});
  }
  bool any = false;
  for (const Sensor& sensor : sensors) any |= sensor.curve->Varies();
  for (const Sensor& sensor : sensors) {
    if (!sensor.curve->Varies()) {
      // Only said beside a thermal export: a non-thermal one never was.
      if (any) {
        s += std::string("# ") + sensor.prefix + "* not written: the " + sensor.name +
             " has no thermal term. A " + sensor.enable +
             " = 1 left on the vehicle\n# would still add its old offsets: set it to 0 there "
             "unless other sensors need it.\n";
      }
      continue;
    }
    if (!CheckCurve(*sensor.curve, "px4", sensor.name, error)) return false;
    if (sensor.id <= 0 || sensor.id > 0xffffffffLL) {
      *error = std::string("px4: PX4 applies ") + sensor.prefix + "* only to the " + sensor.name +
               " whose device id equals " + sensor.prefix + "ID, so without it the thermal terms " +
               "would do nothing: give " + sensor.flag + " (the vehicle's " + sensor.vehicle_id +
               "), or --drop_thermal";
      return false;
    }
    const ThermalCurve& c = *sensor.curve;
    const PolynomialCoefficients p = Cubic(c);
    // PX4 keeps the id in an int32 parameter and compares it as uint32.
    const int32_t id = static_cast<int32_t>(static_cast<uint32_t>(sensor.id));
    s += line(sensor.enable, "1", true);
    s += line(std::string(sensor.prefix) + "ID", std::to_string(id), true);
    s += line(std::string(sensor.prefix) + "TREF", ExactNumber(c.t_ref), false);
    s += line(std::string(sensor.prefix) + "TMIN", ExactNumber(c.t_min), false);
    s += line(std::string(sensor.prefix) + "TMAX", ExactNumber(c.t_max), false);
    for (int k = 0; k <= kTargetOrder; ++k) {
      for (int axis = 0; axis < 3; ++axis) {
        s += line(std::string(sensor.prefix) + "X" + std::to_string(k) + "_" + std::to_string(axis),
                  ExactNumber(p(axis, k)), false);
      }
    }
  }
  if (any) {
    s = "# Thermal compensation (PX4 src/modules/temperature_compensation): the offset\n"
        "#   X0 + X1 d + X2 d^2 + X3 d^3,  d = min(max(T, TMIN), TMAX) - TREF  (degC)\n"
        "# is subtracted from the raw reading before CAL_*_OFF and SCALE. PX4 applies it only\n"
        "# to the sensor whose device id equals TC_A0_ID / TC_G0_ID, and reads TC_*_ENABLE at\n"
        "# boot: reboot after loading. T is the IMU's own temperature reading.\n" +
        s;
  }
  *text = s;
  return true;
}

bool ArduPilotThermalLines(
    const AutopilotThermal& thermal,
    const std::function<std::string(const std::string&, const std::string&)>& line,
    std::string* text, std::string* error) {
  const bool gyro = thermal.has_gyro && thermal.gyro.Varies();
  if (!thermal.accel.Varies() && !gyro) {
    *text = "";
    return true;
  }
  // One TCAL block per IMU: one range for both sensors. The accelerometer's
  // range when it varies, else the gyroscope's.
  const ThermalCurve& range = thermal.accel.Varies() ? thermal.accel : thermal.gyro;
  if (!CheckCurve(thermal.accel, "ardupilot", "accelerometer", error) ||
      (thermal.has_gyro && !CheckCurve(thermal.gyro, "ardupilot", "gyroscope", error))) {
    return false;
  }
  if (gyro && thermal.accel.Varies() &&
      (thermal.gyro.t_min != range.t_min || thermal.gyro.t_max != range.t_max)) {
    *error = "ardupilot: INS_TCAL" + std::to_string(thermal.ardupilot_imu) +
             " holds one temperature range for both sensors; the "
             "accelerometer's [" +
             ExactNumber(range.t_min) + ", " + ExactNumber(range.t_max) +
             "] and the gyroscope's [" + ExactNumber(thermal.gyro.t_min) + ", " +
             ExactNumber(thermal.gyro.t_max) + "] degC differ";
    return false;
  }
  const std::string n = std::to_string(thermal.ardupilot_imu);
  const std::string tcal = "INS_TCAL" + n + "_";
  std::string s =
      "# Thermal compensation (ArduPilot AP_InertialSensor_tempcal.cpp), IMU " + n +
      ":\n"
      "#   v = raw - P(T) + P(CALTEMP),  P(T) = 1e-6 (c1 e + c2 e^2 + c3 e^3),  e = T - 35 degC\n"
      "# with T and CALTEMP clamped to [TMIN, TMAX], before INS_ACCOFFS / INS_GYROFFS. The\n"
      "# CALTEMPs say where the offsets of this file hold. Needs a firmware built with\n"
      "# temperature calibration (HAL_INS_TEMPERATURE_CAL_ENABLE) and a reboot.\n";
  s += line(tcal + "ENABLE", "1");
  s += line(tcal + "TMIN", ExactNumber(range.t_min));
  s += line(tcal + "TMAX", ExactNumber(range.t_max));
  auto coefficients = [&](const ThermalCurve& c, bool on, const char* name) {
    // ArduPilot's polynomial is in (T - 35 degC) without a constant: the
    // constant of the shifted curve cancels between P(T) and P(Tcal).
    PolynomialCoefficients q = PolynomialCoefficients::Zero(3, kTargetOrder + 1);
    if (on) q = ShiftPolynomial(Cubic(c), kArduPilotReference - c.t_ref);
    for (int k = 1; k <= kTargetOrder; ++k) {
      for (int axis = 0; axis < 3; ++axis) {
        s += line(tcal + name + std::to_string(k) + "_" + "XYZ"[axis],
                  ExactNumber(kArduPilotScale * q(axis, k)));
      }
    }
  };
  coefficients(thermal.accel, thermal.accel.Varies(), "ACC");
  coefficients(thermal.gyro, gyro, "GYR");
  // The offsets in the file hold at t_ref (c_0 = 0): Tcal = t_ref, inside
  // the range so ArduPilot's clamp leaves it.
  s += line("INS_ACC" + n + "_CALTEMP",
            ExactNumber(Clamp(thermal.accel.t_ref, range.t_min, range.t_max)));
  if (thermal.has_gyro) {
    s += line("INS_GYR" + n + "_CALTEMP",
              ExactNumber(Clamp(thermal.gyro.t_ref, range.t_min, range.t_max)));
  }
  *text = s;
  return true;
}

ThermalTruncation MeasureThermalTruncation(
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&, double)>& full,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&, double)>& target,
    const std::vector<Eigen::Vector3d>& raws, const std::vector<double>& temperatures, double t_min,
    double t_max) {
  ThermalTruncation r;
  double sum = 0.0;
  for (size_t i = 0; i < raws.size() && i < temperatures.size(); ++i) {
    if (!std::isfinite(temperatures[i])) continue;
    sum += (target(raws[i], temperatures[i]) - full(raws[i], temperatures[i])).squaredNorm();
    ++r.readings;
    for (int g = 0; g < kGridPoints && t_max > t_min; ++g) {
      const double t = GridPoint(t_min, t_max, g);
      r.range_max = std::max(r.range_max, (target(raws[i], t) - full(raws[i], t)).norm());
    }
  }
  r.session_rms = r.readings ? std::sqrt(sum / r.readings) : NAN;
  return r;
}

ThermalCurve BiasCurve(const ThermalModel& model, ThermalSensor sensor) {
  const ThermalPolynomial& b = model.Sensor(sensor).bias;
  ThermalCurve c;
  c.t_ref = model.reference_temperature;
  c.t_min = model.min_temperature;
  c.t_max = model.max_temperature;
  c.coefficients = PolynomialCoefficients::Zero(3, b.active() ? b.order + 1 : 1);
  for (int k = 1; b.active() && k <= b.order; ++k)
    c.coefficients.col(k) = b.coefficients.col(k - 1);
  return c;
}

ThermalModel AutopilotHeldThermal(const ThermalModel& full, double reduction[2]) {
  ThermalModel held;
  held.reference_temperature = full.reference_temperature;
  held.min_temperature = full.min_temperature;
  held.max_temperature = full.max_temperature;
  const ThermalSensor sensors[2] = {ThermalSensor::kAccel, ThermalSensor::kGyro};
  for (int i = 0; i < 2; ++i) {
    const ThermalCurve c = ReduceOrder(BiasCurve(full, sensors[i]), kTargetOrder, &reduction[i]);
    if (!c.Varies()) continue;
    ThermalPolynomial& b = held.MutableSensor(sensors[i])->bias;
    b.Resize(3, c.Order());
    b.coefficients = c.coefficients.rightCols(c.Order());
  }
  return held;
}

namespace {

// The largest |p_i(x)| of a term over the range, every component.
double LargestOverRange(const ThermalModel& m, const ThermalPolynomial& p, int components) {
  double largest = 0.0;
  for (int g = 0; g < kGridPoints; ++g) {
    const double x = GridPoint(m.min_temperature, m.max_temperature, g) - m.reference_temperature;
    for (int i = 0; i < components; ++i) largest = std::max(largest, std::abs(p.Value(i, x)));
  }
  return largest;
}

std::string Format(const char* format, double v) {
  char text[64];
  std::snprintf(text, sizeof(text), format, v);
  return text;
}

}  // namespace

void DescribeThermalTruncation(const LoadedCalibration& calibration, const ImuCorrector& held,
                               std::vector<std::string>* dropped) {
  const ThermalModel& full = calibration.corrector.thermal;
  if (!full.active()) return;
  const size_t before = dropped->size();
  const bool range = full.max_temperature > full.min_temperature;
  const std::string over = range ? " over [" + Format("%.4g", full.min_temperature) + ", " +
                                       Format("%.4g", full.max_temperature) + "] degC"
                                 : " (the model has no valid range: size unknown)";
  const ThermalSensor sensors[2] = {ThermalSensor::kAccel, ThermalSensor::kGyro};
  for (ThermalSensor s : sensors) {
    if (s == ThermalSensor::kGyro && !calibration.corrector.has_gyro) continue;
    const std::string name = s == ThermalSensor::kAccel ? "accelerometer" : "gyroscope";
    const ThermalSensorModel& f = full.Sensor(s);
    const ThermalSensorModel& h = held.thermal.Sensor(s);
    if (f.bias.active() && f.bias.order > h.bias.order) {
      double change = 0.0;
      const ThermalCurve fc = BiasCurve(full, s), hc = BiasCurve(held.thermal, s);
      for (int g = 0; range && g < kGridPoints; ++g) {
        const double t = GridPoint(full.min_temperature, full.max_temperature, g);
        change = std::max(change, (fc.At(t) - hc.At(t)).cwiseAbs().maxCoeff());
      }
      dropped->push_back(
          name + " bias against temperature, order " + std::to_string(f.bias.order) +
          (h.bias.active() ? " held as order " + std::to_string(h.bias.order) : " not held") +
          ": changes the bias by up to " + Format("%.3g", change) + " raw units" + over);
    }
    if (f.scale.active() && !h.scale.active()) {
      const double largest = range ? LargestOverRange(full, f.scale, 3) : NAN;
      // The gyroscope's share at a brisk 100 deg/s (static poses show none).
      const std::string rate = s == ThermalSensor::kGyro
                                   ? " (" + Format("%.3g", 100.0 * largest) + " deg/s at 100 deg/s)"
                                   : "";
      dropped->push_back(name + " scale against temperature (order " +
                         std::to_string(f.scale.order) + "): up to " +
                         Format("%.3g", 100.0 * largest) + "% of the reading" + rate + over);
    }
    if (f.misalignment.active() && !h.misalignment.active()) {
      const int n = ThermalComponents(s, ThermalQuantity::kMisalignment);
      dropped->push_back(
          name + " misalignment against temperature (order " +
          std::to_string(f.misalignment.order) + "): up to " +
          Format("%.3g", 1e3 * (range ? LargestOverRange(full, f.misalignment, n) : NAN)) +
          " mrad" + over);
    }
  }
  if (full.lag_time_constant != 0.0 && held.thermal.lag_time_constant == 0.0) {
    dropped->push_back("thermal lag tau = " + Format("%.3g", full.lag_time_constant) +
                       " s: the target uses the logged temperature as it is (on a 1 degC/min "
                       "ramp it takes the bias " +
                       Format("%.3g", std::abs(full.lag_time_constant) / 60.0) + " degC off)");
  }
  if (dropped->size() == before || calibration.positions.empty()) return;
  // The thermal part alone: the same base model with each thermal model.
  ImuCorrector only_held = calibration.corrector;
  only_held.thermal = held.thermal;
  std::vector<Eigen::Vector3d> raws;
  std::vector<double> temperatures;
  for (const RecordedPosition& p : calibration.positions) {
    raws.push_back(p.raw_mean);
    temperatures.push_back(p.temperature);
  }
  auto correct = [&](const ImuCorrector& k) {
    return [&k](const Eigen::Vector3d& raw, double t) {
      Eigen::Vector3d a = Eigen::Vector3d::Constant(NAN);
      k.CorrectAccel(raw, t, 0.0, &a);
      return a;
    };
  };
  const ThermalTruncation m = MeasureThermalTruncation(
      correct(calibration.corrector), correct(only_held), raws, temperatures,
      range ? full.min_temperature : 0.0, range ? full.max_temperature : 0.0);
  if (m.readings == 0) {
    dropped->push_back(
        "the static positions record no temperature: the thermal terms' share of "
        "the error is not measured");
    return;
  }
  dropped->push_back(
      "accelerometer output with the thermal terms this file holds against the "
      "full thermal model: rms " +
      Format("%.3g", m.session_rms) + " m/s^2 over the calibration's " +
      std::to_string(m.readings) + " static positions" +
      (range ? ", up to " + Format("%.3g", m.range_max) + " m/s^2 in those poses" + over : ""));
}

AutopilotThermal ToAutopilotThermal(const ThermalModel& held, bool has_gyro,
                                    const ExportOptions& options) {
  AutopilotThermal t;
  t.accel = BiasCurve(held, ThermalSensor::kAccel);
  t.gyro = BiasCurve(held, ThermalSensor::kGyro);
  t.has_gyro = has_gyro;
  t.accel_device_id = options.accel_device_id;
  t.gyro_device_id = options.gyro_device_id;
  t.ardupilot_imu = options.ardupilot_imu;
  return t;
}

}  // namespace internal
}  // namespace gravcal
