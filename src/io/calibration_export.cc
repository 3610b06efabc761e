#include "gravcal/io/calibration_export.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cstdio>
#include <sstream>

#include "core/enum_names.h"
#include "gravcal/io/noise_io.h"
#include "io/c_corrector_export.h"
#include "io/export_format.h"
#include "io/thermal_export.h"
#include "util/join.h"

namespace gravcal {

using internal::ExactNumber;
using internal::YamlMatrix;
using internal::YamlRow;

namespace {

const internal::EnumName<ExportTarget> kTargets[] = {{ExportTarget::kKalibr, "kalibr"},
                                                     {ExportTarget::kOpenVins, "openvins"},
                                                     {ExportTarget::kRos, "ros"},
                                                     {ExportTarget::kPx4, "px4"},
                                                     {ExportTarget::kArduPilot, "ardupilot"},
                                                     {ExportTarget::kC, "c"}};

// A = L Q with L lower triangular (positive diagonal) and Q a rotation, from
// the QR decomposition of A^T. False when det(A) <= 0.
bool LowerTimesRotation(const Eigen::Matrix3d& a, Eigen::Matrix3d* lower, Eigen::Matrix3d* q) {
  if (!(a.determinant() > 0.0)) return false;
  Eigen::HouseholderQR<Eigen::Matrix3d> qr(a.transpose());
  Eigen::Matrix3d qm = qr.householderQ();
  Eigen::Matrix3d r = qr.matrixQR().triangularView<Eigen::Upper>();
  const Eigen::Vector3d sign = r.diagonal().cwiseSign();
  qm = qm * sign.asDiagonal();
  r = sign.asDiagonal() * r;
  *lower = r.transpose();
  *q = qm.transpose();
  return true;
}

// A = Q U with Q a rotation and U upper triangular (positive diagonal).
bool RotationTimesUpper(const Eigen::Matrix3d& a, Eigen::Matrix3d* q, Eigen::Matrix3d* upper) {
  if (!(a.determinant() > 0.0)) return false;
  Eigen::HouseholderQR<Eigen::Matrix3d> qr(a);
  Eigen::Matrix3d qm = qr.householderQ();
  Eigen::Matrix3d r = qr.matrixQR().triangularView<Eigen::Upper>();
  const Eigen::Vector3d sign = r.diagonal().cwiseSign();
  *q = qm * sign.asDiagonal();
  *upper = sign.asDiagonal() * r;
  return true;
}

std::string Comment(const std::vector<std::string>& lines, const char* marker) {
  std::string s;
  for (const std::string& line : lines) s += std::string(marker) + " " + line + "\n";
  return s;
}

std::vector<std::string> EffectNamesOf(const std::vector<Effect>& effects,
                                       const std::vector<Effect>& except) {
  std::vector<std::string> names;
  for (Effect e : effects) {
    if (!Contains(except, e)) names.push_back(ToString(e));
  }
  return names;
}

using internal::Join;

// The lines of `dropped` for the target, from the full and truncated models.
void DescribeTruncation(const LoadedCalibration& c, const ExportOptions& options,
                        ExportResult* result) {
  const ImuCorrector& full = c.corrector;
  ImuCorrector truncated = TruncatedCorrector(full, options.target);
  if (options.drop_thermal) truncated.thermal = ThermalModel();
  std::vector<std::string>& dropped = result->dropped;
  const std::vector<std::string> effects =
      EffectNamesOf(full.active_effects, truncated.active_effects);
  if (!effects.empty()) dropped.push_back("effect terms " + Join(effects));
  if (!full.accel.matrix().isApprox(truncated.accel.matrix(), 0.0)) {
    dropped.push_back("accelerometer cross-axis terms and axis rotation (off-diagonal of M)");
  }
  if (full.has_gyro && !full.gyro.matrix.isApprox(truncated.gyro.matrix, 0.0)) {
    const Eigen::Matrix3d d = full.gyro.matrix - truncated.gyro.matrix;
    char text[160];
    std::snprintf(text, sizeof(text),
                  "gyroscope scale and misalignment M_g (up to %.3g%% of the rate: largest row "
                  "sum of |M_g - I|)",
                  100.0 * d.cwiseAbs().rowwise().sum().maxCoeff());
    dropped.push_back(text);
  }
  internal::DescribeThermalTruncation(c, truncated, &dropped);
  if (c.positions.empty()) {
    if (!dropped.empty()) {
      dropped.push_back("the calibration records no static positions: truncation error unknown");
    }
    return;
  }
  result->full_rms = PositionResidualRms(full, c.positions, c.gravity);
  result->truncated_rms = PositionResidualRms(truncated, c.positions, c.gravity);
  const bool temperature_unknown =
      (full.RequiresTemperature() || full.HasThermal()) &&
      std::any_of(c.positions.begin(), c.positions.end(),
                  [](const RecordedPosition& p) { return !std::isfinite(p.temperature); });
  if (!dropped.empty()) {
    char text[200];
    std::snprintf(text, sizeof(text),
                  "|a| - g rms over the calibration's %zu static positions: %.6g m/s^2 with what "
                  "this file holds, %.6g m/s^2 with the full model",
                  c.positions.size(), result->truncated_rms, result->full_rms);
    dropped.push_back(text);
    if (temperature_unknown) {
      dropped.push_back(
          "the positions record no temperature (file older than gravcal 0.2.0 issue 16): the "
          "temperature terms' share of that error is not included");
    }
  }
}

// The header comment every exported file starts with.
std::vector<std::string> Provenance(const LoadedCalibration& c, const ExportOptions& options) {
  std::vector<std::string> lines = {"Written by gravcal " GRAVCAL_VERSION " export --to " +
                                    std::string(ToString(options.target)) + " from " +
                                    options.calibration_name};
  if (!c.provenance.log_file.empty()) {
    lines.push_back(
        "calibrated from " + c.provenance.log_file +
        (c.provenance.log_hash.empty() ? "" : " (content hash " + c.provenance.log_hash + ")") +
        (c.provenance.gravcal_version.empty() ? ""
                                              : " by gravcal " + c.provenance.gravcal_version));
  }
  return lines;
}

std::vector<std::string> DroppedComment(const ExportResult& r) {
  if (r.dropped.empty()) return {"Nothing of the calibration is dropped."};
  std::vector<std::string> lines = {"This target cannot hold the whole calibration. Dropped:"};
  for (const std::string& d : r.dropped) lines.push_back("  " + d);
  return lines;
}

bool NoiseBlock(const ImuNoiseModel& noise, std::string* yaml, std::string* error) {
  return NoiseToKalibrYaml(noise, yaml, error);
}

bool KalibrYaml(const LoadedCalibration& c, const ExportOptions& o, const ExportResult& r,
                std::string* text, std::string* error) {
  const ImuCorrector& k = c.corrector;
  Eigen::Matrix3d accel_m, c_i_b;
  if (!LowerTimesRotation(k.accel.matrix().inverse(), &accel_m, &c_i_b)) {
    *error = "kalibr: accel.matrix has det <= 0";
    return false;
  }
  Eigen::Matrix3d gyro_m = Eigen::Matrix3d::Identity(), c_gyro_i = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d a_g = Eigen::Matrix3d::Zero();
  if (k.has_gyro &&
      !LowerTimesRotation(k.gyro.matrix.inverse() * c_i_b.transpose(), &gyro_m, &c_gyro_i)) {
    *error = "kalibr: gyro.matrix has det <= 0 (a left-handed gyroscope triad)";
    return false;
  }
  if (Contains(k.active_effects, Effect::kGyroGSensitivity)) {
    a_g = k.effects.Matrix(Effect::kGyroGSensitivity) * k.accel.rotation.transpose() *
          c_i_b.transpose() * c_gyro_i.transpose();
  }
  std::string noise;
  if (!NoiseBlock(*o.noise, &noise, error)) return false;
  Eigen::Matrix4d t_i_b = Eigen::Matrix4d::Identity();
  t_i_b.topLeftCorner<3, 3>() = c_i_b;
  std::ostringstream s;
  s << Comment(Provenance(c, o), "#") << Comment(DroppedComment(r), "#")
    << "# Kalibr scale-misalignment model (b = housing frame, i = Kalibr's IMU frame):\n"
    << "#   raw accel = M_a C_i_b a_b + bias_a,  raw gyro = M_g C_gyro_i w_i + A C_gyro_i a_i + "
       "bias_g\n"
    << "# with a_i = C_i_b a_b, w_i = C_i_b w_b. Kalibr estimates the biases online; gravcal's\n"
    << "# are in gravcal_bias (raw units).\n"
    << noise << "rostopic: /imu0\n"
    << "model: scale-misalignment\n"
    << "T_i_b:\n"
    << YamlMatrix(t_i_b, 2) << "accelerometers:\n"
    << "  M:\n"
    << YamlMatrix(accel_m, 4) << "  gravcal_bias: " << YamlRow(k.accel.bias.transpose()) << "\n"
    << "gyroscopes:\n"
    << "  M:\n"
    << YamlMatrix(gyro_m, 4) << "  A:\n"
    << YamlMatrix(a_g, 4) << "  C_gyro_i:\n"
    << YamlMatrix(c_gyro_i, 4) << "  gravcal_bias: "
    << YamlRow((k.has_gyro ? k.gyro.bias : Eigen::Vector3d::Zero()).transpose()) << "\n";
  *text = s.str();
  return true;
}

bool OpenVinsYaml(const LoadedCalibration& c, const ExportOptions& o, const ExportResult& r,
                  std::string* text, std::string* error) {
  const ImuCorrector& k = c.corrector;
  Eigen::Matrix3d r_gyro_to_imu = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d dw = Eigen::Matrix3d::Identity();
  if (k.has_gyro && !RotationTimesUpper(k.gyro.matrix, &r_gyro_to_imu, &dw)) {
    *error = "openvins: gyro.matrix has det <= 0 (a left-handed gyroscope triad)";
    return false;
  }
  Eigen::Matrix3d tg = Eigen::Matrix3d::Zero();
  if (Contains(k.active_effects, Effect::kGyroGSensitivity)) {
    tg = k.effects.Matrix(Effect::kGyroGSensitivity) * k.accel.rotation.transpose();
  }
  std::string noise;
  if (!NoiseBlock(*o.noise, &noise, error)) return false;
  // The noise block's lines, indented under imu0.
  std::string indented;
  std::istringstream lines(noise);
  for (std::string line; std::getline(lines, line);) {
    indented += (line.rfind("#", 0) == 0 ? "" : "  ") + line + "\n";
  }
  std::ostringstream s;
  s << "%YAML:1.0\n"
    << Comment(Provenance(c, o), "#") << Comment(DroppedComment(r), "#")
    << "# OpenVINS \"rpng\" IMU model (ov_msckf Propagator):\n"
    << "#   a = R_ACCtoIMU Da (a_m - b_a),  w = R_GYROtoIMU Dw (w_m - b_g - Tg a)\n"
    << "# Da = Ta^-1, Dw = Tw^-1 upper triangular; R_ACCtoIMU = R_IMUtoACC^T. OpenVINS\n"
    << "# estimates the biases online; gravcal's are in gravcal_*_bias (raw units).\n"
    << "imu0:\n"
    << "  T_i_b:\n"
    << YamlMatrix(Eigen::Matrix4d::Identity(), 4) << indented << "  rostopic: /imu0\n"
    << "  time_offset: 0.0\n"
    << "  model: \"rpng\"\n"
    << "  Tw:\n"
    << YamlMatrix(dw.inverse(), 4) << "  R_IMUtoGYRO:\n"
    << YamlMatrix(r_gyro_to_imu.transpose(), 4) << "  Ta:\n"
    << YamlMatrix(k.accel.upper.inverse(), 4) << "  R_IMUtoACC:\n"
    << YamlMatrix(k.accel.rotation.transpose(), 4) << "  Tg:\n"
    << YamlMatrix(tg, 4) << "  gravcal_accel_bias: " << YamlRow(k.accel.bias.transpose())
    << "\n  gravcal_gyro_bias: "
    << YamlRow((k.has_gyro ? k.gyro.bias : Eigen::Vector3d::Zero()).transpose()) << "\n";
  *text = s.str();
  return true;
}

bool RosYaml(const LoadedCalibration& c, const ExportOptions& o, std::string* text,
             std::string* error) {
  const ImuNoiseModel& n = *o.noise;
  if (!(n.rate_hz > 0.0)) {
    *error = "ros: the noise model has no sample rate";
    return false;
  }
  auto covariance = [&](const std::array<AxisNoiseModel, 3>& axes, const char* sensor,
                        std::string* row) {
    Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
    for (int i = 0; i < 3; ++i) {
      const double density = axes[i].white_noise.value;
      if (!std::isfinite(density)) {
        *error = std::string("ros: the noise model shows no white noise on the ") + sensor +
                 " axis " + "xyz"[i];
        return false;
      }
      m(i, i) = density * density * n.rate_hz;
    }
    *row = YamlRow(Eigen::Map<Eigen::Matrix<double, 9, 1>>(m.data()));
    return true;
  };
  std::string accel, gyro;
  if (!covariance(n.accel, "accelerometer", &accel) || !covariance(n.gyro, "gyroscope", &gyro)) {
    return false;
  }
  std::ostringstream s;
  s << Comment(Provenance(c, o), "#")
    << "# sensor_msgs/Imu covariances (row-major 3x3) of the calibrated readings: per axis\n"
    << "# the white-noise density N squared times the sample rate (variance of one sample,\n"
    << "# (m/s^2)^2 and (rad/s)^2). orientation_covariance[0] = -1: no orientation estimate.\n"
    << "# Apply the calibration (gravcal apply, or the C export) before publishing.\n"
    << "imu_covariance:\n"
    << "  rate_hz: " << ExactNumber(n.rate_hz) << "\n"
    << "  linear_acceleration_covariance: " << accel << "\n"
    << "  angular_velocity_covariance: " << gyro << "\n"
    << "  orientation_covariance: [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]\n";
  *text = s.str();
  return true;
}

// PX4 and ArduPilot: per-axis offset (m/s^2, rad/s) and accelerometer scale.
bool AutopilotScales(const ImuCorrector& t, const char* target, std::string* error) {
  for (int i = 0; i < 3; ++i) {
    const double scale = t.accel.upper(i, i);
    if (!(scale >= 0.1 && scale <= 3.0)) {
      *error = std::string(target) + ": accelerometer scale " + "xyz"[i] + " = " +
               ExactNumber(scale) +
               " is outside the firmware's range [0.1, 3]: the calibration's raw units are not "
               "m/s^2 (the firmware's driver units)";
      return false;
    }
  }
  return true;
}

// PX4 and ArduPilot write the same nine numbers under their own names and
// line format.
struct AutopilotFormat {
  // Comment lines after the provenance: the target's equation and format.
  std::vector<std::string> header;
  // Name prefixes of the accelerometer offset and scale and the gyroscope
  // offset, and the suffix after the axis letter.
  std::string accel_offset;
  std::string accel_scale;
  std::string gyro_offset;
  std::string offset_suffix;
  std::string scale_suffix;
  // One parameter line from the name and the value.
  std::string (*line)(const std::string& name, const std::string& value);
};

std::string AutopilotParameters(const LoadedCalibration& c, const ExportOptions& o,
                                const ExportResult& r, const ImuCorrector& t,
                                const AutopilotFormat& f) {
  std::ostringstream s;
  s << Comment(Provenance(c, o), "#") << Comment(DroppedComment(r), "#") << Comment(f.header, "#");
  const char* axes[3] = {"X", "Y", "Z"};
  for (int i = 0; i < 3; ++i) {
    s << f.line(f.accel_offset + axes[i] + f.offset_suffix, ExactNumber(t.accel.bias(i)));
  }
  for (int i = 0; i < 3; ++i) {
    s << f.line(f.accel_scale + axes[i] + f.scale_suffix, ExactNumber(t.accel.upper(i, i)));
  }
  for (int i = 0; t.has_gyro && i < 3; ++i) {
    s << f.line(f.gyro_offset + axes[i] + f.offset_suffix, ExactNumber(t.gyro.bias(i)));
  }
  return s.str();
}

const AutopilotFormat& Px4Format() {
  static const AutopilotFormat format = {
      {"PX4 (src/lib/sensor_calibration): a = rot (diag(SCALE) (a_m - OFF)) in m/s^2,",
       "w = rot (w_m - OFF) in rad/s; a_m, w_m the driver's readings in the sensor frame.",
       "CAL_*_ID and CAL_*_ROT are left as they are on the vehicle.",
       "QGroundControl parameter file: vehicle, component, name, value, type (9 = float).",
       "MAV ID  COMPONENT ID  PARAM NAME  VALUE (FLOAT)"},
      "CAL_ACC0_",
      "CAL_ACC0_",
      "CAL_GYRO0_",
      "OFF",
      "SCALE",
      [](const std::string& name, const std::string& value) {
        return "1\t1\t" + name + "\t" + value + "\t9\n";
      }};
  return format;
}

// IMU instance `imu` (1..3): INS_ACCOFFS_X for the first, INS_ACC2OFFS_X
// for the second (AP_InertialSensor.cpp's parameter table).
AutopilotFormat ArduPilotFormat(int imu) {
  const std::string n = imu > 1 ? std::to_string(imu) : "";
  return {
      {"ArduPilot (AP_InertialSensor_Backend): a = rot (diag(ACCSCAL) (a_m - ACCOFFS)) in",
       "m/s^2, w = rot (w_m - GYROFFS) in rad/s, sensor frame before the board rotation.",
       "IMU instance " + std::to_string(imu) + ". Parameter file: NAME VALUE per line."},
      "INS_ACC" + n + "OFFS_",
      "INS_ACC" + n + "SCAL_",
      "INS_GYR" + n + "OFFS_",
      "",
      "",
      [](const std::string& name, const std::string& value) { return name + " " + value + "\n"; }};
}

}  // namespace

GRAVCAL_ENUM_STRINGS(ExportTarget, kTargets)

bool NeedsNoise(ExportTarget target) {
  return target == ExportTarget::kKalibr || target == ExportTarget::kOpenVins ||
         target == ExportTarget::kRos;
}

bool ExportOptions::IsValid(std::string* error) const {
  if (ardupilot_imu < 1 || ardupilot_imu > 3) {
    *error = "ardupilot_imu must be 1, 2 or 3 (ArduPilot's IMU instances), not " +
             std::to_string(ardupilot_imu);
    return false;
  }
  if (NeedsNoise(target) && noise == nullptr) {
    *error = std::string("export --to ") + ToString(target) +
             " needs the noise model (--noise noise.json from gravcal noise)";
    return false;
  }
  return true;
}

double PositionResidualRms(const ImuCorrector& corrector,
                           const std::vector<RecordedPosition>& positions, double gravity) {
  if (positions.empty()) return 0.0;
  double sum = 0.0;
  for (const RecordedPosition& p : positions) {
    Eigen::Vector3d a;
    if (!corrector.CorrectAccel(p.raw_mean, p.temperature, p.time, &a)) return NAN;
    const double r = a.norm() - gravity;
    sum += r * r;
  }
  return std::sqrt(sum / positions.size());
}

ImuCorrector TruncatedCorrector(const ImuCorrector& full, ExportTarget target) {
  switch (target) {
    case ExportTarget::kRos:
    case ExportTarget::kC:
      // The C corrector is written from the effects' definitions and holds
      // the thermal model with its lag: the whole model.
      return full;
    case ExportTarget::kKalibr:
    case ExportTarget::kOpenVins: {
      ImuCorrector t = full.WithEffects({Effect::kGyroGSensitivity});
      t.thermal = ThermalModel();
      return t;
    }
    case ExportTarget::kPx4:
    case ExportTarget::kArduPilot: {
      ImuCorrector t = full.WithEffects({});
      // The thermal bias as a cubic; no thermal scale, misalignment or lag.
      double reduction[2];
      t.thermal = internal::AutopilotHeldThermal(full.thermal, reduction);
      // Per-axis scale: the diagonal of M; no rotation, no cross-axis terms.
      const Eigen::Matrix3d m = full.accel.matrix();
      t.accel.upper = m.diagonal().asDiagonal();
      t.accel.rotation.setIdentity();
      t.gyro.matrix.setIdentity();
      return t;
    }
  }
  return full;
}

bool ExportCalibration(const LoadedCalibration& calibration, const ExportOptions& options,
                       ExportResult* result, std::string* error) {
  *result = ExportResult();
  if (!options.IsValid(error)) return false;
  // ros writes covariances only: no correction to truncate.
  if (options.target != ExportTarget::kRos) DescribeTruncation(calibration, options, result);
  std::string text;
  ImuCorrector truncated = TruncatedCorrector(calibration.corrector, options.target);
  if (options.drop_thermal) truncated.thermal = ThermalModel();
  const internal::AutopilotThermal thermal =
      internal::ToAutopilotThermal(truncated.thermal, truncated.has_gyro, options);
  std::string thermal_lines;
  switch (options.target) {
    case ExportTarget::kKalibr:
      if (!KalibrYaml(calibration, options, *result, &text, error)) return false;
      break;
    case ExportTarget::kOpenVins:
      if (!OpenVinsYaml(calibration, options, *result, &text, error)) return false;
      break;
    case ExportTarget::kRos:
      if (!RosYaml(calibration, options, &text, error)) return false;
      break;
    case ExportTarget::kPx4:
      if (!AutopilotScales(truncated, "px4", error)) return false;
      if (!internal::Px4ThermalLines(
              thermal,
              [](const std::string& name, const std::string& value, bool integer) {
                return "1\t1\t" + name + "\t" + value + "\t" + (integer ? "6" : "9") + "\n";
              },
              &thermal_lines, error)) {
        return false;
      }
      text = AutopilotParameters(calibration, options, *result, truncated, Px4Format()) +
             thermal_lines;
      break;
    case ExportTarget::kArduPilot:
      if (!AutopilotScales(truncated, "ardupilot", error)) return false;
      if (!internal::ArduPilotThermalLines(thermal, ArduPilotFormat(options.ardupilot_imu).line,
                                           &thermal_lines, error)) {
        return false;
      }
      text = AutopilotParameters(calibration, options, *result, truncated,
                                 ArduPilotFormat(options.ardupilot_imu)) +
             thermal_lines;
      break;
    case ExportTarget::kC: {
      std::vector<std::string> comment = Provenance(calibration, options);
      comment.push_back("Self-contained C99: no dynamic memory; <math.h> (link -lm with the");
      comment.push_back("quadratic term or a thermal lag). The equations:");
      comment.push_back("docs/workflows/export.md, target c; gravcal_correct_sample holds");
      comment.push_back("the thermal lag, as gravcal apply does.");
      result->files = internal::CCorrectorFiles(calibration.corrector, comment);
      break;
    }
  }
  if (options.target != ExportTarget::kC) result->files.push_back({"", text});
  result->message = std::string("exported for ") + ToString(options.target) +
                    (result->dropped.empty() ? "; nothing dropped" : "; with truncation");
  return true;
}

}  // namespace gravcal
