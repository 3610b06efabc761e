// io/c_corrector_export.h (private): the C99 corrector of a calibration
// (calibration_export.h, target c).
#ifndef GRAVCAL_IO_C_CORRECTOR_EXPORT_H_
#define GRAVCAL_IO_C_CORRECTOR_EXPORT_H_

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

// The thermal model's part (c_thermal_export.cc; all "" without an active
// thermal model): the arrays and helper functions; the line
// "const real x = gravcal_thermal_x(temp_c);" of a sensor; the loop
// subtracting db(x) from `target`[0..2]; the block replacing `y` by
// (I + D(x))^-1 y. The thermal lag is not held (the functions take no
// temperature rate).
bool CThermalActive(const ImuCorrector& c);
std::string CThermalDefinitions(const ImuCorrector& c, const CPrecision& p);
std::string CThermalOffsetLine(const ImuCorrector& c, const CPrecision& p, ThermalSensor sensor);
std::string CThermalBias(const ImuCorrector& c, const CPrecision& p, ThermalSensor sensor,
                         const std::string& target);
std::string CThermalRemoveScale(const ImuCorrector& c, const CPrecision& p, ThermalSensor sensor,
                                const std::string& y);

// The effects the generated functions hold (the C target drops others and
// its export notes name them).
std::vector<Effect> CCorrectorEffects();

// gravcal_correct.h and gravcal_correct.c; `comment` lines head both.
std::vector<ExportedFile> CCorrectorFiles(const ImuCorrector& corrector,
                                          const std::vector<std::string>& comment);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_IO_C_CORRECTOR_EXPORT_H_
