// Reading a multi-IMU session and writing its assembly (io/multi_imu_log.h).
#include "gravcal/workflows/multi_imu_log.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "gravcal/io/calibration_io.h"
#include "gravcal/io/files.h"

namespace gravcal {
namespace {

LogReaderOptions ImuReaderOptions(const MultiImuConfig& config, const MultiImuLogSpec& imu) {
  LogReaderOptions o;
  o.format = LogFormat::kCsv;
  o.time_scale = config.time_scale;
  if (config.time_column != "t") o.rename["t"] = config.time_column;
  const char* names[6] = {"ax", "ay", "az", "gx", "gy", "gz"};
  for (size_t j = 0; j < imu.columns.size(); ++j) {
    if (imu.columns[j] != names[j]) o.rename[names[j]] = imu.columns[j];
  }
  o.topic = imu.topic;
  return o;
}

}  // namespace

std::vector<MultiImuLogSpec> ImusOfHeader(const std::string& text, double accel_scale,
                                          double gyro_scale) {
  // The header: the first line that is neither blank nor a comment.
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.size() >= 3 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);
    if (!line.empty() && line[0] != '#') break;
  }
  std::vector<std::string> names;
  std::stringstream cells(line);
  std::string cell;
  while (std::getline(cells, cell, ',')) {
    const size_t a = cell.find_first_not_of(" \t"), b = cell.find_last_not_of(" \t");
    names.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
  }
  auto has = [&](const std::string& n) {
    return std::find(names.begin(), names.end(), n) != names.end();
  };
  std::vector<MultiImuLogSpec> imus;
  for (const std::string& n : names) {
    if (n.size() <= 3 || n.compare(n.size() - 3, 3, ".ax") != 0) continue;
    const std::string prefix = n.substr(0, n.size() - 3);
    if (!has(prefix + ".ay") || !has(prefix + ".az")) continue;
    MultiImuLogSpec spec;
    spec.name = prefix;
    spec.accel_scale = accel_scale;
    spec.gyro_scale = gyro_scale;
    const bool gyro = has(prefix + ".gx") && has(prefix + ".gy") && has(prefix + ".gz");
    for (const char* c : {"ax", "ay", "az", "gx", "gy", "gz"}) {
      if (c[0] == 'g' && !gyro) break;
      spec.columns.push_back(prefix + "." + c);
    }
    imus.push_back(spec);
  }
  return imus;
}

bool ReadMultiImuLogs(MultiImuConfig* config_in, const std::string& input,
                      std::vector<PlateImu>* imus, CalibrationProvenance* provenance,
                      std::string* error) {
  MultiImuConfig& config = *config_in;
  std::vector<PlateImu> out;
  // The table, read once, when some IMU reads from it as text.
  std::string table;
  bool table_read = false;
  if (config.auto_imus) {
    if (input.empty()) {
      *error = "imus: auto needs --input <table with <name>.ax ... columns>";
      return false;
    }
    if (!ReadFileBytes(input, &table, error)) return false;
    table_read = true;
    if (provenance != nullptr) *provenance = LogProvenanceOfBytes(input, table);
    config.imus = ImusOfHeader(table, config.default_accel_scale, config.default_gyro_scale);
    if (config.imus.empty()) {
      *error = input +
               ": imus: auto found no IMU columns (<name>.ax, <name>.ay, <name>.az) in "
               "the header";
      return false;
    }
    int reference = 0;
    for (size_t i = 0; i < config.imus.size(); ++i) {
      if (config.imus[i].name == config.reference) reference = static_cast<int>(i);
    }
    if (!config.reference.empty() && config.imus[reference].name != config.reference) {
      *error = input + ": reference '" + config.reference + "' is not among the table's IMUs";
      return false;
    }
    config.options.reference = reference;
  }
  for (const MultiImuLogSpec& spec : config.imus) {
    PlateImu imu;
    imu.name = spec.name;
    imu.accel_scale = spec.accel_scale;
    imu.gyro_scale = spec.gyro_scale;
    imu.stated_mounting = spec.rotation;
    const LogReaderOptions options = ImuReaderOptions(config, spec);
    std::string why;
    bool ok = false;
    if (!spec.input.empty()) {
      ok = ReadImuLog(spec.input, options, &imu.log, &why);
    } else if (input.empty()) {
      *error = spec.name + ": no log: give --input, or 'input' for this IMU in the config";
      return false;
    } else if (!spec.topic.empty()) {
      ok = ReadImuLog(input, options, &imu.log, &why);
    } else {
      if (!table_read) {
        if (!ReadFileBytes(input, &table, error)) return false;
        table_read = true;
        if (provenance != nullptr) *provenance = LogProvenanceOfBytes(input, table);
      }
      ok = ParseImuLog(table, input, options, &imu.log, &why);
    }
    if (!ok) {
      *error = spec.name + ": " + why;
      return false;
    }
    out.push_back(std::move(imu));
  }
  if (provenance != nullptr && !table_read && !input.empty()) {
    std::string why;
    if (!LogProvenance(input, provenance, &why)) *provenance = CalibrationProvenance();
  }
  *imus = std::move(out);
  return true;
}

namespace {

nlohmann::json MatrixJson(const Eigen::Matrix3d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

// A number or null (NaN: undetermined).
nlohmann::json Value(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); }

}  // namespace

std::vector<FileContents> MultiImuSessionFiles(const MultiImuResult& result,
                                               const MultiImuConfig& config,
                                               const std::vector<PlateImu>& imus,
                                               const CalibrationProvenance& provenance,
                                               const std::string& output_dir,
                                               const std::string& calibration_prefix) {
  const std::string prefix = calibration_prefix.empty() ? output_dir + "/" : calibration_prefix;
  std::vector<FileContents> files;
  std::vector<double> rates;
  for (size_t i = 0; i < result.imus.size(); ++i) {
    Calibration c = result.imus[i].calibration;
    c.provenance = provenance;
    files.push_back(
        {prefix + result.imus[i].name + ".json", CalibrationToJson(c, config.output_covariance)});
    const ImuLog& log = imus[i].log;
    double rate = i < config.imus.size() ? config.imus[i].update_rate : 0.0;
    if (!(rate > 0.0) && log.size() > 1) rate = (log.size() - 1) / (log.t.back() - log.t.front());
    rates.push_back(rate);
  }
  files.push_back({output_dir + "/assembly.json", MultiImuAssemblyToJson(result)});
  files.push_back(
      {output_dir + "/kalibr_imu_chain.yaml", MultiImuKalibrChain(result, config, rates)});
  files.push_back({output_dir + "/px4_rotations.params",
                   MultiImuPx4Rotations(result, config.options.permutation_tolerance_deg)});
  return files;
}

std::string MultiImuAssemblyToJson(const MultiImuResult& result) {
  nlohmann::json j;
  j["format"] = "gravcal multi-IMU assembly";
  j["version"] = 1;
  j["message"] = result.message;
  j["reference"] = result.imus.empty() ? "" : result.imus[result.reference].name;
  j["poses"] = result.poses;
  j["turns"] = result.turns;
  j["rotation_convention"] =
      "rotation maps the IMU's orthogonalised accelerometer frame into the reference's: "
      "v_ref = rotation * v_imu; sigma is the rotation vector e of rotation_true = rotation * "
      "Exp(e), rad";
  j["time_offset_convention"] =
      "time_offset: the IMU's stamps are late by this much against the reference's, s, at the "
      "reference's first stamp; clock_drift: its change per second";
  nlohmann::json list = nlohmann::json::array();
  for (const PlateImuResult& r : result.imus) {
    nlohmann::json imu;
    imu["name"] = r.name;
    imu["rotation"] = MatrixJson(r.rotation);
    imu["rotation_sigma"] = {Value(r.rotation_std[0]), Value(r.rotation_std[1]),
                             Value(r.rotation_std[2])};
    nlohmann::json cov = nlohmann::json::array();
    for (int a = 0; a < 3; ++a) {
      cov.push_back({Value(r.rotation_covariance(a, 0)), Value(r.rotation_covariance(a, 1)),
                     Value(r.rotation_covariance(a, 2))});
    }
    imu["rotation_covariance"] = cov;
    imu["time_offset"] = Value(r.time_offset);
    imu["time_offset_sigma"] = Value(r.time_offset_std);
    imu["clock_drift"] = Value(r.clock_drift);
    imu["clock_drift_sigma"] = Value(r.clock_drift_std);
    imu["timed_turns"] = r.timed_turns;
    imu["accel_residual_rms"] = Value(r.accel_residual_rms);
    imu["turn_residual_rms_deg"] = Value(r.turn_residual_deg);
    imu["variance_factors"] = {
        {"accel_poses", r.accel_factor}, {"gyro_poses", r.gyro_factor}, {"turns", r.turn_factor}};
    if (std::isfinite(r.up_offset)) {
      imu["up_offset"] = r.up_offset;
      imu["up_offset_sigma"] = r.up_offset_std;
    }
    if (!r.separate_std.empty() && !r.joint_std.empty()) {
      nlohmann::json gain;
      gain["names"] = {"bias_x", "bias_y", "bias_z", "u_xx",        "u_xy",        "u_xz",
                       "u_yy",   "u_yz",   "u_zz",   "gyro_bias_x", "gyro_bias_y", "gyro_bias_z",
                       "m_xx",   "m_xy",   "m_xz",   "m_yx",        "m_yy",        "m_yz",
                       "m_zx",   "m_zy",   "m_zz"};
      nlohmann::json sep = nlohmann::json::array(), joint = nlohmann::json::array();
      for (size_t k = 0; k < r.joint_std.size(); ++k) {
        sep.push_back(Value(k < r.separate_std.size() ? r.separate_std[k] : NAN));
        joint.push_back(Value(r.joint_std[k]));
      }
      gain["separate_sigma"] = sep;
      gain["joint_sigma"] = joint;
      imu["joint_vs_separate"] = gain;
    }
    list.push_back(imu);
  }
  j["imus"] = list;
  nlohmann::json cov = nlohmann::json::array();
  for (int a = 0; a < result.time_offset_covariance.rows(); ++a) {
    nlohmann::json row = nlohmann::json::array();
    for (int b = 0; b < result.time_offset_covariance.cols(); ++b) {
      row.push_back(Value(result.time_offset_covariance(a, b)));
    }
    cov.push_back(row);
  }
  j["time_offset_covariance"] = cov;
  j["undetermined"] = result.undetermined;
  j["warnings"] = result.warnings;
  j["variance_factors"] = {{"accel_poses", result.accel_factor},
                           {"gyro_poses", result.gyro_factor},
                           {"turns", result.turn_factor}};
  return j.dump(2) + "\n";
}

std::string MultiImuKalibrChain(const MultiImuResult& result, const MultiImuConfig& config,
                                const std::vector<double>& rates) {
  std::ostringstream s;
  s.precision(12);
  s << "# Kalibr IMU chain written by gravcal (issue 38): T_i_b is the rotation from the\n"
       "# reference IMU ('body', "
    << (result.imus.empty() ? "" : result.imus[result.reference].name)
    << ") into each IMU; its translation is zero because\n"
       "# a lever arm is not observable from gravity and slow turns. time_offset: the\n"
       "# gyroscope's offset to the reference (s). Noise densities are not written: give\n"
       "# them from gravcal noise.\n";
  for (size_t i = 0; i < result.imus.size(); ++i) {
    const PlateImuResult& r = result.imus[i];
    // T_i_b maps body (reference) coordinates into IMU i's: R^T.
    const Eigen::Matrix3d t = r.rotation.transpose();
    s << "imu" << i << ":\n  T_i_b:\n";
    for (int row = 0; row < 3; ++row) {
      s << "    - [" << t(row, 0) << ", " << t(row, 1) << ", " << t(row, 2) << ", 0.0]\n";
    }
    s << "    - [0.0, 0.0, 0.0, 1.0]\n";
    s << "  model: calibrated\n";
    const std::string topic = i < config.imus.size() && !config.imus[i].topic.empty()
                                  ? config.imus[i].topic
                                  : "/" + r.name;
    s << "  rostopic: " << topic << "\n";
    s << "  time_offset: " << (std::isfinite(r.time_offset) ? r.time_offset : 0.0) << "\n";
    s << "  update_rate: " << (i < rates.size() ? rates[i] : 0.0) << "\n";
  }
  return s.str();
}

namespace {

struct Px4Entry {
  int roll, pitch, yaw;
};
// PX4's enum Rotation (src/lib/conversion/rotation.h), in order: roll,
// pitch, yaw in degrees.
constexpr Px4Entry kPx4Rotations[] = {
    {0, 0, 0},     {0, 0, 45},    {0, 0, 90},    {0, 0, 135},   {0, 0, 180},   {0, 0, 225},
    {0, 0, 270},   {0, 0, 315},   {180, 0, 0},   {180, 0, 45},  {180, 0, 90},  {180, 0, 135},
    {0, 180, 0},   {180, 0, 225}, {180, 0, 270}, {180, 0, 315}, {90, 0, 0},    {90, 0, 45},
    {90, 0, 90},   {90, 0, 135},  {270, 0, 0},   {270, 0, 45},  {270, 0, 90},  {270, 0, 135},
    {0, 90, 0},    {0, 270, 0},   {0, 180, 90},  {0, 180, 270}, {90, 90, 0},   {180, 90, 0},
    {270, 90, 0},  {90, 180, 0},  {270, 180, 0}, {90, 270, 0},  {180, 270, 0}, {270, 270, 0},
    {90, 180, 90}, {90, 0, 270},  {90, 68, 293}, {0, 315, 0},   {90, 315, 0},  {270, 0, 180},
    {270, 0, 270}, {0, 90, 180},  {0, 9, 180},   {0, 45, 0},    {270, 0, 225}, {270, 0, 315}};

Eigen::Matrix3d Px4Matrix(const Px4Entry& e) {
  const double d = M_PI / 180.0;
  return (Eigen::AngleAxisd(e.yaw * d, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(e.pitch * d, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(e.roll * d, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace

int NearestPx4Rotation(const Eigen::Matrix3d& rotation, double* angle_deg) {
  int best = 0;
  double best_angle = 1e300;
  const int n = static_cast<int>(sizeof(kPx4Rotations) / sizeof(kPx4Rotations[0]));
  for (int k = 0; k < n; ++k) {
    const Eigen::Matrix3d d = Px4Matrix(kPx4Rotations[k]).transpose() * rotation;
    const double a = std::acos(std::clamp((d.trace() - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / M_PI;
    if (a < best_angle) {
      best_angle = a;
      best = k;
    }
  }
  if (angle_deg != nullptr) *angle_deg = best_angle;
  return best;
}

std::string MultiImuPx4Rotations(const MultiImuResult& result, double tolerance_deg) {
  std::ostringstream s;
  s << "# PX4 sensor rotations written by gravcal (issue 38): CAL_ACCn_ROT and CAL_GYROn_ROT\n"
       "# turn IMU n into the reference's frame ("
    << (result.imus.empty() ? "" : result.imus[result.reference].name)
    << "), which PX4 takes as the board's; n is the\n"
       "# IMU's place in the config. PX4 applies CAL_*_ROT to external sensors only;\n"
       "# internal ones follow SENS_BOARD_ROT. A rotation that is not one of PX4's\n"
       "# enumerated rotations has no parameter: the line says so.\n";
  for (size_t i = 0; i < result.imus.size(); ++i) {
    const PlateImuResult& r = result.imus[i];
    double angle = 0.0;
    const int k = NearestPx4Rotation(r.rotation, &angle);
    s.setf(std::ios::fixed);
    s.precision(2);
    if (angle <= tolerance_deg) {
      s << "CAL_ACC" << i << "_ROT " << k << "\nCAL_GYRO" << i << "_ROT " << k << "   # " << r.name
        << ": " << angle << " deg from PX4 rotation " << k << "\n";
    } else {
      s << "# " << r.name << ": not one of PX4's enumerated rotations (nearest: " << k << ", "
        << angle << " deg off); no CAL_ACC" << i << "_ROT written\n";
    }
  }
  return s.str();
}

}  // namespace gravcal
