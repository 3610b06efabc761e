// Private: what acceptance.cc and certificate_html.cc share.
#ifndef GRAVCAL_SRC_WORKFLOWS_ACCEPTANCE_INTERNAL_H_
#define GRAVCAL_SRC_WORKFLOWS_ACCEPTANCE_INTERNAL_H_

#include <string>

namespace gravcal {
namespace internal {

// A limit, a measured value or an uncertainty as text: "%.6g".
std::string LimitNumber(double v);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_ACCEPTANCE_INTERNAL_H_
