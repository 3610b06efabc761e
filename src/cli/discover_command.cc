// gravcal discover: the model discrepancy workflow (discovery.h) on one log,
// writing discovery.json and, with --report, the HTML report.
#include <cstdio>

#include "cli/commands.h"
#include "cli/read_long_log.h"
#include "gravcal/io/files.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/workflows/discovery.h"
#include "gravcal/workflows/discovery_report.h"

namespace gravcal {
namespace cli {

int RunDiscover(const LogReportArgs& args) {
  if (args.input.empty()) return Fail("discover needs --input <raw log>");
  if (args.output.empty()) return Fail("discover needs --output <discovery.json>");
  std::string error;
  if (!args.config.IsValid(&error)) return Fail(error);
  ImuLog log;
  if (!ReadLongLog(args.input, args.config.input, &log, &error)) return Fail(error);
  DiscoveryResult result;
  if (!DiscoverEffects(log, args.config.calibration, args.config.effects, args.config.discovery,
                       &result)) {
    return Fail(result.message);
  }
  for (const std::string& w : result.warnings) {
    std::fprintf(stderr, "gravcal: warning: %s\n", w.c_str());
  }
  if (!WriteFilesAtomically({{args.output, DiscoveryToJson(result)},
                             {args.report, args.report.empty() ? "" : DiscoveryToHtml(result)}},
                            &error)) {
    return Fail(error);
  }
  for (size_t i = 0; i < result.steps.size(); ++i) {
    const DiscoveryStep& s = result.steps[i];
    std::fprintf(stderr, "gravcal: step %zu: %s (p = %.3g, delta BIC %.1f; from the %s%s%s)\n",
                 i + 1, ToString(s.effect), s.p_value, s.delta_bic, s.information.c_str(),
                 s.confirmed_by.empty() ? "" : "; confirmed by the ", s.confirmed_by.c_str());
  }
  for (const SensorVerdict& v : result.sensors) {
    std::fprintf(stderr, "gravcal: %s (from the %s)\n", v.verdict.c_str(), v.information.c_str());
  }
  std::fprintf(stderr, "gravcal: %s; wrote %s%s%s\n", result.verdict.c_str(), args.output.c_str(),
               args.report.empty() ? "" : " and ", args.report.c_str());
  return 0;
}

}  // namespace cli
}  // namespace gravcal
