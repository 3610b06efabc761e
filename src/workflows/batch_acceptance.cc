// A batch's units against acceptance limits, with certificates and the
// calibration store (workflows/acceptance.h, AcceptBatchFolder).
#include <sys/stat.h>

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "gravcal/io/calibration_uncertainty_io.h"
#include "gravcal/io/files.h"
#include "gravcal/workflows/acceptance.h"
#include "gravcal/workflows/calibration_store.h"
#include "workflows/report/svg_plot.h"

namespace gravcal {

namespace {

bool Exists(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

// The acceptance section of the fleet report.
std::string ReportSection(const BatchAcceptanceOptions& options, const BatchAcceptance& r) {
  std::string h = "<h2 id='acceptance'>Acceptance limits</h2>\n<p>" +
                  internal::HtmlEscape(options.limits_name) + ": <b>" + std::to_string(r.passed) +
                  " of " + std::to_string(r.checked) + " calibrated units pass</b>, " +
                  std::to_string(r.failed.size()) + " fail.</p>\n";
  if (!r.failed.empty()) {
    h += "<table class='acceptance'><tr><th>unit</th><th>failed limits</th></tr>\n";
    for (const auto& [unit, why] : r.failed) {
      h += "<tr><td>" + internal::HtmlEscape(unit) + "</td><td>" + internal::HtmlEscape(why) +
           "</td></tr>\n";
    }
    h += "</table>\n";
  }
  return h;
}

// `section` placed before the page's closing script (or </body>).
std::string WithSection(const std::string& html, const std::string& section) {
  size_t at = html.rfind("\n<script>");
  if (at == std::string::npos) at = html.rfind("</body>");
  if (at == std::string::npos) return html + section;
  return html.substr(0, at) + "\n" + section + html.substr(at);
}

std::string CsvField(const std::string& text) {
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

}  // namespace

bool AcceptBatchFolder(const std::string& output_dir,
                       const std::vector<std::pair<std::string, std::string>>& units,
                       const BatchAcceptanceOptions& options, BatchAcceptance* result,
                       std::string* error) {
  *result = BatchAcceptance();
  if (!options.certificate_dir.empty() && !MakeFolders(options.certificate_dir, error)) {
    return false;
  }
  std::string csv = "unit,verdict,failed\n";
  for (const auto& [unit, log_path] : units) {
    const std::string path = output_dir + "/" + unit + ".json";
    if (!Exists(path)) continue;  // the unit failed: summary.json says why
    std::string text;
    if (!ReadFileBytes(path, &text, error)) return false;
    Calibration c;
    if (!CalibrationUncertaintyFromJson(text, path, &c, nullptr, error)) return false;
    if (!options.store.empty()) {
      if (!FileCalibration(options.store, unit, options.info.date, text, error)) return false;
      ++result->filed;
    }
    AcceptanceResult acceptance;
    if (options.limits != nullptr) {
      CheckAcceptance(c, *options.limits, &acceptance);
      ++result->checked;
      std::string why;
      for (const LimitCheck& check : acceptance.checks) {
        if (!check.pass) why += (why.empty() ? "" : "; ") + check.name + " " + check.why;
      }
      csv += unit + "," + (acceptance.pass ? "pass" : "fail") + "," + CsvField(why) + "\n";
      if (acceptance.pass) {
        ++result->passed;
      } else {
        result->failed.emplace_back(unit, why);
      }
    }
    if (!options.certificate_dir.empty()) {
      CertificateInfo info = options.info;
      info.unit = unit;
      info.input_file = log_path;
      info.input_hash = c.provenance.log_hash;
      Certificate certificate;
      if (!MakeCertificate(c, info, options.limits, &certificate, error)) {
        *error = path + ": " + *error;
        return false;
      }
      const std::string prefix = options.certificate_dir + "/" + unit;
      if (!WriteFileAtomically(prefix + ".json", CertificateToJson(certificate), error) ||
          !WriteFileAtomically(prefix + ".html", CertificateToHtml(certificate), error)) {
        return false;
      }
      ++result->certificates;
    }
  }
  if (options.limits == nullptr) return true;
  if (!WriteFileAtomically(output_dir + "/limits.csv", csv, error)) return false;
  // summary.json: the counts and the failed units.
  const std::string summary_path = output_dir + "/summary.json";
  std::string summary_text;
  if (ReadFileBytes(summary_path, &summary_text, error)) {
    nlohmann::ordered_json summary = nlohmann::ordered_json::parse(summary_text, nullptr, false);
    if (summary.is_object()) {
      nlohmann::ordered_json failed = nlohmann::ordered_json::array();
      for (const auto& [unit, why] : result->failed) {
        failed.push_back({{"unit", unit}, {"why", why}});
      }
      summary["acceptance"] = {{"limits", options.limits_name},
                               {"checked", result->checked},
                               {"pass", result->passed},
                               {"fail", result->failed.size()},
                               {"failed", failed}};
      if (!WriteFileAtomically(summary_path, summary.dump(2) + "\n", error)) return false;
    }
  }
  error->clear();
  if (!options.report.empty() && Exists(options.report)) {
    std::string html;
    if (!ReadFileBytes(options.report, &html, error) ||
        !WriteFileAtomically(options.report, WithSection(html, ReportSection(options, *result)),
                             error)) {
      return false;
    }
  }
  return true;
}

}  // namespace gravcal
