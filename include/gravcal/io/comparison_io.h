// gravcal/io/comparison_io.h: compare.json and verify.json
// (docs/data_contract.md, "compare.json"): consistent, p_value, level,
// parameters [{name, difference, std, z}], then the test's detail (tested,
// chi2, dof, chi2_p_value, max_shift_p_value, changed, undetermined,
// not_compared, minimal_detectable_change, power, message) and any extra
// sections. Numbers that are not finite are null.
#ifndef GRAVCAL_IO_COMPARISON_IO_H_
#define GRAVCAL_IO_COMPARISON_IO_H_

#include <string>

#include "gravcal/estimation/calibration_comparison.h"
#include "gravcal/io/calibration_io.h"

namespace gravcal {

// The JSON text (2-space indent); `sections` are appended as in
// CalibrationToJson (a section whose text is not valid JSON is left out).
std::string ComparisonToJson(const ComparisonResult& result, const JsonSections& sections);

}  // namespace gravcal

#endif  // GRAVCAL_IO_COMPARISON_IO_H_
