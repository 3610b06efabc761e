// gravcal._gravcal: simulate, noise, discovery, plan and check, and their
// bindings.
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "gravcal/gravcal.h"
#include "gravcal/io/noise_io.h"
#include "gravcal/io/plan_io.h"
#include "gravcal/workflows/discovery.h"
#include "gravcal/workflows/discovery_report.h"
#include "gravcal/workflows/noise_workflow.h"
#include "gravcal/workflows/plan.h"
#include "gravcal/workflows/simulation_workflow.h"

namespace gravcal {
namespace python {

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

namespace {

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
// Plan and check (workflows/plan.h).

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

}  // namespace

void BindRecordings(py::module_& m) {
  m.def("simulate", &SimulateSession, py::arg("config"), py::arg("seed"), py::arg("plan"));
  m.def(
      "noise",
      [](const Config& config, const LogHandle& log, const std::string& kalibr,
         const std::string& handheld, const std::string& report) {
        return Noise(config, log, {"", kalibr, handheld, report});
      },
      py::arg("config"), py::arg("log"), py::arg("kalibr"), py::arg("handheld"), py::arg("report"));
  m.def("discover", &Discover, py::arg("config"), py::arg("log"));

  py::class_<PlanRequest>(m, "PlanRequest", "The request of gravcal plan and gravcal check.")
      .def(py::init<>())
      .def_readwrite("targets", &PlanRequest::targets)
      .def_property(
          "pose_set", [](const PlanRequest& r) { return std::string(ToString(r.pose_set)); },
          [](PlanRequest& r, const std::string& name) {
            std::string error;
            Check(ParseName("pose_set", name, &r.pose_set, &error), error);
          })
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
}

}  // namespace python
}  // namespace gravcal
