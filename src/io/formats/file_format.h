// io/formats/file_format.h (private): what kind of file a log is, from its
// first bytes, so that no flag is needed: "#ROSBAG V2.0" (ROS 1 bag), the
// SQLite header (rosbag2 .db3; the tables are checked on opening), the MCAP
// magic "\x89MCAP0\r\n", an EuRoC / TUM-VI header line "#timestamp [ns],
// w_RS_S_x ...", else text for the contract CSV reader.
#ifndef GRAVCAL_SRC_IO_FORMATS_FILE_FORMAT_H_
#define GRAVCAL_SRC_IO_FORMATS_FILE_FORMAT_H_

#include <memory>
#include <string>
#include <string_view>

#include "gravcal/io/log_reader.h"
#include "io/formats/message_recording.h"

namespace gravcal {
namespace internal {

enum class FileFormat { kText, kEuroc, kRos1Bag, kRosbag2Sqlite, kMcap };

// "contract CSV", "EuRoC / TUM-VI CSV", "ROS 1 bag", ...
const char* FileFormatName(FileFormat format);

// From the first bytes of a file (a few KiB are enough). False with `what`
// for a file gravcal recognises and cannot read (a ROS 1 bag of another
// version) or binary data of no known kind.
bool DetectFileFormat(std::string_view head, FileFormat* format, std::string* what);

// Reads the first bytes of `path` and detects; errors name the file.
bool DetectFileFormatOf(const std::string& path, FileFormat* format, std::string* error);

// The reader of a message-based format (null for text formats).
std::unique_ptr<MessageRecording> NewMessageRecording(FileFormat format);

// EuRoC / TUM-VI: `#timestamp [ns],w_RS_S_x,...,a_RS_S_z` (units in
// brackets): nanosecond stamps, gyroscope (rad/s) before accelerometer
// (m/s^2). The options that read it with the contract CSV parser once the
// leading '#' is dropped, keeping `base`'s other fields.
LogReaderOptions EurocOptions(const LogReaderOptions& base);

// True when `options` leave the layout to the file (no columns, rename or
// skipped lines given), so that an EuRoC header may be recognised.
bool LayoutFromFile(const LogReaderOptions& options);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_FORMATS_FILE_FORMAT_H_
