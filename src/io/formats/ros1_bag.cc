// ROS 1 bags (format 2.0) through the ROS project's own reader,
// librosbag_storage (Debian: librosbag-storage-dev), with its bz2 and lz4
// chunk support. The connection records carry each topic's type and the MD5
// sum of its definition; the messages are handed out as their serialised
// bytes, one at a time in time order, the bag's index keeping memory bounded.
// Without the library (GRAVCAL_HAVE_ROSBAG undefined) a bag is named and
// refused.
#include <memory>
#include <string>
#include <vector>

#include "io/formats/byte_cursor.h"
#include "io/formats/message_recording.h"

#ifdef GRAVCAL_HAVE_ROSBAG
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <map>
#endif

namespace gravcal {
namespace internal {
namespace {

#ifdef GRAVCAL_HAVE_ROSBAG

// The bag's top-level records (after the "#ROSBAG V2.0\n" line), each
//   header_len (uint32 LE), header, data_len (uint32 LE), data,
// must lie inside the file. librosbag_storage allocates what a length field
// says before reading it, so a damaged length made it ask for gigabytes
// (found by fuzz/fuzz_rosbag2_db3 on a bag-headed input): checked here first.
bool RecordsFitInFile(const std::string& path, std::string* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *what = "cannot open";
    return false;
  }
  in.seekg(0, std::ios::end);
  const uint64_t size = static_cast<uint64_t>(in.tellg());
  const uint64_t magic = 13;  // "#ROSBAG V2.0\n"
  uint64_t pos = magic;
  auto read_u32 = [&in](uint64_t at, uint32_t* v) {
    unsigned char b[4];
    in.seekg(static_cast<std::streamoff>(at));
    if (!in.read(reinterpret_cast<char*>(b), 4)) return false;
    *v = static_cast<uint32_t>(b[0]) | static_cast<uint32_t>(b[1]) << 8 |
         static_cast<uint32_t>(b[2]) << 16 | static_cast<uint32_t>(b[3]) << 24;
    return true;
  };
  while (pos < size) {
    uint32_t header_len = 0;
    uint32_t data_len = 0;
    if (pos + 4 > size || !read_u32(pos, &header_len) || pos + 4 + header_len + 4 > size ||
        !read_u32(pos + 4 + header_len, &data_len) ||
        pos + 8 + uint64_t{header_len} + data_len > size) {
      *what = "a record at byte " + std::to_string(pos) + " runs past the end of the file";
      return false;
    }
    // The header's fields, each field_len (uint32 LE) then "name=value",
    // must fill it exactly: ros::Header::parse trusts them (a damaged one
    // overflowed its buffer, fuzz/fuzz_ros1_bag).
    std::string header(header_len, '\0');
    in.seekg(static_cast<std::streamoff>(pos + 4));
    if (!in.read(header.data(), header_len)) {
      *what = "cannot read the record at byte " + std::to_string(pos);
      return false;
    }
    ByteCursor fields(reinterpret_cast<const uint8_t*>(header.data()), header.size());
    while (fields.ok() && fields.remaining() > 0) {
      const uint32_t field_len = fields.U32();
      const uint8_t* field = fields.Bytes(field_len);
      if (field == nullptr || std::memchr(field, '=', field_len) == nullptr) {
        *what = "the record at byte " + std::to_string(pos) + " has a damaged header field";
        return false;
      }
    }
    pos += 8 + uint64_t{header_len} + data_len;
  }
  return true;
}

class Ros1Bag : public MessageRecording {
 public:
  const char* FormatName() const override { return "ROS 1 bag"; }
  const std::vector<RecordingTopic>& topics() const override { return topics_; }

  bool Open(const std::string& path, std::string* error) override {
    path_ = path;
    std::string what;
    if (!RecordsFitInFile(path, &what)) return Fail(error, "not a readable ROS 1 bag: " + what);
    try {
      bag_.open(path, rosbag::bagmode::Read);
      rosbag::View view(bag_);
      for (const rosbag::ConnectionInfo* c : view.getConnections()) {
        // Several connections (publishers) may share a topic.
        auto [it, added] = topic_index_.emplace(c->topic, topics_.size());
        if (added) {
          RecordingTopic topic;
          topic.name = c->topic;
          topic.type = c->datatype;
          topic.encoding = MessageEncoding::kRos1;
          topic.md5sum = c->md5sum;
          topic.messages = 0;
          topics_.push_back(std::move(topic));
        }
        if (topics_[it->second].md5sum != c->md5sum || topics_[it->second].type != c->datatype) {
          return Fail(error, "topic '" + c->topic + "' has connections of different types");
        }
      }
      for (RecordingTopic& topic : topics_) {
        rosbag::View one(bag_, rosbag::TopicQuery(topic.name));
        topic.messages = one.size();
      }
    } catch (const std::exception& e) {
      return Fail(error, "not a readable ROS 1 bag: " + OneLine(e.what()));
    }
    return true;
  }

  bool Read(const std::vector<bool>& wanted, const MessageVisitor& visit,
            std::string* error) override {
    std::vector<std::string> names;
    for (size_t i = 0; i < topics_.size(); ++i) {
      if (i < wanted.size() && wanted[i]) names.push_back(topics_[i].name);
    }
    if (names.empty()) return true;
    try {
      rosbag::View view(bag_, rosbag::TopicQuery(names));
      std::vector<uint8_t> buffer;
      for (const rosbag::MessageInstance& m : view) {
        buffer.resize(m.size());
        ros::serialization::OStream stream(buffer.data(), static_cast<uint32_t>(buffer.size()));
        m.write(stream);
        RecordedMessage message;
        message.topic = topic_index_.at(m.getTopic());
        message.record_time_ns = static_cast<int64_t>(m.getTime().toNSec());
        message.data = buffer.data();
        message.size = buffer.size();
        if (!visit(message)) return false;
      }
    } catch (const std::exception& e) {
      return Fail(error, "corrupt ROS 1 bag: " + OneLine(e.what()));
    }
    return true;
  }

 private:
  bool Fail(std::string* error, const std::string& what) const {
    if (error != nullptr) *error = path_ + ": " + what;
    return false;
  }

  std::string path_;
  rosbag::Bag bag_;
  std::vector<RecordingTopic> topics_;
  std::map<std::string, size_t> topic_index_;
};

#else

class Ros1Bag : public MessageRecording {
 public:
  const char* FormatName() const override { return "ROS 1 bag"; }
  const std::vector<RecordingTopic>& topics() const override { return topics_; }
  bool Open(const std::string& path, std::string* error) override {
    if (error != nullptr) {
      *error = path + ": a ROS 1 bag; this gravcal was built without librosbag-storage-dev";
    }
    return false;
  }
  bool Read(const std::vector<bool>&, const MessageVisitor&, std::string*) override {
    return false;
  }

 private:
  std::vector<RecordingTopic> topics_;
};

#endif

}  // namespace

std::unique_ptr<MessageRecording> NewRos1Bag() { return std::make_unique<Ros1Bag>(); }

}  // namespace internal
}  // namespace gravcal
