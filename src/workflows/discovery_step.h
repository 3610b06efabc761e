// Private: one step of a discovery run (discovery.h): the chosen effect
// added to the model, with what the report shows of it (the candidates,
// ambiguities with advice, gaps before and after, the plots' data).
#ifndef GRAVCAL_SRC_WORKFLOWS_DISCOVERY_STEP_H_
#define GRAVCAL_SRC_WORKFLOWS_DISCOVERY_STEP_H_

#include <vector>

#include "workflows/discovery_context.h"

namespace gravcal {
namespace internal {

// Adds scores[best] (extended fit best_fit) to *current: refits and
// cross-validates, appends the step (and any ambiguity) to *result. `where`
// is the disagreement of the current model. False with result->message when
// the refit fails.
bool TakeStep(const DiscoveryContext& ctx, const DiscoveryOptions& options,
              const std::vector<CandidateScore>& scores, int best, const EffectFitResult& best_fit,
              const Disagreement& where, ModelAssessment* current, DiscoveryResult* result);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_DISCOVERY_STEP_H_
