// gravcal._gravcal: the Python extension module, a thin layer over the
// public C++ API (include/gravcal/). Arrays cross as NumPy arrays; results
// cross as the library's own JSON text (the calibration JSON, truth.json,
// noise.json, discovery.json), so the Python objects and the CLI's files are
// the same numbers by construction. No calibration logic lives here: each
// function converts its arguments, calls the library (without the GIL for
// anything that can take long) and turns a false return into gravcal.Error
// with the library's one-line message. The Pythonic surface (keyword
// arguments, pandas, attribute access) is python/gravcal/__init__.py.
// This file holds the module, the configuration, arrays and logs; the
// bindings of each area are in *_bindings.cc (bindings.h).

#include <algorithm>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "gravcal/gravcal.h"
#include "gravcal/io/files.h"
#include "gravcal/io/recording.h"
#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"

namespace gravcal {
namespace python {

void Check(bool ok, const std::string& message) {
  if (!ok) throw Error(message);
}

namespace {

// ImuLog stores its 3-vectors back to back: an (N, 3) array of doubles.
static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "Vector3d must be unpadded");

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

}  // namespace

void CheckConfig(const Config& config) {
  std::string error;
  Check(config.IsValid(&error), error);
}

namespace {

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

}  // namespace

std::vector<Eigen::Vector3d> ToVectors(const py::object& obj, const char* name, py::ssize_t rows,
                                       const char* reference) {
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
                              const char* reference) {
  const DoubleArray a = AsDoubles(obj, name);
  if (a.ndim() != 1) {
    throw Error(std::string(name) + ": expected an array of shape (N,), got shape " + ShapeText(a));
  }
  if (rows >= 0 && a.shape(0) != rows) {
    throw Error(LengthText(name, a.shape(0), reference, rows));
  }
  return std::vector<double>(a.data(), a.data() + a.shape(0));
}

LogHandle WrapLog(ImuLog log) {
  auto input = std::make_shared<PipelineInput>();
  input->source = log.source;
  input->log = std::move(log);
  return input;
}

namespace {

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
  BindCalibration(m);
  BindBatch(m);
  BindRecordings(m);
  BindVerify(m);
  BindRecorder(m);
  BindThermal(m);
  BindMultiImu(m);
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
}
