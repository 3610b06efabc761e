// io/formats/imu_message.h (private): sensor_msgs/Imu decoded from its two
// wire forms, with the fields gravcal uses.
//
// ROS 1 (sensor_msgs/Imu, MD5 6a62c6daae103f4ff57a132d6f95cec2): little
// endian, packed: uint32 seq, uint32 sec, uint32 nsec, string frame_id
// (uint32 length + bytes), then 37 float64: orientation[4],
// orientation_covariance[9], angular_velocity[3], its covariance[9],
// linear_acceleration[3], its covariance[9].
// ROS 2 (sensor_msgs/msg/Imu) in CDR: a 4-byte encapsulation header (0, 1 =
// little endian; 0, 0 = big endian), then, each primitive aligned to its
// size counted from the end of that header: int32 sec, uint32 nanosec,
// string frame_id (uint32 length including the terminating NUL + bytes),
// then the same 37 float64 (aligned to 8).
// Units are SI as ROS defines them: rad/s, m/s^2.
#ifndef GRAVCAL_SRC_IO_FORMATS_IMU_MESSAGE_H_
#define GRAVCAL_SRC_IO_FORMATS_IMU_MESSAGE_H_

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>

namespace gravcal {
namespace internal {

// The MD5 sum of the standard ROS 1 sensor_msgs/Imu definition.
constexpr const char kRos1ImuMd5[] = "6a62c6daae103f4ff57a132d6f95cec2";

struct ImuMessage {
  // header.stamp, ns since the epoch.
  int64_t stamp_ns = 0;
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();
};

// False with `what` ("message is 12 bytes, too short for sensor_msgs/Imu")
// when the bytes are not one message.
bool DecodeRos1Imu(const uint8_t* data, size_t size, ImuMessage* message, std::string* what);
bool DecodeCdrImu(const uint8_t* data, size_t size, ImuMessage* message, std::string* what);

// True for "sensor_msgs/Imu" and "sensor_msgs/msg/Imu".
bool IsImuType(const std::string& type);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_FORMATS_IMU_MESSAGE_H_
