// gravcal._gravcal's multi-IMU functions (issue 38): simulate a plate of
// IMUs, calibrate one session of several IMUs (methods/multi_imu.h).
#include "bindings.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/methods/multi_imu.h"
#include "gravcal/simulation/plate_simulator.h"
#include "gravcal/workflows/multi_imu_log.h"

namespace gravcal {
namespace python {

void BindMultiImu(py::module_& m) {
  m.def(
      "simulate_plate",
      [](int imus, uint64_t seed, int permuted_imu, double max_clock_offset, double clock_drift_std,
         int slip_imu, double hold_seconds, const std::string& mounting) {
        PlateSimulatorOptions o;
        o.imus = imus;
        o.permuted_imu = permuted_imu;
        o.max_clock_offset = max_clock_offset;
        o.clock_drift_std = clock_drift_std;
        o.slip_imu = slip_imu;
        std::string error;
        Check(ParseName("mounting", mounting, &o.mounting, &error), error);
        o.imu.hold_seconds = hold_seconds;
        o.imu.initial_still_seconds = hold_seconds;
        SimulatedPlate plate;
        bool ok = false;
        {
          py::gil_scoped_release release;
          ok = SimulatePlate(o, seed, &plate, &error);
        }
        Check(ok, error);
        return py::make_tuple(PlateToCsv(plate), PlateTruthToJson(plate));
      },
      py::arg("imus") = 3, py::arg("seed") = 1, py::arg("permuted_imu") = -1,
      py::arg("max_clock_offset") = 0.03, py::arg("clock_drift_std") = 0.0,
      py::arg("slip_imu") = -1, py::arg("hold_seconds") = 10.0, py::arg("mounting") = "random",
      "A simulated plate of IMUs: (CSV text with t, imu<i>.ax .. imu<i>.gz; truth JSON text).");
  m.def(
      "calibrate_multi_imu",
      [](const std::string& input, const std::string& config_path) {
        MultiImuConfig config;
        std::vector<PlateImu> imus;
        MultiImuResult result;
        std::string error;
        bool ok = false;
        {
          py::gil_scoped_release release;
          ok = LoadMultiImuConfig(config_path, &config, &error) &&
               ReadMultiImuLogs(&config, input, &imus, nullptr, &error);
          if (ok) {
            ok = CalibrateMultiImu(imus, config.options, &result);
            if (!ok) error = result.message;
          }
        }
        Check(ok, error);
        py::dict calibrations;
        for (const PlateImuResult& r : result.imus) {
          calibrations[py::str(r.name)] = CalibrationToJson(r.calibration, true);
        }
        py::dict out;
        out["assembly"] = MultiImuAssemblyToJson(result);
        out["calibrations"] = calibrations;
        return out;
      },
      py::arg("input"), py::arg("config"),
      "Calibrates every IMU of a multi-IMU table (config: configs/multi_imu.yaml): "
      "{'assembly': JSON text, 'calibrations': {name: calibration JSON text}}.");
}

}  // namespace python
}  // namespace gravcal
