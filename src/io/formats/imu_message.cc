#include "io/formats/imu_message.h"

#include <cstring>

namespace gravcal {
namespace internal {
namespace {

// The float64 fields after frame_id: orientation 4, covariance 9, angular
// velocity 3 (at 13), covariance 9, linear acceleration 3 (at 25), covariance 9.
constexpr size_t kDoubles = 37;
constexpr size_t kAngularVelocity = 13;
constexpr size_t kLinearAcceleration = 25;

bool SetWhat(std::string* what, std::string message) {
  if (what != nullptr) *what = std::move(message);
  return false;
}

uint32_t Load32(const uint8_t* p, bool big_endian) {
  return big_endian
             ? (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3]
             : (uint32_t{p[3]} << 24) | (uint32_t{p[2]} << 16) | (uint32_t{p[1]} << 8) | p[0];
}

double LoadDouble(const uint8_t* p, bool big_endian) {
  uint64_t bits = 0;
  for (int i = 0; i < 8; ++i) bits |= uint64_t{p[big_endian ? 7 - i : i]} << (8 * i);
  double x;
  std::memcpy(&x, &bits, sizeof(x));
  return x;
}

// Reads the 37 doubles at `p` (bounds checked by the caller).
bool ReadVectors(const uint8_t* p, bool big_endian, ImuMessage* message, std::string* what) {
  for (int i = 0; i < 3; ++i) {
    message->angular_velocity[i] = LoadDouble(p + 8 * (kAngularVelocity + i), big_endian);
    message->linear_acceleration[i] = LoadDouble(p + 8 * (kLinearAcceleration + i), big_endian);
  }
  if (!message->angular_velocity.allFinite() || !message->linear_acceleration.allFinite()) {
    return SetWhat(what, "angular_velocity or linear_acceleration is not finite");
  }
  return true;
}

std::string TooShort(size_t size) {
  return "message is " + std::to_string(size) + " bytes, too short for sensor_msgs/Imu";
}

}  // namespace

bool DecodeRos1Imu(const uint8_t* data, size_t size, ImuMessage* message, std::string* what) {
  if (size < 16) return SetWhat(what, TooShort(size));
  const uint32_t sec = Load32(data + 4, false);
  const uint32_t nsec = Load32(data + 8, false);
  const uint32_t frame_length = Load32(data + 12, false);
  if (frame_length > size - 16 || size - 16 - frame_length < 8 * kDoubles) {
    return SetWhat(what, TooShort(size));
  }
  if (size - 16 - frame_length != 8 * kDoubles) {
    return SetWhat(
        what, "message is " + std::to_string(size) + " bytes, not the size of a sensor_msgs/Imu");
  }
  if (nsec >= 1000000000u) return SetWhat(what, "header.stamp.nsec is above 1e9");
  message->stamp_ns = int64_t{sec} * 1000000000 + nsec;
  return ReadVectors(data + 16 + frame_length, false, message, what);
}

bool DecodeCdrImu(const uint8_t* data, size_t size, ImuMessage* message, std::string* what) {
  if (size < 4 + 12) return SetWhat(what, TooShort(size));
  if (data[0] != 0 || data[1] > 1) {
    return SetWhat(what, "not plain CDR (encapsulation " + std::to_string(data[0]) + " " +
                             std::to_string(data[1]) + ")");
  }
  const bool big_endian = data[1] == 0;
  const uint8_t* body = data + 4;
  const size_t body_size = size - 4;
  const int32_t sec = static_cast<int32_t>(Load32(body, big_endian));
  const uint32_t nsec = Load32(body + 4, big_endian);
  const uint32_t frame_length = Load32(body + 8, big_endian);
  if (frame_length > body_size - 12) return SetWhat(what, TooShort(size));
  const size_t doubles = (12 + size_t{frame_length} + 7) / 8 * 8;
  if (doubles > body_size || body_size - doubles < 8 * kDoubles)
    return SetWhat(what, TooShort(size));
  if (nsec >= 1000000000u) return SetWhat(what, "header.stamp.nanosec is above 1e9");
  message->stamp_ns = int64_t{sec} * 1000000000 + nsec;
  return ReadVectors(body + doubles, big_endian, message, what);
}

bool IsImuType(const std::string& type) {
  return type == "sensor_msgs/Imu" || type == "sensor_msgs/msg/Imu";
}

}  // namespace internal
}  // namespace gravcal
