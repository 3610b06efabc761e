// gravcal calibrate with a multi-IMU config (configs/multi_imu.yaml, issue
// 38): every IMU's calibration, their assembly and its exports, in one
// folder.
#include <cmath>
#include <cstdio>
#include <sstream>

#include "cli/commands.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/files.h"
#include "gravcal/methods/multi_imu.h"
#include "gravcal/workflows/multi_imu_log.h"

namespace gravcal {
namespace cli {
namespace {

std::string Html(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<') {
      out += "&lt;";
    } else if (c == '>') {
      out += "&gt;";
    } else if (c == '&') {
      out += "&amp;";
    } else {
      out += c;
    }
  }
  return out;
}

std::string Cell(double value, double sigma, const char* format) {
  char v[64], s[64];
  std::snprintf(v, sizeof(v), format, value);
  if (!std::isfinite(sigma)) return std::string(v) + " (undetermined)";
  std::snprintf(s, sizeof(s), format, sigma);
  return std::string(v) + " &plusmn; " + s;
}

// The IMUs side by side: residuals, rotation to the reference, time offset,
// and the sigma gain of the joint fit.
std::string ReportHtml(const MultiImuResult& r) {
  std::ostringstream h;
  h << "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>gravcal multi-IMU</title>"
       "<style>td,th{padding:2px 8px;border:1px solid #ccc;font-family:monospace}"
       "table{border-collapse:collapse}</style></head><body>\n";
  h << "<h1>Multi-IMU calibration</h1><p>" << Html(r.message) << "</p>\n<table><tr><th></th>";
  for (const PlateImuResult& imu : r.imus) h << "<th>" << Html(imu.name) << "</th>";
  h << "</tr>\n";
  auto row = [&](const std::string& name, auto cell) {
    h << "<tr><th>" << name << "</th>";
    for (const PlateImuResult& imu : r.imus) h << "<td>" << cell(imu) << "</td>";
    h << "</tr>\n";
  };
  row("pose rows rms (m/s&sup2;)",
      [](const PlateImuResult& i) { return Cell(i.accel_residual_rms, 0.0, "%.2e").substr(0, 8); });
  row("turn rows rms (deg)", [](const PlateImuResult& i) {
    char b[32];
    std::snprintf(b, sizeof(b), "%.4f", i.turn_residual_deg);
    return std::string(b);
  });
  for (int r0 = 0; r0 < 3; ++r0) {
    row("rotation row " + std::to_string(r0), [r0](const PlateImuResult& i) {
      char b[96];
      std::snprintf(b, sizeof(b), "%+.5f %+.5f %+.5f", i.rotation(r0, 0), i.rotation(r0, 1),
                    i.rotation(r0, 2));
      return std::string(b);
    });
  }
  row("rotation sigma (deg)", [](const PlateImuResult& i) {
    char b[96];
    const Eigen::Vector3d s = i.rotation_std * 180.0 / M_PI;
    std::snprintf(b, sizeof(b), "%.4f %.4f %.4f", s.x(), s.y(), s.z());
    return std::string(b);
  });
  row("time offset (ms)", [](const PlateImuResult& i) {
    return Cell(i.time_offset * 1e3, i.time_offset_std * 1e3, "%.3f");
  });
  row("clock drift (ppm)", [](const PlateImuResult& i) {
    return Cell(i.clock_drift * 1e6, i.clock_drift_std * 1e6, "%.1f");
  });
  row("accel bias", [](const PlateImuResult& i) {
    const Calibration& c = i.calibration;
    return Cell(c.accel.model.bias.x(), c.accel.bias_std.x(), "%.4g") + "<br>" +
           Cell(c.accel.model.bias.y(), c.accel.bias_std.y(), "%.4g") + "<br>" +
           Cell(c.accel.model.bias.z(), c.accel.bias_std.z(), "%.4g");
  });
  row("largest sigma gain, joint vs separate", [](const PlateImuResult& i) {
    double gain = NAN;
    for (size_t k = 0; k < i.joint_std.size() && k < i.separate_std.size(); ++k) {
      const double g = i.separate_std[k] / i.joint_std[k];
      if (std::isfinite(g) && !(g <= gain)) gain = g;
    }
    char b[32];
    std::snprintf(b, sizeof(b), "%.2f x", gain);
    return std::string(b);
  });
  h << "</table>\n";
  if (!r.warnings.empty()) {
    h << "<h2>Checks</h2><ul>";
    for (const std::string& w : r.warnings) h << "<li>" << Html(w) << "</li>";
    h << "</ul>\n";
  }
  h << "<h2>Not determined</h2><ul>";
  for (const std::string& u : r.undetermined) h << "<li>" << Html(u) << "</li>";
  h << "</ul></body></html>\n";
  return h.str();
}

}  // namespace

int RunMultiImuCalibrate(const std::string& config_path, const std::string& input,
                         const std::string& output_dir, const std::string& report,
                         bool has_overrides) {
  if (output_dir.empty()) {
    return Fail(
        "calibrate with a multi-IMU config needs --output-dir <folder> (one JSON per IMU "
        "and assembly.json)");
  }
  if (has_overrides) {
    return Fail(
        "calibrate with a multi-IMU config: config keys are not taken as flags; set them "
        "in " +
        config_path);
  }
  std::string error;
  MultiImuConfig config;
  if (!LoadMultiImuConfig(config_path, &config, &error)) return Fail(error);
  std::vector<PlateImu> imus;
  CalibrationProvenance provenance;
  if (!ReadMultiImuLogs(&config, input, &imus, &provenance, &error)) return Fail(error);
  MultiImuResult result;
  if (!CalibrateMultiImu(imus, config.options, &result)) return Fail(result.message);
  for (const std::string& w : result.warnings) {
    std::fprintf(stderr, "gravcal: warning: %s\n", w.c_str());
  }
  if (!MakeFolders(output_dir, &error)) return Fail(error);
  std::vector<FileContents> files =
      MultiImuSessionFiles(result, config, imus, provenance, output_dir);
  if (!report.empty()) files.push_back({report, ReportHtml(result)});
  if (!WriteFilesAtomically(files, &error)) return Fail(error);
  for (const PlateImuResult& r : result.imus) {
    std::fprintf(
        stderr, "gravcal: %s: time offset %s, rotation sigma %.4f %.4f %.4f deg\n", r.name.c_str(),
        std::isfinite(r.time_offset_std) ? (std::to_string(r.time_offset * 1e3) + " +- " +
                                            std::to_string(r.time_offset_std * 1e3) + " ms")
                                               .c_str()
                                         : "undetermined",
        r.rotation_std.x() * 180 / M_PI, r.rotation_std.y() * 180 / M_PI,
        r.rotation_std.z() * 180 / M_PI);
  }
  std::fprintf(stderr, "gravcal: %s; wrote %zu files to %s\n", result.message.c_str(), files.size(),
               output_dir.c_str());
  return 0;
}

}  // namespace cli
}  // namespace gravcal
