#include "io/formats/file_format.h"

#include <cerrno>
#include <cstring>
#include <fstream>

#include "io/formats/reader_module.h"

namespace gravcal {
namespace internal {
namespace {

bool StartsWith(std::string_view s, std::string_view prefix) {
  return s.size() >= prefix.size() && s.compare(0, prefix.size(), prefix) == 0;
}

bool IsEurocHeader(std::string_view head) {
  const size_t newline = head.find('\n');
  const std::string_view line = head.substr(0, newline);
  return StartsWith(line, "#timestamp") && line.find("w_RS_S_x") != std::string_view::npos &&
         line.find("a_RS_S_z") != std::string_view::npos;
}

}  // namespace

const char* FileFormatName(FileFormat format) {
  switch (format) {
    case FileFormat::kText:
      return "text log";
    case FileFormat::kEuroc:
      return "EuRoC / TUM-VI CSV";
    case FileFormat::kRos1Bag:
      return "ROS 1 bag";
    case FileFormat::kRosbag2Sqlite:
      return "rosbag2 SQLite bag";
    case FileFormat::kMcap:
      return "MCAP file";
  }
  return "?";
}

bool DetectFileFormat(std::string_view head, FileFormat* format, std::string* what) {
  if (StartsWith(head, "#ROSBAG V2.0\n")) {
    *format = FileFormat::kRos1Bag;
  } else if (StartsWith(head, "#ROSBAG V")) {
    const std::string version(head.substr(9, std::min<size_t>(head.find('\n'), 12) - 9));
    *what = "a ROS 1 bag of version '" + version + "'; gravcal reads version 2.0";
    return false;
  } else if (StartsWith(head, std::string_view("SQLite format 3\0", 16))) {
    *format = FileFormat::kRosbag2Sqlite;
  } else if (StartsWith(head, "\x89MCAP")) {
    *format = FileFormat::kMcap;
  } else if (IsEurocHeader(head)) {
    *format = FileFormat::kEuroc;
  } else if (head.find('\0') != std::string_view::npos) {
    *what =
        "binary data of a kind gravcal does not read (not a ROS 1 bag, rosbag2 .db3 or MCAP "
        "file)";
    return false;
  } else {
    *format = FileFormat::kText;
  }
  return true;
}

bool DetectFileFormatOf(const std::string& path, FileFormat* format, std::string* error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *error = path + ": cannot open: " + std::strerror(errno);
    return false;
  }
  char head[4096];
  in.read(head, sizeof(head));
  std::string what;
  if (!DetectFileFormat(std::string_view(head, static_cast<size_t>(in.gcount())), format, &what)) {
    *error = path + ": " + what;
    return false;
  }
  return true;
}

std::unique_ptr<MessageRecording> NewMessageRecording(FileFormat format) {
  switch (format) {
    case FileFormat::kRos1Bag:
    case FileFormat::kRosbag2Sqlite:
    case FileFormat::kMcap:
      // Read by the reader module, loaded when the file is opened.
      return NewModuleRecording(static_cast<int>(format), FileFormatName(format));
    default:
      return nullptr;
  }
}

LogReaderOptions EurocOptions(const LogReaderOptions& base) {
  LogReaderOptions options = base;
  options.format = LogFormat::kCsv;
  options.columns = {"t", "gx", "gy", "gz", "ax", "ay", "az"};
  options.time_scale = 1e-9;
  return options;
}

bool LayoutFromFile(const LogReaderOptions& options) {
  return options.format == LogFormat::kCsv && options.columns.empty() && options.rename.empty() &&
         options.skip_lines == 0 && options.gyro_path.empty();
}

}  // namespace internal
}  // namespace gravcal
