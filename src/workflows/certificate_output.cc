// The calibration certificate and the acceptance verdict as JSON, and the
// certificate as a self-contained HTML page (workflows/acceptance.h).
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "gravcal/workflows/acceptance.h"
#include "io/json_helpers.h"
#include "workflows/acceptance_internal.h"
#include "workflows/report/svg_plot.h"

namespace gravcal {

using internal::LimitNumber;

namespace {

nlohmann::ordered_json ChecksJson(const AcceptanceResult& result) {
  using Json = nlohmann::ordered_json;
  using internal::JsonNumber;
  Json checks = Json::array();
  for (const LimitCheck& c : result.checks) {
    checks.push_back({{"name", c.name},
                      {"measured", JsonNumber<Json>(c.measured)},
                      {"min", JsonNumber<Json>(c.min)},
                      {"max", JsonNumber<Json>(c.max)},
                      {"pass", c.pass},
                      {"checked", c.checked},
                      {"why", c.why}});
  }
  return checks;
}

}  // namespace

std::string AcceptanceToJson(const AcceptanceResult& result) {
  nlohmann::ordered_json j;
  j["verdict"] = result.pass ? "pass" : "fail";
  j["message"] = result.message;
  j["limits"] = ChecksJson(result);
  return j.dump(2) + "\n";
}

std::string CertificateToJson(const Certificate& cert) {
  using Json = nlohmann::ordered_json;
  using internal::JsonNumber;
  Json j;
  j["unit"] = cert.info.unit;
  j["date"] = cert.info.date;
  j["station"] = cert.info.station;
  j["software"] = {{"name", "gravcal"},
                   {"version", cert.info.software_version},
                   {"hash", cert.info.software_hash}};
  j["input"] = {{"file", cert.info.input_file}, {"hash", cert.info.input_hash}};
  j["config"] = {{"file", cert.info.config_name}, {"text", cert.info.config_text}};
  j["method"] = cert.method;
  j["gravity"] = {{"value", cert.gravity},
                  {"source", cert.gravity_source},
                  {"standard_uncertainty", cert.gravity_std}};
  j["residual_rms"] = JsonNumber<Json>(cert.residual_rms);
  j["measured"] = {
      {"accel_noise_density",
       {JsonNumber<Json>(cert.accel_noise_density(0)),
        JsonNumber<Json>(cert.accel_noise_density(1)),
        JsonNumber<Json>(cert.accel_noise_density(2))}},
      {"gyro_noise_density",
       {JsonNumber<Json>(cert.gyro_noise_density(0)), JsonNumber<Json>(cert.gyro_noise_density(1)),
        JsonNumber<Json>(cert.gyro_noise_density(2))}},
      {"temperature_min", JsonNumber<Json>(cert.temperature_min)},
      {"temperature_max", JsonNumber<Json>(cert.temperature_max)}};
  j["coverage_factor"] = cert.info.coverage_factor;
  Json parameters = Json::array();
  for (const CertificateEntry& e : cert.parameters) {
    Json p;
    p["name"] = e.name;
    p["unit"] = e.unit;
    p["value"] = JsonNumber<Json>(e.value);
    p["standard_uncertainty"] = JsonNumber<Json>(e.standard_uncertainty);
    p["expanded_uncertainty"] = JsonNumber<Json>(e.expanded_uncertainty);
    Json budget = Json::array();
    for (const auto& [source, u] : e.budget) {
      budget.push_back(
          {{"source", ToString(source)}, {"standard_uncertainty", JsonNumber<Json>(u)}});
    }
    p["budget"] = budget;
    parameters.push_back(p);
  }
  j["parameters"] = parameters;
  j["notes"] = cert.notes;
  if (cert.has_limits) {
    j["verdict"] = cert.acceptance.pass ? "pass" : "fail";
    j["limits"] = ChecksJson(cert.acceptance);
    j["verdict_message"] = cert.acceptance.message;
  } else {
    j["verdict"] = nullptr;
    j["verdict_message"] = "no limits given";
  }
  return j.dump(2) + "\n";
}

std::string CertificateToHtml(const Certificate& cert) {
  std::string h =
      "<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>Calibration certificate " +
      internal::HtmlEscape(cert.info.unit) +
      "</title><style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
      "td,th{border:1px solid #999;padding:2px 8px;text-align:right}th{background:#eee}"
      ".pass{color:#070}.fail{color:#b00}</style></head><body>\n";
  h += "<h1>Calibration certificate</h1>\n<table id='identity'>\n";
  const std::pair<const char*, std::string> rows[] = {
      {"Unit", cert.info.unit},
      {"Date (UTC)", cert.info.date},
      {"Station", cert.info.station},
      {"Software", "gravcal " + cert.info.software_version + " (" + cert.info.software_hash + ")"},
      {"Input", cert.info.input_file + " (" + cert.info.input_hash + ")"},
      {"Config", cert.info.config_name},
      {"Method", cert.method},
      {"Gravity", LimitNumber(cert.gravity) + " m/s^2 (" + cert.gravity_source +
                      "), u = " + LimitNumber(cert.gravity_std) + " m/s^2"},
      {"Residual |a| - g rms", LimitNumber(cert.residual_rms) + " m/s^2"},
      {"Accelerometer noise density (holds)",
       cert.accel_noise_density.allFinite()
           ? LimitNumber(cert.accel_noise_density(0)) + ", " +
                 LimitNumber(cert.accel_noise_density(1)) + ", " +
                 LimitNumber(cert.accel_noise_density(2)) + " m/s^2/sqrt(Hz)"
           : "not measured"},
      {"Gyroscope noise density (holds)", cert.gyro_noise_density.allFinite()
                                              ? LimitNumber(cert.gyro_noise_density(0)) + ", " +
                                                    LimitNumber(cert.gyro_noise_density(1)) + ", " +
                                                    LimitNumber(cert.gyro_noise_density(2)) +
                                                    " rad/s/sqrt(Hz)"
                                              : "not measured"},
      {"Temperature (holds)", std::isfinite(cert.temperature_min)
                                  ? LimitNumber(cert.temperature_min) + " to " +
                                        LimitNumber(cert.temperature_max) + " degC"
                                  : "not in the log"}};
  for (const auto& [k, v] : rows)
    h += "<tr><th>" + std::string(k) + "</th><td>" + internal::HtmlEscape(v) + "</td></tr>\n";
  h += "</table>\n<h2>Parameters (expanded uncertainty, coverage factor k = " +
       LimitNumber(cert.info.coverage_factor) +
       ")</h2>\n<table id='parameters'>\n"
       "<tr><th>parameter</th><th>unit</th><th>value</th><th>u (noise)</th><th>u (pose "
       "scatter / placement)</th><th>u (gravity)</th><th>u_c</th><th>U = k u_c</th></tr>\n";
  for (const CertificateEntry& e : cert.parameters) {
    h += "<tr class='parameter'><td>" + internal::HtmlEscape(e.name) + "</td><td>" +
         internal::HtmlEscape(e.unit) + "</td><td>" + LimitNumber(e.value) + "</td>";
    if (!std::isfinite(e.standard_uncertainty)) {
      h += "<td colspan='5'>not determined by this session</td></tr>\n";
      continue;
    }
    std::string noise = "", scatter = "", gravity = "";
    for (const auto& [source, u] : e.budget) {
      (source == UncertaintySource::kNoise     ? noise
       : source == UncertaintySource::kGravity ? gravity
                                               : scatter) = LimitNumber(u);
    }
    h += "<td>" + noise + "</td><td>" + scatter + "</td><td>" + gravity + "</td><td>" +
         LimitNumber(e.standard_uncertainty) + "</td><td>" + LimitNumber(e.expanded_uncertainty) +
         "</td></tr>\n";
  }
  h += "</table>\n<ul>\n";
  for (const std::string& n : cert.notes) h += "<li>" + internal::HtmlEscape(n) + "</li>\n";
  h += "</ul>\n<h2>Verdict</h2>\n";
  if (cert.has_limits) {
    h += "<p id='verdict' class='" + std::string(cert.acceptance.pass ? "pass" : "fail") + "'>" +
         (cert.acceptance.pass ? "PASS" : "FAIL") + ": " +
         internal::HtmlEscape(cert.acceptance.message) +
         "</p>\n<table id='limits'><tr><th>limit</th><th>measured</th><th>min</th><th>max</th>"
         "<th>result</th></tr>\n";
    for (const LimitCheck& c : cert.acceptance.checks) {
      h += "<tr><td>" + internal::HtmlEscape(c.name) + "</td><td>" + LimitNumber(c.measured) +
           "</td><td>" + LimitNumber(c.min) + "</td><td>" + LimitNumber(c.max) +
           "</td><td class='" +
           (!c.checked ? "pass'>" + internal::HtmlEscape(c.why)
            : c.pass   ? "pass'>pass"
                       : "fail'>fail: " + internal::HtmlEscape(c.why)) +
           "</td></tr>\n";
    }
    h += "</table>\n";
  } else {
    h += "<p id='verdict'>no limits given</p>\n";
  }
  h += "<h2>Configuration</h2>\n<pre>" + internal::HtmlEscape(cert.info.config_text) +
       "</pre>\n</body></html>\n";
  return h;
}

}  // namespace gravcal
