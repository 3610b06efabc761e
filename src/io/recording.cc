#include "gravcal/io/recording.h"

#include <algorithm>
#include <cstdint>
#include <exception>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "gravcal/io/imu_stream.h"
#include "io/formats/file_format.h"
#include "io/formats/imu_message.h"
#include "io/formats/message_log.h"
#include "util/error.h"

namespace gravcal {
namespace {

using internal::SetError;

// Interval statistics of increasing times (IMU topics and text logs), fed
// one time at a time. The intervals are kept as (value, count) pairs, so
// memory grows with the number of distinct intervals (a handful for a
// sensor's clock, at most 16 bytes per sample for a jittering host clock),
// never with the text: `inspect` reads a log larger than memory.
class TimeSummary {
 public:
  void Add(double t) {
    if (count_ == 0) {
      first_ = t;
    } else {
      pending_.push_back(t - last_);
      if (pending_.size() == kPending) Compact();
    }
    last_ = t;
    ++count_;
  }

  void Finish(TopicSummary* topic) {
    topic->messages = count_;
    if (count_ == 0) return;
    topic->first_s = first_;
    topic->last_s = last_;
    if (count_ < 2 || !(last_ > first_)) return;
    topic->rate_hz = static_cast<double>(count_ - 1) / (last_ - first_);
    Compact();
    topic->longest_interval_s = intervals_.back().first;
    // The median is the interval of rank n / 2 in sorted order.
    int64_t rank = (count_ - 1) / 2;
    for (const auto& [value, count] : intervals_) {
      if (rank < count) {
        topic->median_interval_s = value;
        break;
      }
      rank -= count;
    }
    topic->gaps = 0;
    for (const auto& [value, count] : intervals_) {
      if (value > 2.0 * topic->median_interval_s) topic->gaps += count;
    }
  }

 private:
  static constexpr size_t kPending = size_t{1} << 16;

  // Sorts the pending intervals into the (value, count) pairs.
  void Compact() {
    std::sort(pending_.begin(), pending_.end());
    std::vector<std::pair<double, int64_t>> merged;
    merged.reserve(intervals_.size() + 16);
    auto put = [&](double value, int64_t count) {
      if (!merged.empty() && merged.back().first == value) {
        merged.back().second += count;
      } else {
        merged.emplace_back(value, count);
      }
    };
    size_t i = 0;
    for (const double value : pending_) {
      while (i < intervals_.size() && intervals_[i].first <= value) {
        put(intervals_[i].first, intervals_[i].second);
        ++i;
      }
      put(value, 1);
    }
    for (; i < intervals_.size(); ++i) put(intervals_[i].first, intervals_[i].second);
    intervals_ = std::move(merged);
    pending_.clear();
  }

  int64_t count_ = 0;
  double first_ = 0.0;
  double last_ = 0.0;
  std::vector<double> pending_;
  std::vector<std::pair<double, int64_t>> intervals_;
};

bool InspectMessages(internal::MessageRecording* recording, const std::string& path,
                     const LogReaderOptions& options, RecordingSummary* summary,
                     std::string* error) {
  const std::vector<internal::RecordingTopic> topics = recording->topics();
  std::vector<TopicSummary> out(topics.size());
  // IMU topics' times go into their interval statistics; other topics
  // only count.
  std::vector<TimeSummary> imu_times(topics.size());
  std::vector<int64_t> imu_messages(topics.size(), 0);
  std::vector<bool> wanted(topics.size(), true);
  std::string failure;
  size_t failed_topic = 0;
  int64_t failed_message = 0;
  auto visit = [&](const internal::RecordedMessage& m) {
    TopicSummary& s = out[m.topic];
    const internal::RecordingTopic& topic = topics[m.topic];
    double t = static_cast<double>(m.record_time_ns) * 1e-9;
    if (internal::IsImuType(topic.type)) {
      int64_t stamp_ns = 0;
      Eigen::Vector3d gyro, accel;
      if (!internal::DecodeImu(topic, m, &stamp_ns, &gyro, &accel, &failure)) {
        failed_topic = m.topic;
        failed_message = imu_messages[m.topic];
        return false;
      }
      if (!options.record_time) t = static_cast<double>(stamp_ns) * 1e-9;
      imu_times[m.topic].Add(t);
      ++imu_messages[m.topic];
      return true;
    }
    if (s.messages == 0) s.first_s = t;
    s.first_s = std::min(s.first_s, t);
    s.last_s = std::max(s.last_s, t);
    ++s.messages;
    return true;
  };
  if (!recording->Read(wanted, visit, error)) {
    if (failure.empty()) return false;
    return SetError(error, path + ": topic '" + internal::OneLine(topics[failed_topic].name) +
                               "' message " + std::to_string(failed_message) + ": " + failure);
  }
  for (size_t i = 0; i < topics.size(); ++i) {
    TopicSummary& s = out[i];
    s.name = topics[i].name;
    s.type = topics[i].type;
    s.imu = internal::IsImuType(topics[i].type);
    if (s.imu) {
      imu_times[i].Finish(&s);
    } else if (s.messages > 1 && s.last_s > s.first_s) {
      s.rate_hz = static_cast<double>(s.messages - 1) / (s.last_s - s.first_s);
    }
  }
  summary->topics = std::move(out);
  return true;
}

}  // namespace

bool InspectRecording(const std::string& path, const LogReaderOptions& options,
                      RecordingSummary* summary, std::string* error) {
  try {
    internal::FileFormat format = internal::FileFormat::kText;
    if (!internal::DetectFileFormatOf(path, &format, error)) return false;
    RecordingSummary result;
    result.format = internal::FileFormatName(format);
    if (std::unique_ptr<internal::MessageRecording> recording =
            internal::NewMessageRecording(format)) {
      if (!recording->Open(path, error) ||
          !InspectMessages(recording.get(), path, options, &result, error)) {
        return false;
      }
    } else {
      // Sample by sample (imu_stream.h): the same checks and messages as
      // ReadImuLog, in memory that does not grow with the log.
      ImuCsvStreamReader reader;
      if (!reader.Open(path, options, error)) return false;
      TimeSummary times;
      ImuSample sample;
      while (reader.Next(&sample, error)) times.Add(sample.t);
      if (!error->empty()) return false;
      TopicSummary topic;
      topic.type = reader.has_gyro() ? "accelerometer and gyroscope" : "accelerometer";
      topic.imu = true;
      times.Finish(&topic);
      result.topics.push_back(topic);
    }
    *summary = std::move(result);
    return true;
  } catch (const std::exception& e) {
    return SetError(error, path + ": " + e.what());
  }
}

bool IsMessageRecording(std::string_view first_bytes) {
  internal::FileFormat format = internal::FileFormat::kText;
  std::string what;
  return internal::DetectFileFormat(first_bytes, &format, &what) &&
         internal::NewMessageRecording(format) != nullptr;
}

bool ListImuTopics(const std::string& path, std::vector<std::string>* topics, std::string* error) {
  try {
    internal::FileFormat format = internal::FileFormat::kText;
    if (!internal::DetectFileFormatOf(path, &format, error)) return false;
    std::vector<std::string> names;
    if (std::unique_ptr<internal::MessageRecording> recording =
            internal::NewMessageRecording(format)) {
      if (!recording->Open(path, error)) return false;
      for (const internal::RecordingTopic& t : recording->topics()) {
        if (internal::IsImuType(t.type)) names.push_back(t.name);
      }
      if (names.empty()) {
        size_t unused = 0;
        internal::SelectImuTopic(*recording, path, "", &unused, error);
        return false;
      }
    } else {
      names.push_back("");
    }
    *topics = std::move(names);
    return true;
  } catch (const std::exception& e) {
    return SetError(error, path + ": " + e.what());
  }
}

}  // namespace gravcal
