// calibrate --limits limits.yaml and --certificate PREFIX (issue 36): the
// pass/fail verdict against acceptance limits, and the calibration
// certificate (PREFIX.json, PREFIX.html). Exit code 4 when a limit fails
// (the calibration and the certificate are written: they record it). Also
// batch's limits, certificates and store, and apply's and export's
// calibration taken from a store.
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
#include "util/error.h"

namespace gravcal {
namespace cli {
namespace {

using internal::SetError;

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

// What a certificate records of this run: station, date, software, config.
CertificateInfo StationInfo(const std::string& config_path) {
  CertificateInfo info;
  char host[256] = {0};
  if (gethostname(host, sizeof(host) - 1) == 0) info.station = host;
  info.date = NowUtc();
  info.software_version = GravcalVersion();
  info.software_hash = ProgramHash();
  info.config_name = config_path.empty() ? "(defaults)" : config_path;
  std::string error;
  if (!config_path.empty()) ReadFileBytes(config_path, &info.config_text, &error);
  return info;
}

}  // namespace

bool CheckLimitsFile(const std::string& limits, std::string* error) {
  AcceptanceLimits parsed;
  return limits.empty() || ReadAcceptanceLimits(limits, &parsed, error);
}

int FinishAcceptance(const CalibrateArgs& args, const Calibration& calibration,
                     const AcceptanceLimits* limits) {
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
  if (limits == nullptr && args.certificate.empty()) return 0;
  AcceptanceResult acceptance;
  if (limits != nullptr) CheckAcceptance(calibration, *limits, &acceptance);
  if (!args.certificate.empty()) {
    CertificateInfo info = StationInfo(args.config_path);
    info.unit = UnitName(args);
    info.input_file = args.input;
    info.input_hash = calibration.provenance.log_hash;
    Certificate certificate;
    if (!MakeCertificate(calibration, info, limits, &certificate, &error)) {
      return Fail(error);
    }
    if (!WriteFileAtomically(args.certificate + ".json", CertificateToJson(certificate), &error) ||
        !WriteFileAtomically(args.certificate + ".html", CertificateToHtml(certificate), &error)) {
      return Fail(error);
    }
  }
  if (limits == nullptr) return 0;
  std::fprintf(stderr, "gravcal: limits %s: %s\n", args.limits.c_str(), acceptance.message.c_str());
  return acceptance.pass ? 0 : kOutOfLimits;
}

int FinishBatchAcceptance(const BatchArgs& args,
                          const std::vector<std::pair<std::string, std::string>>& units, int code) {
  if (args.limits.empty() && args.certificate.empty() && args.store.empty()) return code;
  std::string error;
  AcceptanceLimits limits;
  if (!args.limits.empty() && !ReadAcceptanceLimits(args.limits, &limits, &error)) {
    return Fail(error);
  }
  BatchAcceptanceOptions options;
  options.limits = args.limits.empty() ? nullptr : &limits;
  options.limits_name = args.limits;
  options.certificate_dir = args.certificate;
  options.store = args.store;
  options.report = args.report;
  options.info = StationInfo(args.config_path);
  BatchAcceptance result;
  if (!AcceptBatchFolder(args.output_dir, units, options, &result, &error)) return Fail(error);
  if (result.filed > 0) {
    std::fprintf(stderr, "gravcal: filed %zu calibrations in %s (%s)\n", result.filed,
                 args.store.c_str(), options.info.date.c_str());
  }
  if (result.certificates > 0) {
    std::fprintf(stderr, "gravcal: wrote %zu certificates in %s\n", result.certificates,
                 args.certificate.c_str());
  }
  if (args.limits.empty()) return code;
  std::string failed_units;
  for (const auto& [unit, why] : result.failed) {
    failed_units += (failed_units.empty() ? "" : ", ") + unit + " (" + why + ")";
  }
  std::fprintf(stderr, "gravcal: limits %s: %zu of %zu calibrated units pass%s%s\n",
               args.limits.c_str(), result.passed, result.checked,
               result.failed.empty() ? "" : "; fail: ", failed_units.c_str());
  return code != 0 ? code : (result.failed.empty() ? 0 : kOutOfLimits);
}

bool ResolveCalibrationPath(const std::string& calibration, const StoredCalibrationArgs& stored,
                            std::string* path, std::string* error) {
  const bool from_store = !stored.store.empty() || !stored.unit.empty();
  if (!from_store) {
    if (!stored.at.empty()) return SetError(error, "--at needs --store and --unit");
    *path = calibration;
    return true;
  }
  if (!calibration.empty()) {
    return SetError(error, "give either --calibration or --store with --unit, not both");
  }
  if (stored.store.empty() || stored.unit.empty()) {
    return SetError(error, "the calibration from a store needs both --store and --unit");
  }
  const std::string at = stored.at.empty() ? NowUtc() : stored.at;
  StoreEntry entry;
  std::string warning;
  if (!ClosestCalibration(stored.store, stored.unit, at, stored.max_age_days, &entry, &warning,
                          error)) {
    return false;
  }
  *path = stored.store + "/" + entry.file;
  std::fprintf(stderr, "gravcal: unit %s: the calibration closest to %s is %s (%s)\n",
               stored.unit.c_str(), at.c_str(), entry.date.c_str(), path->c_str());
  if (!warning.empty()) std::fprintf(stderr, "gravcal: warning: %s\n", warning.c_str());
  return true;
}

}  // namespace cli
}  // namespace gravcal
