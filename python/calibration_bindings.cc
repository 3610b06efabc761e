// gravcal._gravcal: the calibration Python holds, calibrate, apply and
// export, and their bindings.
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "gravcal/gravcal.h"
#include "gravcal/io/calibration_models.h"
#include "gravcal/io/files.h"

namespace gravcal {
namespace python {
namespace {

// ---------------------------------------------------------------------------
// Calibration: the library's result, or a calibration file's JSON text, and
// the models `apply` and `export` use. A result made here reaches its models
// directly (io/calibration_models.h); JSON text is made only when asked for
// (to_json, to_dict, write) and parsed only for a file's text.

// How many times a calibration was turned into JSON text or parsed back
// (the Python tests check that calibrate, apply and export make none).
std::atomic<int> json_conversions{0};

}  // namespace

PyCalibration PyCalibration::FromText(const std::string& text, const std::string& name) {
  PyCalibration c;
  c.json = text;
  c.has_json = true;
  c.name = name;
  c.Models();
  return c;
}

std::unique_ptr<PyCalibration> PyCalibration::FromResult(std::shared_ptr<const Calibration> result,
                                                         bool include_covariance,
                                                         const std::string& name) {
  auto c = std::make_unique<PyCalibration>();
  c->result = std::move(result);
  c->include_covariance = include_covariance;
  c->name = name;
  return c;
}

const std::string& PyCalibration::Json() const {
  if (!has_json) {
    json = CalibrationToJson(*result, include_covariance);
    has_json = true;
    ++json_conversions;
  }
  return json;
}

const LoadedCalibration& PyCalibration::Models() const {
  if (!parsed) {
    std::string error;
    if (result != nullptr) {
      Check(ModelsFromCalibration(*result, name, &models, &error), error);
    } else {
      Check(CalibrationFromJson(json, name, &models, &error), error);
      ++json_conversions;
    }
    parsed = true;
  }
  return models;
}

namespace {

PyCalibration CalibrationFromFile(const std::string& path) {
  std::string text, error;
  Check(ReadFileBytes(path, &text, &error), error);
  return PyCalibration::FromText(text, path);
}

void WriteCalibration(const PyCalibration& c, const std::string& path) {
  std::string error;
  Check(WriteFileAtomically(path, c.Json(), &error), error);
}

// Applies everything the calibration holds (core/imu_corrector.h, row by
// row with ImuCorrector::CorrectRow, as `gravcal apply` does) to every row: accel (N, 3) raw ->
// m/s^2 and, when given, gyro (N, 3) raw -> rad/s with the corrected accel for the g-sensitivity.
// temp (N) and t (N) feed the temperature and time terms and are required by name when the
// calibration has such terms.
py::tuple ApplyCalibration(const PyCalibration& c, const py::object& accel, const py::object& gyro,
                           const py::object& temp, const py::object& t) {
  std::vector<Eigen::Vector3d> a = ToVectors(accel, "accel", -1);
  const py::ssize_t n = static_cast<py::ssize_t>(a.size());
  const ImuCorrector& corrector = c.Models().corrector;
  std::vector<Eigen::Vector3d> w;
  if (!gyro.is_none()) {
    Check(corrector.has_gyro, "gyro: the calibration has no gyroscope model");
    w = ToVectors(gyro, "gyro", n, "accel");
  }
  Check(!corrector.RequiresTemperature() || !temp.is_none(),
        "temp: the calibration has temperature effects and needs the temperature of every row");
  Check(!corrector.RequiresTime() || !t.is_none(),
        "t: the calibration has time (drift) effects and needs the time of every row");
  std::vector<double> temperature =
      temp.is_none() ? std::vector<double>(a.size(), NAN) : ToScalars(temp, "temp", n, "accel");
  std::vector<double> time =
      t.is_none() ? std::vector<double>(a.size(), 0.0) : ToScalars(t, "t", n, "accel");
  for (const auto* v : {&a, &w}) {
    for (size_t i = 0; i < v->size(); ++i) {
      Check((*v)[i].allFinite(), std::string(v == &a ? "accel" : "gyro") + ": row " +
                                     std::to_string(i) + " is not finite");
    }
  }
  DoubleArray a_out({n, static_cast<py::ssize_t>(3)});
  DoubleArray w_out({static_cast<py::ssize_t>(w.size()), static_cast<py::ssize_t>(3)});
  size_t bad_row = a.size();
  bool overflow = false;
  {
    py::gil_scoped_release release;
    double* ao = a_out.mutable_data();
    double* wo = w_out.mutable_data();
    for (size_t i = 0; i < a.size(); ++i) {
      if (!corrector.CorrectRow(temperature[i], time[i], &a[i], w.empty() ? nullptr : &w[i])) {
        bad_row = i;
        break;
      }
      // As `gravcal apply`: nothing that is not a number is returned.
      if (!a[i].allFinite() || (!w.empty() && !w[i].allFinite())) {
        bad_row = i;
        overflow = true;
        break;
      }
      Eigen::Map<Eigen::Vector3d>(ao + 3 * i) = a[i];
      if (!w.empty()) Eigen::Map<Eigen::Vector3d>(wo + 3 * i) = w[i];
    }
  }
  Check(bad_row == a.size(),
        "accel: row " + std::to_string(bad_row) +
            (overflow ? ": the corrected sample is not finite (the reading times the calibration "
                        "overflows)"
                      : ": the quadratic term has no real root (reading outside the calibrated "
                        "range)"));
  return py::make_tuple(a_out, gyro.is_none() ? py::object(py::none()) : py::object(w_out));
}

// RunCalibration, as `gravcal calibrate` runs it, into the result Python
// will hold; `provenance` names the log file when there is one.
std::unique_ptr<PyCalibration> Run(const Config& config, const PipelineInput& input,
                                   const CalibrationProvenance* provenance = nullptr) {
  auto c = std::make_shared<Calibration>();
  bool ok;
  {
    py::gil_scoped_release release;
    ok = RunCalibration(config, input, c.get());
  }
  Check(ok, c->message);
  if (provenance != nullptr) c->provenance = *provenance;
  return PyCalibration::FromResult(std::move(c), config.output_covariance, input.source);
}

// On a log in memory: the log itself when there is no side input, else a
// copy with the side files. RunCalibration checks the config first.
std::unique_ptr<PyCalibration> Calibrate(const Config& config, const LogHandle& log,
                                         const std::string& attitudes, const std::string& segments,
                                         const std::string& noise) {
  if (attitudes.empty() && segments.empty() && noise.empty()) return Run(config, *log);
  PipelineInput input = *log;
  input.attitudes_path = attitudes;
  input.segments_path = segments;
  input.noise_path = noise;
  return Run(config, input);
}

// On a log file, read straight into the pipeline's input, with the file's
// provenance, as `gravcal calibrate --input` does (the config checked
// first, so that its errors come before the file's).
std::unique_ptr<PyCalibration> CalibrateFile(const Config& config, const std::string& path,
                                             const std::string& attitudes,
                                             const std::string& segments,
                                             const std::string& noise) {
  CheckConfig(config);
  PipelineInput input;
  input.source = path;
  input.attitudes_path = attitudes;
  input.segments_path = segments;
  input.noise_path = noise;
  CalibrationProvenance provenance;
  std::string error;
  bool ok;
  {
    py::gil_scoped_release release;
    ok = ReadImuLog(path, config.input, &input.log, &provenance, &error);
  }
  Check(ok, error);
  return Run(config, input, &provenance);
}

// `gravcal export`: the files' names and texts, what the target drops, the
// truncation's residuals.
py::dict Export(const PyCalibration& c, const std::string& to, const std::string& name,
                const std::string& noise_path, const std::string& noise_text,
                uint64_t accel_device_id, uint64_t gyro_device_id, bool drop_thermal) {
  ExportOptions options;
  options.accel_device_id = static_cast<int64_t>(accel_device_id);
  options.gyro_device_id = static_cast<int64_t>(gyro_device_id);
  options.drop_thermal = drop_thermal;
  std::string error;
  Check(ParseName("to", to, &options.target, &error), error);
  ImuNoise noise;
  if (ReadNoise(noise_path, noise_text, &noise)) options.noise = &noise.model;
  options.calibration_name = name.empty() ? c.name : name;
  ExportResult result;
  Check(ExportCalibration(c.Models(), options, &result, &error), error);
  py::list files;
  for (const ExportedFile& f : result.files) {
    py::dict file;
    file["name"] = f.name;
    file["text"] = f.text;
    files.append(file);
  }
  py::dict d;
  d["files"] = files;
  d["dropped"] = result.dropped;
  d["full_rms"] = result.full_rms;
  d["truncated_rms"] = result.truncated_rms;
  d["message"] = result.message;
  return d;
}

// CPU seconds of the calling thread (the library is single-threaded here:
// Ceres runs with num_threads 1), which a loaded machine does not inflate
// the way it does wall time.
double ThreadCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// For benchmarks/python_overhead.py: CPU seconds per call of a C++ user's
// code doing what the Python call does, `repeats` calls: on `path`,
// ReadImuLog (with the provenance, one read) and RunCalibration (as
// `gravcal calibrate`);
// with an empty path, RunCalibration on the log in memory.
double TimeCalibrate(const Config& config, const LogHandle& log, const std::string& path,
                     int repeats) {
  py::gil_scoped_release release;
  const double start = ThreadCpuSeconds();
  for (int i = 0; i < repeats; ++i) {
    Calibration c;
    if (path.empty()) {
      RunCalibration(config, *log, &c);
      continue;
    }
    PipelineInput input;
    input.source = path;
    CalibrationProvenance provenance;
    std::string error;
    if (ReadImuLog(path, config.input, &input.log, &provenance, &error) &&
        RunCalibration(config, input, &c)) {
      c.provenance = provenance;
    }
  }
  return (ThreadCpuSeconds() - start) / std::max(repeats, 1);
}

}  // namespace

void BindCalibration(py::module_& m) {
  py::class_<PyCalibration>(m, "Calibration")
      .def_property_readonly("json", &PyCalibration::Json)
      .def_property_readonly("has_gyro",
                             [](const PyCalibration& c) { return c.Models().corrector.has_gyro; })
      .def_static("from_file", &CalibrationFromFile)
      .def_static("from_text",
                  [](const std::string& text, const std::string& name) {
                    return PyCalibration::FromText(text, name);
                  })
      .def("write", &WriteCalibration)
      .def("report",
           [](const PyCalibration& c, bool full) {
             Check(c.result != nullptr,
                   c.name + ": a calibration read from JSON has no report (only a result has)");
             return full ? c.result->FullReport() : c.result->BriefReport();
           })
      .def("apply", &ApplyCalibration, py::arg("accel"), py::arg("gyro"), py::arg("temp"),
           py::arg("t"));
  m.def("_json_conversions", [] { return json_conversions.load(); });
  m.def("calibrate", &Calibrate, py::arg("config"), py::arg("log"), py::arg("attitudes"),
        py::arg("segments"), py::arg("noise"));
  m.def("calibrate_file", &CalibrateFile, py::arg("config"), py::arg("path"), py::arg("attitudes"),
        py::arg("segments"), py::arg("noise"));
  m.def("export", &Export, py::arg("calibration"), py::arg("to"), py::arg("name"),
        py::arg("noise_path"), py::arg("noise_text"), py::arg("accel_device_id") = 0,
        py::arg("gyro_device_id") = 0, py::arg("drop_thermal") = false);
  m.def("_time_calibrate", &TimeCalibrate, py::arg("config"), py::arg("log"), py::arg("path"),
        py::arg("repeats"));
}

}  // namespace python
}  // namespace gravcal
