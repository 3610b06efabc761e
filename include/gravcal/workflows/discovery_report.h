// gravcal/workflows/discovery_report.h: the discovery result as discovery.json and as
// a self-contained HTML report (inline SVG plots, no external assets).
//
// discovery.json: `baseline` (model, gap and cross-validated gap), `steps`
// in order (effect, description, parameters with std, p_value, delta_bic,
// gap_before / gap_after / cv_gap_before / cv_gap_after in the unit of the
// effect's sensor, `where` the model disagreed), `ambiguous` (pairs this
// session cannot separate, with advice), `final_model`, `verdict`
// ("no significant missing effect" when nothing was found), `warnings`.
#ifndef GRAVCAL_WORKFLOWS_DISCOVERY_REPORT_H_
#define GRAVCAL_WORKFLOWS_DISCOVERY_REPORT_H_

#include <string>

#include "gravcal/workflows/discovery.h"

namespace gravcal {

std::string DiscoveryToJson(const DiscoveryResult& result);

std::string DiscoveryToHtml(const DiscoveryResult& result);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_DISCOVERY_REPORT_H_
