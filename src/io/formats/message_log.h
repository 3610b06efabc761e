// io/formats/message_log.h (private): the ImuLog of one sensor_msgs/Imu
// topic of a bag or MCAP file, whatever its format.
#ifndef GRAVCAL_SRC_IO_FORMATS_MESSAGE_LOG_H_
#define GRAVCAL_SRC_IO_FORMATS_MESSAGE_LOG_H_

#include <string>

#include "gravcal/core/imu_log.h"
#include "gravcal/io/log_reader.h"
#include "io/formats/message_recording.h"

namespace gravcal {
namespace internal {

// The topic to read: options.topic when given, else the only
// sensor_msgs/Imu topic. False with one line naming the file and listing
// the topics when there is none, several, or the named one is not there.
bool SelectImuTopic(const MessageRecording& recording, const std::string& path,
                    const std::string& topic, size_t* index, std::string* error);

// Reads the selected topic (recording already open) into `log`: t in
// seconds from header.stamp (or record time with options.record_time),
// gyro = angular_velocity (rad/s), accel = linear_acceleration (m/s^2).
bool ReadMessageLog(MessageRecording* recording, const std::string& path,
                    const LogReaderOptions& options, ImuLog* log, std::string* error);

// Decodes one sensor_msgs/Imu message of `topic` by its encoding.
bool DecodeImu(const RecordingTopic& topic, const RecordedMessage& message, int64_t* stamp_ns,
               Eigen::Vector3d* gyro, Eigen::Vector3d* accel, std::string* what);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_FORMATS_MESSAGE_LOG_H_
