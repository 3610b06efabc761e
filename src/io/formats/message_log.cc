#include "io/formats/message_log.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "io/formats/imu_message.h"
#include "util/error.h"

namespace gravcal {
namespace internal {
namespace {

// "/imu0 (sensor_msgs/Imu), /cam0 (sensor_msgs/Image)".
std::string Listing(const std::vector<RecordingTopic>& topics, bool imu_only) {
  std::string out;
  for (const RecordingTopic& t : topics) {
    if (imu_only && !IsImuType(t.type)) continue;
    out += (out.empty() ? "" : ", ") + OneLine(t.name) + " (" + OneLine(t.type) + ")";
  }
  return out.empty() ? std::string("none") : out;
}

// The least a sensor_msgs/Imu takes serialised, in ROS 1 or CDR: its
// orientation, three covariances and two vectors are 37 doubles.
constexpr uint64_t kImuMessageBytes = 37 * 8;

// The samples to reserve for a topic that the file says holds `messages`.
// That count is the file's own word (an MCAP statistics record, a bag's
// index), and a damaged one asked for 25.7 GB (fuzz/regressions/mcap), so the
// reservation is also bounded by the messages the file's size could hold
// uncompressed. A compressed file may hold more; the vectors then grow as
// its messages are read.
size_t SamplesToReserve(int64_t messages, const std::string& path) {
  std::error_code ec;
  const uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (messages <= 0 || ec) return 0;
  return static_cast<size_t>(
      std::min<uint64_t>(static_cast<uint64_t>(messages), bytes / kImuMessageBytes));
}

}  // namespace

bool SelectImuTopic(const MessageRecording& recording, const std::string& path,
                    const std::string& topic, size_t* index, std::string* error) {
  const std::vector<RecordingTopic>& topics = recording.topics();
  const std::string kind = std::string(recording.FormatName());
  if (!topic.empty()) {
    for (size_t i = 0; i < topics.size(); ++i) {
      if (topics[i].name != topic) continue;
      if (!IsImuType(topics[i].type)) {
        return SetError(error, path + ": topic '" + topic + "' holds " + OneLine(topics[i].type) +
                                   ", not sensor_msgs/Imu");
      }
      *index = i;
      return true;
    }
    return SetError(
        error, path + ": no topic '" + topic + "'; the IMU topics are " + Listing(topics, true));
  }
  std::vector<size_t> imu;
  for (size_t i = 0; i < topics.size(); ++i) {
    if (IsImuType(topics[i].type)) imu.push_back(i);
  }
  if (imu.empty()) {
    return SetError(error, path + ": a " + kind + " with no sensor_msgs/Imu topic (topics: " +
                               Listing(topics, false) + ")");
  }
  if (imu.size() > 1) {
    return SetError(error,
                    path + ": " + std::to_string(imu.size()) +
                        " sensor_msgs/Imu topics, give one with --topic: " + Listing(topics, true));
  }
  *index = imu[0];
  return true;
}

bool DecodeImu(const RecordingTopic& topic, const RecordedMessage& message, int64_t* stamp_ns,
               Eigen::Vector3d* gyro, Eigen::Vector3d* accel, std::string* what) {
  ImuMessage imu;
  bool ok = false;
  if (topic.encoding == MessageEncoding::kRos1) {
    ok = DecodeRos1Imu(message.data, message.size, &imu, what);
  } else if (topic.encoding == MessageEncoding::kCdr) {
    ok = DecodeCdrImu(message.data, message.size, &imu, what);
  } else {
    *what = "messages are not in CDR or ROS 1 serialisation";
  }
  if (!ok) return false;
  *stamp_ns = imu.stamp_ns;
  *gyro = imu.angular_velocity;
  *accel = imu.linear_acceleration;
  return true;
}

bool ReadMessageLog(MessageRecording* recording, const std::string& path,
                    const LogReaderOptions& options, ImuLog* log, std::string* error) {
  size_t index = 0;
  if (!SelectImuTopic(*recording, path, options.topic, &index, error)) return false;
  const RecordingTopic topic = recording->topics()[index];
  if (topic.encoding == MessageEncoding::kRos1 && !topic.md5sum.empty() &&
      topic.md5sum != kRos1ImuMd5) {
    return SetError(error, path + ": topic '" + OneLine(topic.name) +
                               "' has a sensor_msgs/Imu definition other than the standard one "
                               "(MD5 " +
                               OneLine(topic.md5sum) + ")");
  }
  ImuLog read;
  const size_t reserved = SamplesToReserve(topic.messages, path);
  read.t.reserve(reserved);
  read.accel.reserve(reserved);
  read.gyro.reserve(reserved);
  std::vector<bool> wanted(recording->topics().size(), false);
  wanted[index] = true;
  const std::string where = path + ": topic '" + OneLine(topic.name) + "' message ";
  auto visit = [&](const RecordedMessage& message) {
    int64_t stamp_ns = 0;
    Eigen::Vector3d gyro, accel;
    std::string what;
    const size_t i = read.t.size();
    if (!DecodeImu(topic, message, &stamp_ns, &gyro, &accel, &what)) {
      return SetError(error, where + std::to_string(i) + ": " + what);
    }
    const int64_t ns = options.record_time ? message.record_time_ns : stamp_ns;
    const double t = static_cast<double>(ns) * 1e-9;
    if (i > 0 && !(t > read.t.back())) {
      return SetError(error, where + std::to_string(i) + ": time " + std::to_string(t) +
                                 " s does not increase (previous " + std::to_string(read.t.back()) +
                                 " s)" +
                                 (options.record_time ? ""
                                                      : "; --record_time true uses the "
                                                        "recorder's times"));
    }
    read.t.push_back(t);
    read.gyro.push_back(gyro);
    read.accel.push_back(accel);
    return true;
  };
  if (!recording->Read(wanted, visit, error)) return false;
  if (read.t.empty())
    return SetError(error, path + ": topic '" + OneLine(topic.name) + "' has no messages");
  read.source = path;
  *log = std::move(read);
  return true;
}

}  // namespace internal
}  // namespace gravcal
