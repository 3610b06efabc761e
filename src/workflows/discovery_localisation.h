// Private: where a discovery model (discovery.h) disagrees with the
// session: measured minus simulated per position, the worst positions, and
// the positions grouped by dominant axis, specific-force level, time and
// temperature, each in units of the position's own noise.
#ifndef GRAVCAL_SRC_WORKFLOWS_DISCOVERY_LOCALISATION_H_
#define GRAVCAL_SRC_WORKFLOWS_DISCOVERY_LOCALISATION_H_

#include "workflows/discovery_context.h"

namespace gravcal {
namespace internal {

// The disagreement of `fit` with every position, with the where_count worst
// positions per sensor and a one-line summary.
Disagreement Locate(const DiscoveryContext& ctx, const EffectFitResult& fit, int where_count);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_DISCOVERY_LOCALISATION_H_
