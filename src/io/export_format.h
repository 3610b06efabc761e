// io/export_format.h (private): numbers and matrices as the exporters write
// them: the shortest decimal that reads back to the same double.
#ifndef GRAVCAL_IO_EXPORT_FORMAT_H_
#define GRAVCAL_IO_EXPORT_FORMAT_H_

#include <Eigen/Core>
#include <string>

#include "util/numbers.h"

namespace gravcal {
namespace internal {

// "[a, b, c]" of one row.
template <typename Derived>
std::string YamlRow(const Eigen::MatrixBase<Derived>& row) {
  std::string s = "[";
  for (Eigen::Index i = 0; i < row.size(); ++i) s += (i ? ", " : "") + ExactNumber(row(i));
  return s + "]";
}

// A 3x3 or 4x4 matrix as a YAML list of rows, each on its own line with
// `indent` spaces before the dash.
template <typename Derived>
std::string YamlMatrix(const Eigen::MatrixBase<Derived>& m, int indent) {
  std::string s;
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    s += std::string(indent, ' ') + "- " + YamlRow(m.row(r)) + "\n";
  }
  return s;
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_IO_EXPORT_FORMAT_H_
