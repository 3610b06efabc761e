// What the translation units of gravcal._gravcal share: the error Python
// sees, the array and log conversions, the calibration Python holds, and
// the Bind functions that PYBIND11_MODULE (gravcal_module.cc) calls, one per
// area: calibration, apply and export (calibration_bindings.cc), batch
// (batch_bindings.cc), simulate, noise, discovery, plan and check
// (recording_bindings.cc).
#ifndef GRAVCAL_PYTHON_BINDINGS_H_
#define GRAVCAL_PYTHON_BINDINGS_H_

// Every translation unit sees the same type casters (Eigen, NumPy, STL), as
// the one file of before did.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "gravcal/gravcal.h"
#include "gravcal/io/noise_io.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"

namespace py = pybind11;

namespace gravcal {
namespace python {

// Raised as gravcal.Error (a ValueError) with the library's message.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void Check(bool ok, const std::string& message);

using Keys = std::vector<std::pair<std::string, std::string>>;

void CheckConfig(const Config& config);

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// An (N, 3) array into 3-vectors; `rows` = N expected (the length of
// `reference`), or -1 for any.
std::vector<Eigen::Vector3d> ToVectors(const py::object& obj, const char* name, py::ssize_t rows,
                                       const char* reference = "t");
std::vector<double> ToScalars(const py::object& obj, const char* name, py::ssize_t rows,
                              const char* reference = "t");

// A Python gravcal.Log is a PipelineInput holding the log (source = the
// log's source, no side input), never changed once made: calibrate hands it
// to RunCalibration as it is (no copy of the samples), any number of
// threads may read it at once, and NumPy views of its vectors stay valid.
using LogHandle = std::shared_ptr<PipelineInput>;

LogHandle WrapLog(ImuLog log);

// A calibration as Python holds it (calibration_bindings.cc).
struct PyCalibration {
  // The library's result, when made here (null when read from a file).
  std::shared_ptr<const Calibration> result;
  bool include_covariance = true;
  std::string name;
  // The JSON text (built from `result` on first use) and the models (from
  // `result`, else read from the text as ReadCalibrationJson would; on
  // first use).
  mutable std::string json;
  mutable bool has_json = false;
  mutable bool parsed = false;
  mutable LoadedCalibration models;

  // A file's text, checked at once.
  static PyCalibration FromText(const std::string& text, const std::string& name);
  // Held as made: results are handed to Python without a copy or a move.
  static std::unique_ptr<PyCalibration> FromResult(std::shared_ptr<const Calibration> result,
                                                   bool include_covariance,
                                                   const std::string& name);
  const std::string& Json() const;
  const LoadedCalibration& Models() const;
};

// The noise model of a request: noise.json at `path`, else the text of one
// (a dict from gravcal.noise, as JSON); false when neither is given.
bool ReadNoise(const std::string& path, const std::string& text, ImuNoise* noise);

void BindCalibration(py::module_& m);
void BindBatch(py::module_& m);
void BindRecordings(py::module_& m);
// compare, verify, the store, limits and the certificate (verify_bindings.cc).
void BindVerify(py::module_& m);
void BindRecorder(py::module_& m);
// thermal_bindings.cc (issue 35): thermal_model, thermal_evaluate.
void BindThermal(py::module_& m);
void BindMultiImu(py::module_& m);  // multi_imu_bindings.cc (issue 38)

}  // namespace python
}  // namespace gravcal

#endif  // GRAVCAL_PYTHON_BINDINGS_H_
