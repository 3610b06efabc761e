// Private: what each kind of warning (core/types.h WarningCode) means for
// the user and the action that fixes it, for the warning table of the
// calibration report. The message of a warning says what happened in this
// session; the advice says what that kind of warning means in general.
#ifndef GRAVCAL_SRC_WORKFLOWS_REPORT_WARNING_ADVICE_H_
#define GRAVCAL_SRC_WORKFLOWS_REPORT_WARNING_ADVICE_H_

#include <string>

#include "gravcal/core/types.h"

namespace gravcal {
namespace internal {

struct WarningAdvice {
  // What the warning means; empty for a code without advice (only
  // kUnclassified, which the report marks as unexplained).
  std::string meaning;
  // The action that fixes it.
  std::string action;
};

WarningAdvice AdviceFor(WarningCode code);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_REPORT_WARNING_ADVICE_H_
