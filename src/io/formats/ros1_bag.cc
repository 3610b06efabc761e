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

#include "io/formats/message_recording.h"
#include "io/formats/ros1_bag_structure.h"

#ifdef GRAVCAL_HAVE_ROSBAG
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <cstdint>
#include <exception>
#include <map>
#endif

namespace gravcal {
namespace internal {
namespace {

#ifdef GRAVCAL_HAVE_ROSBAG

class Ros1Bag : public MessageRecording {
 public:
  const char* FormatName() const override { return "ROS 1 bag"; }
  const std::vector<RecordingTopic>& topics() const override { return topics_; }

  bool Open(const std::string& path, std::string* error) override {
    path_ = path;
    std::string what;
    if (!CheckRos1BagStructure(path, &what))
      return Fail(error, "not a readable ROS 1 bag: " + what);
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
