// gravcal._gravcal: the Recorder of gravcal record (workflows/recorder.h),
// for guiding a calibration from one's own acquisition loop.
#include <memory>
#include <string>
#include <vector>

#include "bindings.h"
#include "gravcal/workflows/recorder.h"

namespace gravcal {
namespace python {

namespace {

// The recorder and what it needs alive (the noise model it points to).
struct PyRecorder {
  Config config;
  ImuNoise noise;
  Recorder recorder;
  std::string log_csv;
};

std::unique_ptr<PyRecorder> MakeRecorder(const Config& config, const std::string& targets,
                                         const std::string& pose_set, double max_time,
                                         double accel_noise_density, const std::string& noise_path,
                                         const std::string& noise_text) {
  CheckConfig(config);
  auto r = std::make_unique<PyRecorder>();
  r->config = config;
  RecorderOptions options;
  options.request.targets = targets;
  std::string error;
  Check(ParseName("pose_set", pose_set, &options.request.pose_set, &error), error);
  options.request.accel_noise_density = accel_noise_density;
  options.max_time_seconds = max_time;
  if (ReadNoise(noise_path, noise_text, &r->noise)) options.request.noise_model = &r->noise.model;
  Check(r->recorder.Start(r->config, options, &error), error);
  return r;
}

// Each event's JSON text.
std::vector<std::string> Texts(const std::vector<RecorderEvent>& events) {
  std::vector<std::string> out;
  for (const RecorderEvent& e : events) out.push_back(e.json);
  return out;
}

}  // namespace

void BindRecorder(py::module_& m) {
  py::class_<PyRecorder>(m, "Recorder")
      .def(py::init(&MakeRecorder), py::arg("config"), py::arg("targets"),
           py::arg("pose_set") = "faces+45", py::arg("max_time") = 0.0,
           py::arg("accel_noise_density") = 0.0, py::arg("noise") = "", py::arg("noise_text") = "")
      .def(
          "feed",
          [](PyRecorder& r, double t, const Eigen::Vector3d& accel, py::object gyro,
             double temperature) {
            const bool has_gyro = !gyro.is_none();
            const Eigen::Vector3d g =
                has_gyro ? gyro.cast<Eigen::Vector3d>() : Eigen::Vector3d::Zero();
            return Texts(r.recorder.Feed(t, accel, g, temperature, has_gyro));
          },
          py::arg("t"), py::arg("accel"), py::arg("gyro") = py::none(),
          py::arg("temp") = std::numeric_limits<double>::quiet_NaN())
      .def("warn", [](PyRecorder& r, const std::string& kind,
                      const std::string& message) { return r.recorder.Warn(kind, message).json; })
      .def_property_readonly("done", [](const PyRecorder& r) { return r.recorder.done(); })
      .def_property_readonly("done_reason",
                             [](const PyRecorder& r) { return r.recorder.status().done_reason; })
      .def_property_readonly("log_csv", [](const PyRecorder& r) { return r.log_csv; })
      .def(
          "finish",
          [](PyRecorder& r, const std::string& reason) {
            RecorderResult result;
            std::string error;
            bool ok;
            {
              py::gil_scoped_release release;
              ok = r.recorder.Finish(reason, {}, &result, &error);
            }
            Check(ok, error);
            r.log_csv = result.log_csv;
            // (calibration or None, the done event, the failure's message).
            if (!result.ok) {
              return py::make_tuple(py::none(), result.done.json, result.calibration.message);
            }
            auto c = std::make_shared<const Calibration>(std::move(result.calibration));
            return py::make_tuple(py::cast(PyCalibration::FromResult(
                                      std::move(c), r.config.output_covariance, "record")),
                                  result.done.json, std::string());
          },
          py::arg("reason"));
}

}  // namespace python
}  // namespace gravcal
