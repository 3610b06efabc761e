// gravcal history UNIT --store DIR (issue 36): the unit's calibrations in
// the store, each parameter's trend and a drift test, and compare between
// consecutive calibrations. Exit 0 (also when something drifts: the
// listing is the answer), 1 bad input.
#include <cstdio>
#include <string>

#include "cli/commands.h"
#include "gravcal/io/files.h"
#include "gravcal/workflows/calibration_store.h"

namespace gravcal {
namespace cli {

int RunHistory(const HistoryArgs& args) {
  if (args.positional.size() != 1) return Fail("history needs one unit: gravcal history UNIT");
  if (args.store.empty()) return Fail("history needs --store (the calibration store folder)");
  std::string error;
  if (!(args.level > 0.0 && args.level < 1.0)) return Fail("--level: must lie in (0, 1)");
  UnitHistory history;
  if (!ReadUnitHistory(args.store, args.positional[0], args.level, &history, &error)) {
    return Fail(error);
  }
  if (!args.output.empty() && !WriteOutput(args.output, UnitHistoryToJson(history), &error)) {
    return Fail(error);
  }
  if (!args.report.empty() &&
      !WriteFileAtomically(args.report, UnitHistoryToHtml(history), &error)) {
    return Fail(error);
  }
  if (args.output == "-") return 0;
  std::printf("unit %s: %zu calibrations\n", history.unit.c_str(), history.calibrations.size());
  for (size_t k = 0; k < history.calibrations.size(); ++k) {
    std::printf("  %s  %s", history.calibrations[k].date.c_str(),
                history.calibrations[k].file.c_str());
    if (k > 0) std::printf("  vs previous: %s", history.steps[k - 1].message.c_str());
    std::printf("\n");
  }
  std::printf("%-20s %14s %14s %10s %8s  %s\n", "parameter", "last", "slope/day", "slope sd", "p",
              "drift");
  for (const ParameterHistory& p : history.parameters) {
    std::printf("%-20s %14.6g %14.4g %10.3g %8.3g  %s\n", p.name.c_str(),
                p.values.empty() ? NAN : p.values.back(), p.slope_per_day, p.slope_std, p.p_value,
                p.drifts ? "DRIFTS" : "-");
  }
  std::printf("%s\n", history.message.c_str());
  return 0;
}

}  // namespace cli
}  // namespace gravcal
