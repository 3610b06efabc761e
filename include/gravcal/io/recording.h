// gravcal/io/recording.h: what a log file holds, for `gravcal inspect` and
// for a batch over the IMU topics of one bag.
//
// Formats are recognised from the file's first bytes (docs/data_contract.md,
// "Formats"): contract CSV or whitespace text, EuRoC / TUM-VI CSV, ROS 1 bag
// (V2.0), rosbag2 SQLite (.db3) and MCAP. Bags and MCAP files hold topics;
// sensor_msgs/Imu topics are the ones gravcal reads. A text log is one
// "topic" with an empty name.
#ifndef GRAVCAL_IO_RECORDING_H_
#define GRAVCAL_IO_RECORDING_H_

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "gravcal/io/log_reader.h"

namespace gravcal {

struct TopicSummary {
  std::string name;
  std::string type;
  // True for sensor_msgs/Imu (the topics gravcal can read).
  bool imu = false;
  int64_t messages = 0;
  // Seconds: the first and last time (header stamps for IMU topics unless
  // record_time, record time otherwise) and the mean rate over the span.
  double first_s = 0.0;
  double last_s = 0.0;
  double rate_hz = 0.0;
  // IMU topics: the median interval, the intervals longer than twice it
  // (gaps) and the longest interval, seconds.
  double median_interval_s = 0.0;
  int64_t gaps = 0;
  double longest_interval_s = 0.0;
};

struct RecordingSummary {
  // "ROS 1 bag", "MCAP file", "EuRoC / TUM-VI CSV", "text log", ...
  std::string format;
  std::vector<TopicSummary> topics;
};

// Reads the whole file once (streaming). False with one line naming the file
// when it cannot be read.
bool InspectRecording(const std::string& path, const LogReaderOptions& options,
                      RecordingSummary* summary, std::string* error);

// The sensor_msgs/Imu topics of a bag or MCAP file, in the file's order; for
// a text log, one empty name. Reads only the file's topic list.
bool ListImuTopics(const std::string& path, std::vector<std::string>* topics, std::string* error);

// True when `first_bytes` (the first KiB of a file) start a ROS 1 bag,
// rosbag2 .db3 or MCAP file: those are read from their path (ReadImuLog),
// never from memory (ParseImuLog).
bool IsMessageRecording(std::string_view first_bytes);

}  // namespace gravcal

#endif  // GRAVCAL_IO_RECORDING_H_
