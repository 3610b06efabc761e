// io/c_corrector_export.h (private): the C99 corrector of a calibration
// (calibration_export.h, target c).
#ifndef GRAVCAL_IO_C_CORRECTOR_EXPORT_H_
#define GRAVCAL_IO_C_CORRECTOR_EXPORT_H_

#include <set>
#include <string>
#include <vector>

#include "gravcal/io/calibration_export.h"

namespace gravcal {
namespace internal {

// A C literal of v (exact for double; rounded by the compiler for float).
std::string CNumber(double v, bool f);

// One precision of the generated code: "double" or "float", the array
// prefix ("D_", "F_") and the function suffix ("", "_f").
struct CPrecision {
  bool single = false;
  std::string real;
  std::string prefix;
  std::string suffix;
};

// An effect's C term (its definition's kC, effect_definition.h) in one
// precision: `p` becomes `array`, `x` becomes `input`; in single precision
// the real literals take f and the math functions their float names
// (sqrtf). `used` (may be null) collects the identifiers the term reads.
std::string CExpression(const char* expression, const std::string& array, const std::string& input,
                        bool single, std::set<std::string>* used);

// The thermal model's part (c_thermal_export.cc; all "" without an active
// thermal model): the arrays and helper functions; the line
// "const real x = gravcal_thermal_x(<temperature>);" of a sensor; the loop
// subtracting db(x) from `target`[0..2]; the block replacing `y` by
// (I + D(x))^-1 y.
bool CThermalActive(const ImuCorrector& c);
std::string CThermalDefinitions(const ImuCorrector& c, const CPrecision& p);
std::string CThermalOffsetLine(const ImuCorrector& c, const CPrecision& p, ThermalSensor sensor,
                               const std::string& temperature);
// The thermal lag's state functions: gravcal_lag_init and the static
// gravcal_lag_element (the element's temperature at a sample: the exact
// first-order lag filter of ThermalElementRate, core/thermal_rate.h, so
// gravcal_correct_sample gives gravcal apply's numbers); the element is at
// the recorded temperature without a lag.
std::string CLagFunctions(const ImuCorrector& c, const CPrecision& p);
std::string CThermalBias(const ImuCorrector& c, const CPrecision& p, ThermalSensor sensor,
                         const std::string& target);
std::string CThermalRemoveScale(const ImuCorrector& c, const CPrecision& p, ThermalSensor sensor,
                                const std::string& y);

// gravcal_correct.h and gravcal_correct.c; `comment` lines head both.
std::vector<ExportedFile> CCorrectorFiles(const ImuCorrector& corrector,
                                          const std::vector<std::string>& comment);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_IO_C_CORRECTOR_EXPORT_H_
