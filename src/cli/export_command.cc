// gravcal export: a calibration written for Kalibr, OpenVINS, ROS, PX4,
// ArduPilot or as C source (io/calibration_export.h). What the target cannot
// hold is said on standard error and in the file. Exit 0 written; 1 bad
// input or a calibration the target cannot take (nothing written).
#include <sys/stat.h>

#include <cstdio>
#include <string>

#include "cli/commands.h"
#include "gravcal/io/calibration_export.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/files.h"
#include "gravcal/io/noise_io.h"

namespace gravcal {
namespace cli {

int RunExport(const ExportArgs& args) {
  std::string calibration_path, error;
  if (!ResolveCalibrationPath(args.calibration, args.stored, &calibration_path, &error)) {
    return Fail(error);
  }
  if (calibration_path.empty()) {
    return Fail("export needs --calibration <calib.json> (or --store DIR --unit SN)");
  }
  ExportOptions options;
  if (!args.to) return Fail("export needs --to <target>, one of " + AcceptedNames(ExportTarget()));
  options.target = *args.to;
  const bool c_target = options.target == ExportTarget::kC;
  if (c_target && args.output_dir.empty()) {
    return Fail("export --to c needs --output-dir <folder> (writes gravcal_correct.h and .c)");
  }
  if (!c_target && args.output.empty()) return Fail("export needs --output <file>");
  LoadedCalibration calibration;
  if (!ReadCalibrationJson(calibration_path, &calibration, &error)) return Fail(error);
  ImuNoise noise;
  if (!args.noise.empty()) {
    if (!ReadNoiseJson(args.noise, &noise, &error)) return Fail(error);
    options.noise = &noise.model;
  }
  options.calibration_name = calibration_path;
  options.accel_device_id = static_cast<int64_t>(args.accel_device_id);
  options.gyro_device_id = static_cast<int64_t>(args.gyro_device_id);
  options.drop_thermal = args.drop_thermal;
  options.ardupilot_imu = args.ardupilot_imu;
  ExportResult result;
  if (!ExportCalibration(calibration, options, &result, &error)) return Fail(error);
  for (const std::string& line : result.dropped) {
    std::fprintf(stderr, "gravcal: export --to %s drops: %s\n", ToString(*args.to), line.c_str());
  }
  if (c_target && !MakeFolders(args.output_dir, &error)) return Fail(error);
  // Every file in place, or none.
  std::vector<FileContents> files;
  std::vector<std::string> written;
  for (const ExportedFile& file : result.files) {
    written.push_back(c_target ? args.output_dir + "/" + file.name : args.output);
    if (written.back() != "-") files.push_back({written.back(), file.text});
  }
  if (!WriteFilesAtomically(files, &error)) return Fail(error);
  for (const ExportedFile& file : result.files) {
    if (!c_target && args.output == "-" && !WriteOutput(args.output, file.text, &error)) {
      return Fail(error);
    }
  }
  std::string names;
  for (const std::string& w : written)
    names += (names.empty() ? "" : " and ") + (w == "-" ? "standard output" : w);
  std::fprintf(stderr, "gravcal: %s; wrote %s\n", result.message.c_str(), names.c_str());
  return 0;
}

}  // namespace cli
}  // namespace gravcal
