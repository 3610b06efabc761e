// gravcal._gravcal: is the calibration still good? compare, verify, the
// calibration store and its history, acceptance limits and the certificate
// (issue 36: estimation/calibration_comparison.h, estimation/check_session.h,
// workflows/calibration_store.h, workflows/acceptance.h). Results cross as
// the JSON text the CLI writes (compare.json, verify.json, history's
// --output, the certificate).
#include <ctime>
#include <string>
#include <utility>

#include "bindings.h"
#include "gravcal/estimation/calibration_comparison.h"
#include "gravcal/estimation/check_session.h"
#include "gravcal/io/calibration_uncertainty_io.h"
#include "gravcal/io/comparison_io.h"
#include "gravcal/workflows/acceptance.h"
#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/calibration_store.h"
#include "gravcal/workflows/compare.h"

namespace gravcal {
namespace python {
namespace {

// The calibration with its uncertainty: the result itself when made here,
// else read from its JSON as compare reads a file.
Calibration WithUncertainty(const PyCalibration& c) {
  if (c.result != nullptr) return *c.result;
  Calibration out;
  std::string error;
  Check(CalibrationUncertaintyFromJson(c.Json(), c.name, &out, nullptr, &error), error);
  return out;
}

ComparisonOptions Options(double level) {
  ComparisonOptions options;
  options.level = level;
  std::string error;
  Check(options.IsValid(&error), "level: " + error);
  return options;
}

std::string Compare(const PyCalibration& a, const PyCalibration& b, double level,
                    const std::string& space_name) {
  const ComparisonOptions options = Options(level);
  ComparisonSpace space;
  std::string error;
  Check(ParseName("space", space_name, &space, &error), error);
  ParameterVector p[2];
  const Calibration c[2] = {WithUncertainty(a), WithUncertainty(b)};
  const std::string names[2] = {a.name, b.name};
  Check(SameRawUnits(c[0], c[1], &error), names[0] + ", " + names[1] + ": " + error);
  for (int i = 0; i < 2; ++i) {
    Check(CalibrationParameters(c[i], space, &p[i], &error),
          names[i] + ": cannot be tested: " + error);
  }
  ComparisonResult result;
  Check(CompareParameters(p[0], p[1], options, &result), result.message);
  Check(result.tested, "cannot be tested: " + result.message);
  return ComparisonToJson(result, {{"space", std::string("\"") + ToString(space) + "\""}});
}

std::string Verify(const PyCalibration& stored, const Config& config, const LogHandle& log,
                   double level) {
  CheckConfig(config);
  const ComparisonOptions options = Options(level);
  const Calibration calibration = WithUncertainty(stored);
  CheckSessionResult result;
  std::string error;
  bool ok;
  {
    py::gil_scoped_release release;
    ok = VerifyCheckLog(log->log, calibration, config.calibration, options, &result, &error);
  }
  Check(ok, error);
  Check(result.comparison.tested, log->log.source + ": cannot be tested: nothing to test");
  return ComparisonToJson(result.comparison, {{"poses", CheckPosesToJson(result)}});
}

std::string History(const std::string& store, const std::string& unit, double level) {
  Check(level > 0.0 && level < 1.0, "level: must lie in (0, 1)");
  UnitHistory history;
  std::string error;
  Check(ReadUnitHistory(store, unit, level, &history, &error), error);
  return UnitHistoryToJson(history);
}

// The limits from a file, else from YAML text (a dict from Python, as JSON).
AcceptanceLimits Limits(const std::string& path, const std::string& text) {
  AcceptanceLimits limits;
  std::string error;
  Check(path.empty() ? AcceptanceLimitsFromYaml(text, "limits", &limits, &error)
                     : ReadAcceptanceLimits(path, &limits, &error),
        error);
  return limits;
}

std::string CheckLimits(const PyCalibration& c, const std::string& path, const std::string& text) {
  AcceptanceResult result;
  CheckAcceptance(WithUncertainty(c), Limits(path, text), &result);
  return AcceptanceToJson(result);
}

// (certificate JSON, HTML). `info` fields as the CLI fills them; the
// software version is this module's.
std::pair<std::string, std::string> MakeCertificateText(const PyCalibration& c, bool has_limits,
                                                        const std::string& path,
                                                        const std::string& text,
                                                        CertificateInfo info) {
  const Calibration calibration = WithUncertainty(c);
  AcceptanceLimits limits;
  if (has_limits) limits = Limits(path, text);
  info.software_version = GravcalVersion();
  if (info.date.empty()) info.date = FormatUtcDate(std::time(nullptr));
  if (info.input_hash.empty()) info.input_hash = calibration.provenance.log_hash;
  if (info.input_file.empty()) info.input_file = calibration.provenance.log_file;
  Certificate certificate;
  std::string error;
  Check(MakeCertificate(calibration, info, has_limits ? &limits : nullptr, &certificate, &error),
        c.name + ": " + error);
  return {CertificateToJson(certificate), CertificateToHtml(certificate)};
}

void File(const std::string& store, const std::string& unit, const std::string& date,
          const PyCalibration& c) {
  std::string error;
  Check(FileCalibration(store, unit, date.empty() ? FormatUtcDate(std::time(nullptr)) : date,
                        c.Json(), &error),
        error);
}

py::dict Closest(const std::string& store, const std::string& unit, const std::string& date,
                 double max_age_days) {
  StoreEntry entry;
  std::string warning, error;
  Check(ClosestCalibration(store, unit, date.empty() ? FormatUtcDate(std::time(nullptr)) : date,
                           max_age_days, &entry, &warning, &error),
        error);
  py::dict d;
  d["unit"] = entry.unit;
  d["date"] = entry.date;
  d["file"] = store + "/" + entry.file;
  d["method"] = entry.method;
  d["warning"] = warning;
  return d;
}

}  // namespace

void BindVerify(py::module_& m) {
  m.def("compare", &Compare, py::arg("a"), py::arg("b"), py::arg("level"), py::arg("space"));
  m.def("verify", &Verify, py::arg("calibration"), py::arg("config"), py::arg("log"),
        py::arg("level"));
  m.def("history", &History, py::arg("store"), py::arg("unit"), py::arg("level"));
  m.def("check_limits", &CheckLimits, py::arg("calibration"), py::arg("path"), py::arg("text"));
  m.def(
      "certificate",
      [](const PyCalibration& c, bool has_limits, const std::string& path, const std::string& text,
         const std::string& unit, const std::string& station, const std::string& date,
         const std::string& input_file, const std::string& config_name,
         const std::string& config_text, double coverage_factor) {
        CertificateInfo info;
        info.unit = unit;
        info.station = station;
        info.date = date;
        info.input_file = input_file;
        info.config_name = config_name;
        info.config_text = config_text;
        info.coverage_factor = coverage_factor;
        return MakeCertificateText(c, has_limits, path, text, info);
      },
      py::arg("calibration"), py::arg("has_limits"), py::arg("path"), py::arg("text"),
      py::arg("unit"), py::arg("station"), py::arg("date"), py::arg("input_file"),
      py::arg("config_name"), py::arg("config_text"), py::arg("coverage_factor"));
  m.def("file_calibration", &File, py::arg("store"), py::arg("unit"), py::arg("date"),
        py::arg("calibration"));
  m.def("closest_calibration", &Closest, py::arg("store"), py::arg("unit"), py::arg("date"),
        py::arg("max_age_days"));
}

}  // namespace python
}  // namespace gravcal
