// io/formats/message_recording.h (private): the one interface behind which
// the message-based recording formats are read: ROS 1 bags, rosbag2 SQLite
// (.db3) and MCAP. A format lists its topics and hands out the messages of
// the topics asked for, in file order, one at a time, so that a file of many
// GB is read in bounded memory; message_log.cc turns the messages of one
// sensor_msgs/Imu topic into an ImuLog, inspect.cc summarises them.
#ifndef GRAVCAL_SRC_IO_FORMATS_MESSAGE_RECORDING_H_
#define GRAVCAL_SRC_IO_FORMATS_MESSAGE_RECORDING_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace gravcal {
namespace internal {

// How a topic's messages are serialised.
enum class MessageEncoding {
  // ROS 1 serialisation (little endian, no alignment).
  kRos1,
  // OMG CDR with its 4-byte encapsulation header (ROS 2).
  kCdr,
  // Anything else (json, protobuf, ...): listed, never decoded.
  kOther,
};

struct RecordingTopic {
  std::string name;
  // As the file names it: "sensor_msgs/Imu" (ROS 1), "sensor_msgs/msg/Imu".
  std::string type;
  MessageEncoding encoding = MessageEncoding::kOther;
  // The message count when the file's index says it; -1 when unknown.
  int64_t messages = -1;
  // ROS 1: the definition's MD5 sum, to refuse a non-standard sensor_msgs/Imu.
  std::string md5sum;
};

// One message as the file holds it; `data` is valid during the visit only.
struct RecordedMessage {
  // Index into topics().
  size_t topic = 0;
  // When the recorder received it, ns since the epoch.
  int64_t record_time_ns = 0;
  const uint8_t* data = nullptr;
  size_t size = 0;
};

// Returns false to stop reading (the visitor sets the error itself).
using MessageVisitor = std::function<bool(const RecordedMessage&)>;

class MessageRecording {
 public:
  virtual ~MessageRecording() = default;
  // "ROS 1 bag", "rosbag2 SQLite bag", "MCAP file": how messages name it.
  virtual const char* FormatName() const = 0;
  // Reads what the file holds (its topics). Errors are one line
  // "<path>: what is wrong".
  virtual bool Open(const std::string& path, std::string* error) = 0;
  // Fixed once Open returns: Read never adds to it.
  virtual const std::vector<RecordingTopic>& topics() const = 0;
  // Visits every message of a topic i with wanted[i], in file order.
  virtual bool Read(const std::vector<bool>& wanted, const MessageVisitor& visit,
                    std::string* error) = 0;
};

// A message from a library (SQLite, librosbag) as one line: line breaks and
// other control characters become spaces, runs of spaces one, at most 200
// characters.
inline std::string OneLine(const std::string& text) {
  std::string out;
  for (char c : text) {
    const bool blank = static_cast<unsigned char>(c) < 0x20 || c == 0x7f || c == ' ';
    if (blank && (out.empty() || out.back() == ' ')) continue;
    out += blank ? ' ' : c;
    if (out.size() >= 200) return out + "...";
  }
  return out;
}

// The readers themselves, compiled into the reader module only
// (reader_module.h); the library reaches them through NewMessageRecording.
std::unique_ptr<MessageRecording> NewRos1Bag();
std::unique_ptr<MessageRecording> NewRosbag2Sqlite();
std::unique_ptr<MessageRecording> NewMcapFile();

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_FORMATS_MESSAGE_RECORDING_H_
