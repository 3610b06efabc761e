// io/c_corrector_export.h (private): the C99 corrector of a calibration
// (calibration_export.h, target c).
#ifndef GRAVCAL_IO_C_CORRECTOR_EXPORT_H_
#define GRAVCAL_IO_C_CORRECTOR_EXPORT_H_

#include <string>
#include <vector>

#include "gravcal/io/calibration_export.h"

namespace gravcal {
namespace internal {

// gravcal_correct.h and gravcal_correct.c; `comment` lines head both.
std::vector<ExportedFile> CCorrectorFiles(const ImuCorrector& corrector,
                                          const std::vector<std::string>& comment);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_IO_C_CORRECTOR_EXPORT_H_
