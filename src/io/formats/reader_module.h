// io/formats/reader_module.h (private): the readers of bags and MCAP files
// (ROS 1 bag, rosbag2 SQLite, MCAP) live in a module of their own,
// libgravcal_formats.so, loaded with dlopen the first time such a file is
// opened, so that a CSV calibration loads none of SQLite, zstd, lz4, zlib or
// the ROS libraries (issue 39 part 5; benchmarks/startup.sh counts them).
//
// The module exports two C functions: kReaderModuleVersion returns the
// GRAVCAL_VERSION it was built with (a module of another version is
// refused, by name), kReaderModuleNew returns a new reader of a FileFormat
// (as int), owned by the caller, or null for a text format.
//
// Where the module is looked for: the folder GRAVCAL_MODULE_DIR
// (environment) names, when set, and nothing else; else, in order, the folder of the binary holding
// this code (the tool, the Python extension, a program linking libgravcal) and its
// ../lib/gravcal and ../lib64/gravcal; the install folder
// (<prefix>/<libdir>/gravcal); the build tree.
#ifndef GRAVCAL_SRC_IO_FORMATS_READER_MODULE_H_
#define GRAVCAL_SRC_IO_FORMATS_READER_MODULE_H_

#include <memory>
#include <string>

#include "io/formats/message_recording.h"

namespace gravcal {
namespace internal {

constexpr char kReaderModuleFile[] = "libgravcal_formats.so";
constexpr char kReaderModuleVersion[] = "gravcal_formats_version";
constexpr char kReaderModuleNew[] = "gravcal_formats_new_recording";

using ReaderModuleVersionFunction = const char* (*)();
using ReaderModuleNewFunction = MessageRecording* (*)(int format);

// A reader of `format` (a message-based FileFormat, as int) whose Open
// loads the module first; a module that cannot be loaded makes Open fail
// with one line: "<path>: cannot read a ROS 1 bag: <why> (...)".
std::unique_ptr<MessageRecording> NewModuleRecording(int format, const char* format_name);

// Loads the module (once per process) and says where from; false with *why
// when it cannot be loaded. For `gravcal --version` style reports and tests.
bool LoadReaderModule(std::string* where, std::string* why);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_FORMATS_READER_MODULE_H_
