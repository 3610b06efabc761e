// The verdict of a calibration report: good, look at these, or record
// again, with its reasons (private to workflows/report).
#ifndef GRAVCAL_WORKFLOWS_REPORT_CALIBRATION_VERDICT_H_
#define GRAVCAL_WORKFLOWS_REPORT_CALIBRATION_VERDICT_H_

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include "gravcal/core/calibration.h"

namespace gravcal {
namespace internal {

enum class VerdictLevel { kGood, kLook, kAgain };

struct Verdict {
  VerdictLevel level = VerdictLevel::kGood;
  std::vector<std::string> reasons;
  // What is said without raising the level (an expected, handled excess).
  std::vector<std::string> notes;
  void Raise(VerdictLevel l, const std::string& reason) {
    level = std::max(level, l);
    reasons.push_back(reason);
  }
};

// Residual of pose k after refinement in its own sigma; NaN without one.
double AfterSigma(const PositionReport& p);

// The per-pose outlier test: |residual / sigma| beyond this has two-sided
// probability 0.01 / n when the sigmas (white noise plus the pose-to-pose
// scatter, when absorbed) are honest: Bonferroni over the n poses, so a
// session of honest poses names none with probability 0.99 whatever n is.
double OutlierThreshold(size_t n);

// "pose 3 (+x up, 12.0 to 22.0 s)".
std::string PoseName(const Calibration& c, size_t k);

// Three situations are kept apart (issue 33): the noise model being
// optimistic for hand placement (expected; the variance component absorbs
// it and says so, no look needed), named disturbed poses (the outlier test
// above, with what to do), and a session that cannot determine what was
// asked or fit at all. "Record the session again" only where re-recording
// helps: the calibration failed, or too many poses were disturbed to trust.
Verdict Judge(const Calibration& c);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_REPORT_CALIBRATION_VERDICT_H_
