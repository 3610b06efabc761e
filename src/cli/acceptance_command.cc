// calibrate --limits limits.yaml and --certificate PREFIX (issue 36): the
// pass/fail verdict against acceptance limits, and the calibration
// certificate (PREFIX.json, PREFIX.html). Exit code 4 when a limit fails
// (the calibration and the certificate are written: they record it).
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <string>

#include "cli/commands.h"
#include "gravcal/io/calibration_uncertainty_io.h"
#include "gravcal/io/files.h"
#include "gravcal/workflows/acceptance.h"
#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/calibration_store.h"
#include "util/content_hash.h"

namespace gravcal {
namespace cli {
namespace {

constexpr int kOutOfLimits = 4;

std::string NowUtc() { return FormatUtcDate(std::time(nullptr)); }

// The content hash of this program's executable ("" when it cannot be read).
std::string ProgramHash() {
  std::string bytes, error;
  if (!ReadFileBytes("/proc/self/exe", &bytes, &error)) return "";
  internal::ContentHash hash;
  hash.Add(bytes);
  return hash.Hex();
}

std::string UnitName(const CalibrateArgs& args) {
  if (!args.unit.empty()) return args.unit;
  std::string stem = args.input.substr(args.input.find_last_of('/') + 1);
  return stem.substr(0, stem.find_last_of('.'));
}

}  // namespace

bool CheckLimitsFile(const std::string& limits, std::string* error) {
  AcceptanceLimits parsed;
  return limits.empty() || ReadAcceptanceLimits(limits, &parsed, error);
}

int FinishAcceptance(const CalibrateArgs& args, const Calibration& calibration) {
  std::string error;
  if (!args.store.empty()) {
    // The stored copy always has the covariance: history and compare need it.
    const std::string date = NowUtc();
    if (!FileCalibration(args.store, UnitName(args), date, CalibrationToJson(calibration, true),
                         &error)) {
      return Fail(error);
    }
    std::fprintf(stderr, "gravcal: filed as unit '%s', %s, in %s\n", UnitName(args).c_str(),
                 date.c_str(), args.store.c_str());
  }
  if (args.limits.empty() && args.certificate.empty()) return 0;
  AcceptanceLimits limits;
  const bool has_limits = !args.limits.empty();
  if (has_limits && !ReadAcceptanceLimits(args.limits, &limits, &error)) return Fail(error);
  AcceptanceResult acceptance;
  if (has_limits) CheckAcceptance(calibration, limits, &acceptance);
  if (!args.certificate.empty()) {
    CertificateInfo info;
    info.unit = UnitName(args);
    char host[256] = {0};
    if (gethostname(host, sizeof(host) - 1) == 0) info.station = host;
    info.date = NowUtc();
    info.software_version = GravcalVersion();
    info.software_hash = ProgramHash();
    info.input_file = args.input;
    info.input_hash = calibration.provenance.log_hash;
    info.config_name = args.config_path.empty() ? "(defaults)" : args.config_path;
    if (!args.config_path.empty()) ReadFileBytes(args.config_path, &info.config_text, &error);
    Certificate certificate;
    if (!MakeCertificate(calibration, info, has_limits ? &limits : nullptr, &certificate, &error)) {
      return Fail(error);
    }
    if (!WriteFileAtomically(args.certificate + ".json", CertificateToJson(certificate), &error) ||
        !WriteFileAtomically(args.certificate + ".html", CertificateToHtml(certificate), &error)) {
      return Fail(error);
    }
  }
  if (!has_limits) return 0;
  std::fprintf(stderr, "gravcal: limits %s: %s\n", args.limits.c_str(), acceptance.message.c_str());
  return acceptance.pass ? 0 : kOutOfLimits;
}

int FinishBatchAcceptance(const BatchArgs& args, const std::vector<std::string>& units, int code) {
  if (args.limits.empty()) return code;
  std::string error;
  AcceptanceLimits limits;
  if (!ReadAcceptanceLimits(args.limits, &limits, &error)) return Fail(error);
  std::string csv = "unit,verdict,failed\n";
  std::string failed_units;
  int checked = 0, failed = 0;
  for (const std::string& unit : units) {
    const std::string path = args.output_dir + "/" + unit + ".json";
    Calibration c;
    struct stat st;
    if (stat(path.c_str(), &st) != 0) continue;  // the unit failed: the batch says why
    if (!ReadCalibrationUncertainty(path, &c, nullptr, &error)) return Fail(error);
    AcceptanceResult result;
    CheckAcceptance(c, limits, &result);
    ++checked;
    std::string why;
    for (const LimitCheck& check : result.checks) {
      if (!check.pass) why += (why.empty() ? "" : "; ") + check.name + " " + check.why;
    }
    csv += unit + "," + (result.pass ? "pass" : "fail") + ",\"" + why + "\"\n";
    if (!result.pass) {
      ++failed;
      failed_units += (failed_units.empty() ? "" : ", ") + unit + " (" + why + ")";
    }
  }
  if (!WriteFileAtomically(args.output_dir + "/limits.csv", csv, &error)) return Fail(error);
  std::fprintf(stderr, "gravcal: limits %s: %d of %d calibrated units pass%s%s\n",
               args.limits.c_str(), checked - failed, checked, failed > 0 ? "; fail: " : "",
               failed_units.c_str());
  return code != 0 ? code : (failed > 0 ? kOutOfLimits : 0);
}

}  // namespace cli
}  // namespace gravcal
