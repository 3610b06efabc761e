// gravcal._gravcal: the Python extension module, a thin layer over the
// public C++ API (include/gravcal/). Arrays cross as NumPy arrays; results
// cross as the library's own JSON text (the calibration JSON, truth.json,
// noise.json, discovery.json), so the Python objects and the CLI's files are
// the same numbers by construction. No calibration logic lives here: each
// function converts its arguments, calls the library (without the GIL for
// anything that can take long) and turns a false return into gravcal.Error
// with the library's one-line message. The Pythonic surface (keyword
// arguments, pandas, attribute access) is python/gravcal/__init__.py.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "gravcal/gravcal.h"

namespace py = pybind11;

namespace gravcal {
namespace python {
namespace {

// Raised as gravcal.Error (a ValueError) with the library's message.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void Check(bool ok, const std::string& message) {
  if (!ok) throw Error(message);
}

// ImuLog stores its 3-vectors back to back: an (N, 3) array of doubles.
static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "Vector3d must be unpadded");

using Keys = std::vector<std::pair<std::string, std::string>>;

// The configuration: a YAML file (optional) and then keys with values
// written as YAML, in order, exactly as `gravcal <command> --config path
// --key value` builds it.
Config MakeConfig(const std::string& path, const Keys& keys) {
  Config config;
  std::string error;
  if (!path.empty()) Check(LoadConfigFile(path, &config, &error), error);
  for (const auto& [key, value] : keys) Check(SetConfigValue(key, value, &config, &error), error);
  return config;
}

Config WithKeys(const Config& base, const Keys& keys) {
  Config config = base;
  std::string error;
  for (const auto& [key, value] : keys) Check(SetConfigValue(key, value, &config, &error), error);
  return config;
}

void CheckConfig(const Config& config) {
  std::string error;
  Check(config.IsValid(&error), error);
}

// ---------------------------------------------------------------------------
// Arrays.

// A read-only NumPy view of memory owned by `owner` (kept alive by it).
py::array View(const double* data, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides,
               py::handle owner) {
  py::array a(py::dtype::of<double>(), std::move(shape), std::move(strides), data, owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::object Vectors(const std::vector<Eigen::Vector3d>& v, py::handle owner) {
  if (v.empty()) return py::none();
  return View(v.front().data(), {static_cast<py::ssize_t>(v.size()), 3},
              {3 * sizeof(double), sizeof(double)}, owner);
}

py::object Scalars(const std::vector<double>& v, py::handle owner) {
  if (v.empty()) return py::none();
  return View(v.data(), {static_cast<py::ssize_t>(v.size())}, {sizeof(double)}, owner);
}

std::string ShapeText(const py::array& a) {
  std::string text = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) {
    text += (i ? ", " : "") + std::to_string(a.shape(i));
  }
  return text + (a.ndim() == 1 ? ",)" : ")");
}

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// `obj` as a C-contiguous float64 array (copied only when it is not one).
DoubleArray AsDoubles(const py::object& obj, const char* name) {
  DoubleArray a = DoubleArray::ensure(obj);
  if (!a) {
    PyErr_Clear();
    throw Error(std::string(name) + ": not an array of numbers");
  }
  return a;
}

// "accel: 9 samples, but t has 10".
std::string LengthText(const char* name, py::ssize_t got, const char* reference, py::ssize_t rows) {
  return std::string(name) + ": " + std::to_string(got) + " samples, but " + reference + " has " +
         std::to_string(rows);
}

// An (N, 3) array into 3-vectors; `rows` = N expected (the length of
// `reference`), or -1 for any.
std::vector<Eigen::Vector3d> ToVectors(const py::object& obj, const char* name, py::ssize_t rows,
                                       const char* reference = "t") {
  const DoubleArray a = AsDoubles(obj, name);
  if (a.ndim() != 2 || a.shape(1) != 3) {
    throw Error(std::string(name) + ": expected an array of shape (N, 3), got shape " +
                ShapeText(a));
  }
  if (rows >= 0 && a.shape(0) != rows) {
    throw Error(LengthText(name, a.shape(0), reference, rows));
  }
  std::vector<Eigen::Vector3d> out(a.shape(0));
  if (!out.empty()) std::copy(a.data(), a.data() + 3 * out.size(), out.front().data());
  return out;
}

std::vector<double> ToScalars(const py::object& obj, const char* name, py::ssize_t rows,
                              const char* reference = "t") {
  const DoubleArray a = AsDoubles(obj, name);
  if (a.ndim() != 1) {
    throw Error(std::string(name) + ": expected an array of shape (N,), got shape " + ShapeText(a));
  }
  if (rows >= 0 && a.shape(0) != rows) {
    throw Error(LengthText(name, a.shape(0), reference, rows));
  }
  return std::vector<double>(a.data(), a.data() + a.shape(0));
}

// A Python gravcal.Log is a PipelineInput holding the log (source = the
// log's source, no side input), never changed once made: calibrate hands it
// to RunCalibration as it is (no copy of the samples), any number of
// threads may read it at once, and NumPy views of its vectors stay valid.
using LogHandle = std::shared_ptr<PipelineInput>;

LogHandle WrapLog(ImuLog log) {
  auto input = std::make_shared<PipelineInput>();
  input->source = log.source;
  input->log = std::move(log);
  return input;
}

// A log from arrays: t (N,), accel (N, 3), optional gyro (N, 3) and temp
// (N,). ImuLog::Validate names the first bad sample (NaN, time that does not
// increase).
LogHandle MakeLog(const py::object& t, const py::object& accel, const py::object& gyro,
                  const py::object& temp, const std::string& source) {
  ImuLog log;
  log.source = source;
  log.t = ToScalars(t, "t", -1);
  const py::ssize_t n = static_cast<py::ssize_t>(log.t.size());
  log.accel = ToVectors(accel, "accel", n);
  if (!gyro.is_none()) log.gyro = ToVectors(gyro, "gyro", n);
  if (!temp.is_none()) log.temperature = ToScalars(temp, "temp", n);
  std::string error;
  Check(log.Validate(&error), error);
  return WrapLog(std::move(log));
}

LogHandle ReadLog(const std::string& path, const Config& config) {
  ImuLog log;
  std::string error;
  bool ok;
  {
    py::gil_scoped_release release;
    ok = ReadImuLog(path, config.input, &log, &error);
  }
  Check(ok, error);
  return WrapLog(std::move(log));
}

// ---------------------------------------------------------------------------
// Calibration: the calibration JSON text (what `gravcal calibrate` writes)
// and the models read back from it (what `gravcal apply` uses).

struct PyCalibration {
  // The library's result, when made here (null when read from a file).
  std::shared_ptr<const Calibration> result;
  bool include_covariance = true;
  std::string name;
  // The JSON text (built from `result` on first use) and the models read
  // back from it, as ReadCalibrationJson would (on first apply).
  mutable std::string json;
  mutable bool has_json = false;
  mutable bool parsed = false;
  mutable LoadedCalibration models;

  // A file's text, checked at once.
  static PyCalibration FromText(const std::string& text, const std::string& name) {
    PyCalibration c;
    c.json = text;
    c.has_json = true;
    c.name = name;
    c.Models();
    return c;
  }

  // Held as made: results are handed to Python without a copy or a move.
  static std::unique_ptr<PyCalibration> FromResult(std::shared_ptr<const Calibration> result,
                                                   bool include_covariance,
                                                   const std::string& name) {
    auto c = std::make_unique<PyCalibration>();
    c->result = std::move(result);
    c->include_covariance = include_covariance;
    c->name = name;
    return c;
  }

  const std::string& Json() const {
    if (!has_json) {
      json = CalibrationToJson(*result, include_covariance);
      has_json = true;
    }
    return json;
  }

  const LoadedCalibration& Models() const {
    if (!parsed) {
      std::string error;
      Check(CalibrationFromJson(Json(), name, &models, &error), error);
      parsed = true;
    }
    return models;
  }
};

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
    ok = ReadImuLog(path, config.input, &input.log, &error) &&
         LogProvenance(path, &provenance, &error);
  }
  Check(ok, error);
  return Run(config, input, &provenance);
}

// `gravcal simulate` (workflows/simulation_workflow.h): the truth
// (truth.json text), the raw log, the fixture's attitudes (attitudes.csv
// text) and, for sim_motion rate_table, the segments (segments.csv text,
// else empty).
py::tuple SimulateSession(const Config& config, uint64_t seed, const std::string& plan) {
  SimulationRequest request;
  request.plan_path = plan;
  request.seed = seed;
  SimulationFiles files;
  std::string error;
  bool ok;
  {
    py::gil_scoped_release release;
    ok = SimulateFromConfig(config, request, &files, &error);
  }
  Check(ok, error);
  return py::make_tuple(files.truth_json, WrapLog(std::move(files.session.log)),
                        files.attitudes_csv, files.segments_csv);
}

// ---------------------------------------------------------------------------
// Batch.

struct PyBatchResult {
  std::string unit;
  std::string status;
  bool skipped = false;
  std::string message;
  std::string content_hash;
  py::object calibration = py::none();
  BatchTimings timings;
};

// One unit as Python describes it: id, path (or empty), log (or None),
// attitudes path, config overrides.
struct UnitSpec {
  std::string id;
  std::string path;
  py::object log;
  std::string attitudes;
  Keys overrides;
};

std::vector<PyBatchResult> Batch(const std::vector<BatchUnit>& units, const Config& base,
                                 int threads) {
  BatchOptions options;
  options.threads = threads;
  std::vector<BatchResult> results;
  std::string error;
  bool ok;
  {
    py::gil_scoped_release release;
    ok = CalibrateBatch(units, base, options, &results, &error);
  }
  Check(ok, error);
  std::vector<PyBatchResult> out(results.size());
  for (size_t i = 0; i < results.size(); ++i) {
    const BatchResult& r = results[i];
    PyBatchResult& p = out[i];
    p.unit = r.unit;
    p.status = ToString(r.status);
    p.skipped = r.skipped;
    p.message = r.message;
    p.content_hash = r.content_hash;
    p.timings = r.timings;
    Config config;
    if (r.status == BatchStatus::kOk && EffectiveConfig(units[i], base, &config, &error)) {
      // The unit's <unit>.json as `gravcal batch` writes it.
      p.calibration = py::cast(PyCalibration::FromResult(
          std::make_shared<const Calibration>(std::move(results[i].calibration)),
          config.output_covariance, r.unit));
    }
  }
  return out;
}

std::vector<BatchUnit> UnitsFromSpecs(const std::vector<UnitSpec>& specs) {
  std::vector<BatchUnit> units(specs.size());
  for (size_t i = 0; i < specs.size(); ++i) {
    units[i].id = specs[i].id;
    units[i].path = specs[i].path;
    if (!specs[i].log.is_none()) units[i].log = specs[i].log.cast<const PipelineInput&>().log;
    units[i].attitudes_path = specs[i].attitudes;
    units[i].overrides = specs[i].overrides;
  }
  return units;
}

// The units of a manifest CSV or of a folder (every file matching
// `pattern`), as `gravcal batch --manifest` / `--input-dir` find them.
std::vector<BatchUnit> UnitsFromManifest(const std::string& path, const Config& base) {
  std::vector<BatchUnit> units;
  std::string error;
  Check(ReadBatchManifest(path, base, &units, &error), error);
  return units;
}

std::vector<BatchUnit> UnitsFromFolder(const std::string& folder, const std::string& pattern) {
  std::vector<BatchUnit> units;
  std::string error;
  Check(UnitsFromDirectory(folder, pattern, &units, &error), error);
  return units;
}

// ---------------------------------------------------------------------------
// Noise and discovery: the JSON text of noise.json and discovery.json.

// `gravcal noise` (workflows/noise_workflow.h): noise.json's text, and
// the files of `files` written as the CLI writes them (WriteNoiseFiles, the
// report titled with the log's source).
std::string Noise(const Config& config, const LogHandle& input, const NoiseFiles& files) {
  NoiseOptions options;
  std::string error;
  Check(NoiseOptionsFromConfig(config, &options, &error), error);
  ImuNoise noise;
  bool ok;
  {
    py::gil_scoped_release release;
    ok = CharacteriseLogNoise(input->log, options, &noise, &error) &&
         WriteNoiseFiles(noise, input->log.source, files, nullptr, &error);
  }
  Check(ok, error);
  return NoiseToJson(noise);
}

py::tuple Discover(const Config& config, const LogHandle& input) {
  const ImuLog& log = input->log;
  CheckConfig(config);
  DiscoveryResult result;
  bool ok;
  {
    py::gil_scoped_release release;
    ok = DiscoverEffects(log, config.calibration, config.effects, config.discovery, &result);
  }
  Check(ok, result.message);
  return py::make_tuple(DiscoveryToJson(result), DiscoveryToHtml(result));
}

// ---------------------------------------------------------------------------
// Plan, check and export (workflows/plan.h, io/calibration_export.h).

// The noise model of a request: noise.json at `path`, else the text of one
// (a dict from gravcal.noise, as JSON); false when neither is given.
bool ReadNoise(const std::string& path, const std::string& text, ImuNoise* noise) {
  std::string error;
  if (!path.empty()) {
    Check(ReadNoiseJson(path, noise, &error), error);
  } else if (!text.empty()) {
    Check(NoiseFromJson(text, "noise", noise, &error), error);
  } else {
    return false;
  }
  return true;
}

// `gravcal plan`: plan.json's text.
std::string Plan(const Config& config, PlanRequest request, const std::string& noise_path,
                 const std::string& noise_text) {
  ImuNoise noise;
  if (ReadNoise(noise_path, noise_text, &noise)) request.noise_model = &noise.model;
  RecordingPlan plan;
  std::string error;
  bool ok;
  {
    py::gil_scoped_release release;
    ok = MakeRecordingPlan(config, request, &plan, &error);
  }
  Check(ok, error);
  return PlanToJson(plan);
}

py::list PosesList(const std::vector<PlannedPose>& poses) {
  py::list list;
  for (const PlannedPose& p : poses) {
    py::dict d;
    d["up"] = std::vector<double>(p.up.data(), p.up.data() + 3);
    d["hold_s"] = p.hold_seconds;
    d["instruction"] = p.instruction;
    list.append(d);
  }
  return list;
}

// `gravcal check`: the report's fields, and "text", what the CLI prints.
py::dict CheckSession(const Config& config, const LogHandle& log, PlanRequest request,
                      const std::string& noise_path, const std::string& noise_text) {
  ImuNoise noise;
  if (ReadNoise(noise_path, noise_text, &noise)) request.noise_model = &noise.model;
  std::string error;
  CoverageReport report;
  bool ok;
  {
    py::gil_scoped_release release;
    ok = CheckRecording(log->log, config, request, &report, &error);
  }
  Check(ok, error);
  py::dict d;
  const SensorPrediction& accel = report.accel;
  d["parameters"] = accel.parameter_names;
  d["positions"] = report.positions;
  d["nominal_scale"] = accel.nominal_scale;
  d["predicted_std"] = accel.predicted_std;
  d["predicted_std_scale_free"] = accel.predicted_std_scale_free;
  d["targets_scale_free"] = accel.targets_scale_free;
  d["targeted"] = accel.targeted;
  d["undetermined"] = report.undetermined;
  d["short_of_target"] = report.short_of_target;
  d["proposed"] = PosesList(report.proposed);
  d["predicted_std_with_proposed"] = report.predicted_std_with_proposed;
  d["undetermined_with_proposed"] = report.undetermined_with_proposed;
  d["message"] = report.message;
  d["text"] = CoverageReportText(report);
  return d;
}

// `gravcal export`: the files' names and texts, what the target drops, the
// truncation's residuals.
py::dict Export(const PyCalibration& c, const std::string& to, const std::string& name,
                const std::string& noise_path, const std::string& noise_text) {
  ExportOptions options;
  Check(FromString(to, &options.target),
        "to: expected one of " + ExportTargetNames() + ", not '" + to + "'");
  ImuNoise noise;
  if (ReadNoise(noise_path, noise_text, &noise)) options.noise = &noise.model;
  options.calibration_name = name.empty() ? c.name : name;
  ExportResult result;
  std::string error;
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
// ReadImuLog, LogProvenance and RunCalibration (as `gravcal calibrate`);
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
    if (ReadImuLog(path, config.input, &input.log, &error) &&
        LogProvenance(path, &provenance, &error) && RunCalibration(config, input, &c)) {
      c.provenance = provenance;
    }
  }
  return (ThreadCpuSeconds() - start) / std::max(repeats, 1);
}

}  // namespace
}  // namespace python
}  // namespace gravcal

PYBIND11_MODULE(_gravcal, m) {
  using namespace gravcal;
  using namespace gravcal::python;
  m.doc() = "gravcal's C++ core; use the gravcal package, not this module.";
  py::register_exception<gravcal::python::Error>(m, "Error", PyExc_ValueError);
  m.attr("__version__") = GravcalVersion();

  py::class_<Config>(m, "Config", "A gravcal configuration (the YAML keys).")
      .def(py::init(&MakeConfig), py::arg("path") = "", py::arg("keys") = Keys{})
      .def("with_keys", &WithKeys, py::arg("keys"))
      .def("value",
           [](const Config& c, const std::string& key) {
             Check(IsConfigKey(key), "unknown config key '" + key + "'");
             return ConfigValueText(c, key);
           })
      .def_property_readonly("method",
                             [](const Config& c) { return std::string(ToString(c.method)); })
      .def("text", &ConfigText, "Every key with its value, one 'key: value' line each.");
  m.def("config_keys", []() {
    std::vector<std::pair<std::string, std::string>> keys;
    for (const ConfigKey& k : ConfigKeys()) keys.emplace_back(k.name, k.help);
    return keys;
  });

  py::class_<PipelineInput, LogHandle>(m, "Log")
      .def_property_readonly("source", [](const PipelineInput& l) { return l.log.source; })
      .def_property_readonly(
          "t",
          [](py::object self) { return Scalars(self.cast<const PipelineInput&>().log.t, self); })
      .def_property_readonly("accel",
                             [](py::object self) {
                               return Vectors(self.cast<const PipelineInput&>().log.accel, self);
                             })
      .def_property_readonly(
          "gyro",
          [](py::object self) { return Vectors(self.cast<const PipelineInput&>().log.gyro, self); })
      .def_property_readonly("temp",
                             [](py::object self) {
                               return Scalars(self.cast<const PipelineInput&>().log.temperature,
                                              self);
                             })
      .def("__len__", [](const PipelineInput& l) { return l.log.size(); })
      .def("to_csv", [](const PipelineInput& l, const std::string& path) {
        std::string error;
        Check(WriteImuLogCsv(l.log, path, &error), error);
      });
  m.def("make_log", &MakeLog, py::arg("t"), py::arg("accel"), py::arg("gyro"), py::arg("temp"),
        py::arg("source"));
  m.def("read_log", &ReadLog, py::arg("path"), py::arg("config"));

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
      .def("apply", &ApplyCalibration, py::arg("accel"), py::arg("gyro"), py::arg("temp"),
           py::arg("t"));
  m.def("calibrate", &Calibrate, py::arg("config"), py::arg("log"), py::arg("attitudes"),
        py::arg("segments"), py::arg("noise"));
  m.def("calibrate_file", &CalibrateFile, py::arg("config"), py::arg("path"), py::arg("attitudes"),
        py::arg("segments"), py::arg("noise"));
  m.def("simulate", &SimulateSession, py::arg("config"), py::arg("seed"), py::arg("plan"));

  py::class_<BatchUnit>(m, "BatchUnit").def_readonly("id", &BatchUnit::id);
  py::class_<PyBatchResult>(m, "BatchResult")
      .def_readonly("unit", &PyBatchResult::unit)
      .def_readonly("status", &PyBatchResult::status)
      .def_readonly("skipped", &PyBatchResult::skipped)
      .def_readonly("message", &PyBatchResult::message)
      .def_readonly("content_hash", &PyBatchResult::content_hash)
      .def_readwrite("calibration", &PyBatchResult::calibration)
      .def_property_readonly("timings", [](const PyBatchResult& r) {
        py::dict d;
        d["read_seconds"] = r.timings.read_seconds;
        d["detect_seconds"] = r.timings.detect_seconds;
        d["solve_seconds"] = r.timings.solve_seconds;
        d["total_seconds"] = r.timings.total_seconds;
        return d;
      });
  m.def("units_from_manifest", &UnitsFromManifest, py::arg("path"), py::arg("config"));
  m.def("units_from_folder", &UnitsFromFolder, py::arg("folder"), py::arg("pattern"));
  m.def(
      "units",
      [](const std::vector<py::tuple>& specs) {
        std::vector<UnitSpec> s(specs.size());
        for (size_t i = 0; i < specs.size(); ++i) {
          s[i].id = specs[i][0].cast<std::string>();
          s[i].path = specs[i][1].cast<std::string>();
          s[i].log = specs[i][2];
          s[i].attitudes = specs[i][3].cast<std::string>();
          s[i].overrides = specs[i][4].cast<Keys>();
        }
        return UnitsFromSpecs(s);
      },
      py::arg("specs"));
  m.def("batch", &Batch, py::arg("units"), py::arg("config"), py::arg("threads"));
  m.def(
      "noise",
      [](const Config& config, const LogHandle& log, const std::string& kalibr,
         const std::string& handheld, const std::string& report) {
        return Noise(config, log, {"", kalibr, handheld, report});
      },
      py::arg("config"), py::arg("log"), py::arg("kalibr"), py::arg("handheld"), py::arg("report"));
  m.def("discover", &Discover, py::arg("config"), py::arg("log"));
  // The destination contract (io/files.h), checked before any work:
  // outputs and inputs as (path, name in messages) pairs.
  m.def("check_destinations", [](const std::vector<std::pair<std::string, std::string>>& outputs,
                                 const std::vector<std::pair<std::string, std::string>>& inputs) {
    std::vector<Destination> destinations;
    for (const auto& [path, name] : outputs) destinations.push_back({path, name});
    std::vector<Source> sources;
    for (const auto& [path, name] : inputs) sources.push_back({path, name});
    std::string error;
    Check(CheckDestinations(destinations, sources, &error), error);
  });
  m.def("write_file", [](const std::string& path, const std::string& text) {
    std::string error;
    Check(WriteFileAtomically(path, text, &error), error);
  });

  py::class_<PlanRequest>(m, "PlanRequest", "The request of gravcal plan and gravcal check.")
      .def(py::init<>())
      .def_readwrite("targets", &PlanRequest::targets)
      .def_readwrite("pose_set", &PlanRequest::pose_set)
      .def_readwrite("free_candidates", &PlanRequest::free_candidates)
      .def_readwrite("max_time_seconds", &PlanRequest::max_time_seconds)
      .def_readwrite("overhead_seconds", &PlanRequest::overhead_seconds)
      .def_readwrite("min_hold_seconds", &PlanRequest::min_hold_seconds)
      .def_readwrite("max_hold_seconds", &PlanRequest::max_hold_seconds)
      .def_readwrite("max_poses", &PlanRequest::max_poses)
      .def_readwrite("accel_noise_density", &PlanRequest::accel_noise_density)
      .def_readwrite("accel_bias_instability", &PlanRequest::accel_bias_instability)
      .def_readwrite("accel_random_walk", &PlanRequest::accel_random_walk)
      .def_readwrite("pose_disturbance", &PlanRequest::pose_disturbance)
      .def_readwrite("extra_poses", &PlanRequest::extra_poses);
  m.def("plan", &Plan, py::arg("config"), py::arg("request"), py::arg("noise_path"),
        py::arg("noise_text"));
  m.def("check", &CheckSession, py::arg("config"), py::arg("log"), py::arg("request"),
        py::arg("noise_path"), py::arg("noise_text"));
  m.def("export", &Export, py::arg("calibration"), py::arg("to"), py::arg("name"),
        py::arg("noise_path"), py::arg("noise_text"));
  m.def("_time_calibrate", &TimeCalibrate, py::arg("config"), py::arg("log"), py::arg("path"),
        py::arg("repeats"));
}
