// gravcal/io/files.h: whole files in and out, with errors that name the file.
#ifndef GRAVCAL_IO_FILES_H_
#define GRAVCAL_IO_FILES_H_

#include <string>

namespace gravcal {

// Reads a whole file into `bytes`; errors name the file ("x.csv: cannot
// open: No such file or directory").
bool ReadFileBytes(const std::string& path, std::string* bytes, std::string* error);

// Writes `contents` to `path` through a temporary file in the same directory
// and a rename, so a failure never leaves a partial file.
bool WriteFileAtomically(const std::string& path, const std::string& contents, std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_IO_FILES_H_
