// Private: one round of candidates in a discovery run (discovery.h): every
// candidate effect tried on top of the current model, scored (likelihood
// ratio, delta BIC, cross-validated gap), and the one to name chosen.
#ifndef GRAVCAL_SRC_WORKFLOWS_DISCOVERY_CANDIDATES_H_
#define GRAVCAL_SRC_WORKFLOWS_DISCOVERY_CANDIDATES_H_

#include <string>
#include <vector>

#include "workflows/discovery_context.h"

namespace gravcal {
namespace internal {

// Tries every effect of `candidates` on top of `current`: scores[i] says
// whether candidates[i] was tried (with its delta chi2 and gaps) or why not,
// fits[i] holds its extended fit (empty when not tried). An effect that
// cannot be tested in this session is warned about once (names kept in
// *warned).
void TryCandidates(const DiscoveryContext& ctx, const ModelAssessment& current,
                   const std::vector<Effect>& candidates, const DiscoveryOptions& options,
                   std::vector<std::string>* warned, std::vector<std::string>* warnings,
                   std::vector<CandidateScore>* scores, std::vector<EffectFitResult>* fits);

// The likelihood-ratio p-value and delta BIC of every candidate tried, each
// from its own sensor's residuals, noise level and residual count (see
// discovery_candidates.cc for the noise scale).
void ScoreCandidates(const DiscoveryContext& ctx, const ModelAssessment& current,
                     const std::vector<EffectFitResult>& fits, std::vector<CandidateScore>* scores);

// Marks the significant candidates (with the reason of each that is not;
// each sensor's tests at `significance` divided among its own candidates)
// and returns the index of the one to name, or -1; looks at pairs of
// candidates masking each other when none is significant alone. A
// candidate is cross-validated (from fits[i], its extended fit) only when
// its likelihood-ratio, BIC and confirmation tests pass; the others keep a
// NaN cross-validated gap for their sensor.
int ChooseCandidate(const DiscoveryContext& ctx, const ModelAssessment& current,
                    const DiscoveryOptions& options, const std::vector<EffectFitResult>& fits,
                    std::vector<CandidateScore>* scores);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_DISCOVERY_CANDIDATES_H_
