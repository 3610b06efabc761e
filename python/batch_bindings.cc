// gravcal._gravcal: batch calibration (workflows/batch.h,
// workflows/batch_folder.h) and its bindings.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "gravcal/gravcal.h"
#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/batch_folder.h"
#include "gravcal/workflows/batch_manifest.h"
#include "workflows/batch_scheduler_shard.h"

namespace gravcal {

using internal::IsSchedulerShard;
using internal::ProcessEnvironment;
using internal::ShardFromScheduler;
namespace python {
namespace {

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

// One unit's result for Python; the calibration as the unit's <unit>.json
// (what `gravcal batch` writes).
PyBatchResult ToPython(BatchResult* r, const BatchUnit& unit, const Config& base) {
  PyBatchResult p;
  p.unit = r->unit;
  p.status = ToString(r->status);
  p.skipped = r->skipped;
  p.message = r->message;
  p.content_hash = r->content_hash;
  p.timings = r->timings;
  Config config;
  std::string error;
  if (r->status == BatchStatus::kOk && !r->skipped &&
      EffectiveConfig(unit, base, &config, &error)) {
    p.calibration = py::cast(
        PyCalibration::FromResult(std::make_shared<const Calibration>(std::move(r->calibration)),
                                  config.output_covariance, r->unit));
  }
  return p;
}

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
  std::vector<PyBatchResult> out;
  for (size_t i = 0; i < results.size(); ++i) out.push_back(ToPython(&results[i], units[i], base));
  return out;
}

// `gravcal batch` from Python (workflows/batch_folder.h): the units of the
// manifest or folder in `source` (else `units`), written into output_dir and
// resumed from it. A skipped unit's status and message come from its stored
// row. Returns (results, full report text).
py::tuple BatchToFolder(const std::vector<BatchUnit>& units, const BatchSource& source,
                        const Config& base, int threads, const std::string& output_dir,
                        const std::string& report, const std::string& shard) {
  BatchFolderOptions options;
  options.output_dir = output_dir;
  options.report = report;
  options.threads = threads;
  std::string error;
  std::string shard_source;
  Check(IsSchedulerShard(shard)
            ? ShardFromScheduler(shard, ProcessEnvironment(), &options.shard, &shard_source, &error)
            : shard.empty() || ParseShard(shard, &options.shard, &error),
        error);
  BatchFolderUnits shard_units;
  BatchFolderSummary summary;
  bool ok;
  {
    py::gil_scoped_release release;
    ok = (source.manifest.empty() && source.input_dir.empty()
              ? (shard_units = ShardOfFleet(units, base, options.shard), true)
              : ListBatchFolderUnits(source, base, options, &shard_units, &error)) &&
         CalibrateBatchToFolder(shard_units, base, options, &summary, &error);
  }
  Check(ok, error);
  summary.shard_source = shard_source;
  std::vector<PyBatchResult> out;
  for (size_t i = 0; i < summary.results.size(); ++i) {
    BatchResult& r = summary.results[i];
    if (r.skipped) {
      r.status = summary.rows[i].status;
      r.message = summary.rows[i].message;
    }
    out.push_back(ToPython(&r, shard_units.units[i], base));
  }
  return py::make_tuple(out, summary.FullReport());
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

}  // namespace

void BindBatch(py::module_& m) {
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
      "batch_to_folder",
      [](const std::vector<BatchUnit>& units, const std::string& manifest,
         const std::string& input_dir, const std::string& pattern, const Config& base, int threads,
         const std::string& output_dir, const std::string& report, const std::string& shard) {
        return BatchToFolder(units, {manifest, input_dir, pattern, "", ""}, base, threads,
                             output_dir, report, shard);
      },
      py::arg("units"), py::arg("manifest"), py::arg("input_dir"), py::arg("pattern"),
      py::arg("config"), py::arg("threads"), py::arg("output_dir"), py::arg("report"),
      py::arg("shard"));
}

}  // namespace python
}  // namespace gravcal
