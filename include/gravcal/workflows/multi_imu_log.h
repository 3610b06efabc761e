// gravcal/workflows/multi_imu_log.h: the input of a multi-IMU session (issue 38):
// its config (configs/multi_imu.yaml; `imus: [...]`, each IMU with its own
// columns, units, mounting and, optionally, its own log or bag topic) and
// the reading of its logs into one PlateImu per IMU (methods/multi_imu.h).
//
// One table holding every IMU's columns (t, imu0.ax .. imu1.gz) is read
// once and each IMU's columns picked from it by the checked text reader
// (log_reader.h: every error names the file and line); an IMU with its own
// `input` is read from that file (on the same clock); an IMU with a `topic`
// is read from the bag or MCAP file (one sensor_msgs/Imu topic per IMU).
//
// Outputs (docs/data_contract.md, "Multi-IMU assembly"): assembly.json with
// each IMU's rotation to the reference, its sigma and the time offsets; the
// Kalibr IMU chain; PX4's CAL_ACCn_ROT / CAL_GYROn_ROT where a rotation is
// one of PX4's enumerated rotations.
#ifndef GRAVCAL_WORKFLOWS_MULTI_IMU_LOG_H_
#define GRAVCAL_WORKFLOWS_MULTI_IMU_LOG_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/io/files.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/methods/multi_imu.h"
#include "gravcal/simulation/plate_simulator.h"

namespace gravcal {

struct MultiImuLogSpec {
  std::string name;
  // Column names in the file: ax ay az [gx gy gz] (default <name>.ax ...).
  std::vector<std::string> columns;
  // SI per raw unit (m/s^2, rad/s).
  double accel_scale = 1.0;
  double gyro_scale = 1.0;
  // Its own log (same clock), or its bag/MCAP topic; empty = the table.
  std::string input;
  std::string topic;
  // Stated mounting, plate from housing (row-major in the config).
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  // Sample rate written to the Kalibr chain (0 = from the log).
  double update_rate = 0.0;
};

struct MultiImuConfig {
  // `imus: auto`: every <name>.ax, <name>.ay, <name>.az (and <name>.gx ..)
  // of the table's header is an IMU, in header order, with the top-level
  // units (default_*_scale).
  bool auto_imus = false;
  double default_accel_scale = 1.0;
  double default_gyro_scale = 1.0;
  std::vector<MultiImuLogSpec> imus;
  // The reference IMU's name (default the first).
  std::string reference;
  // The table's layout: time column name and scale.
  std::string time_column = "t";
  double time_scale = 1.0;
  MultiImuOptions options;
  // Write the separate calibrations' sigmas next to the joint ones.
  bool output_covariance = true;
  // `gravcal simulate --config <this>`: the plate simulator's options, from
  // the sim_* keys (sim_imus, sim_mounting, sim_permuted_imu,
  // sim_flipped_imu, sim_slip_imu, sim_max_clock_offset,
  // sim_clock_drift_std, sim_hold, sim_turn, sim_rate) and the top-level
  // units (the table is written in them).
  PlateSimulatorOptions simulation;
};

// True when `path` is a YAML file whose top level has the key `imus`.
bool IsMultiImuConfigFile(const std::string& path);

// Loads the config; false with one line naming the file, line and key.
bool LoadMultiImuConfig(const std::string& path, MultiImuConfig* config, std::string* error);
bool ParseMultiImuConfig(const std::string& text, const std::string& name, MultiImuConfig* config,
                         std::string* error);

// Reads every IMU's log: from `input` (the table or the bag) unless the IMU
// names its own. *provenance (when not null) gets the table's. False with
// one line naming the IMU and the file; *imus untouched then.
// With imus: auto, config->imus is filled from the table's header first.
bool ReadMultiImuLogs(MultiImuConfig* config, const std::string& input, std::vector<PlateImu>* imus,
                      CalibrationProvenance* provenance, std::string* error);

// The IMUs of a table header (imus: auto): names with .ax .ay .az columns.
std::vector<MultiImuLogSpec> ImusOfHeader(const std::string& text, double accel_scale,
                                          double gyro_scale);

// The files of one calibrated session: <calibration_prefix><name>.json per
// IMU (the calibration schema, with `provenance`; the prefix "" means
// "<output_dir>/"), and in output_dir assembly.json, kalibr_imu_chain.yaml
// and px4_rotations.params.
std::vector<FileContents> MultiImuSessionFiles(const MultiImuResult& result,
                                               const MultiImuConfig& config,
                                               const std::vector<PlateImu>& imus,
                                               const CalibrationProvenance& provenance,
                                               const std::string& output_dir,
                                               const std::string& calibration_prefix = "");

// assembly.json (docs/data_contract.md).
std::string MultiImuAssemblyToJson(const MultiImuResult& result);

// Kalibr's IMU chain (imu0: T_i_b, time_offset, rostopic, update_rate ...)
// with the rotations (translation zero: the lever arm is not observable,
// said in a comment) and time offsets. `rates` per IMU (Hz).
std::string MultiImuKalibrChain(const MultiImuResult& result, const MultiImuConfig& config,
                                const std::vector<double>& rates);

// PX4 parameters CAL_ACC<n>_ROT and CAL_GYRO<n>_ROT (n the IMU's index)
// where the rotation is within tolerance_deg of one of PX4's enumerated
// rotations; otherwise a comment saying so and the nearest one.
std::string MultiImuPx4Rotations(const MultiImuResult& result, double tolerance_deg);

// The index of PX4's enumerated rotation (src/lib/conversion/rotation.h:
// R = Rz(yaw) Ry(pitch) Rx(roll), sensor to airframe) nearest `rotation`,
// and the angle to it in degrees.
int NearestPx4Rotation(const Eigen::Matrix3d& rotation, double* angle_deg);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_MULTI_IMU_LOG_H_
