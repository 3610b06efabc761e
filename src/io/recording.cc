#include "gravcal/io/recording.h"

#include <algorithm>
#include <exception>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "io/formats/file_format.h"
#include "io/formats/imu_message.h"
#include "io/formats/message_log.h"
#include "util/error.h"

namespace gravcal {
namespace {

using internal::SetError;

// Interval statistics of increasing times (IMU topics and text logs).
void SummariseTimes(const std::vector<double>& t, TopicSummary* topic) {
  topic->messages = static_cast<int64_t>(t.size());
  if (t.empty()) return;
  topic->first_s = t.front();
  topic->last_s = t.back();
  if (t.size() < 2 || !(t.back() > t.front())) return;
  topic->rate_hz = static_cast<double>(t.size() - 1) / (t.back() - t.front());
  std::vector<double> dt(t.size() - 1);
  for (size_t i = 1; i < t.size(); ++i) dt[i - 1] = t[i] - t[i - 1];
  topic->longest_interval_s = *std::max_element(dt.begin(), dt.end());
  std::vector<double> sorted = dt;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  topic->median_interval_s = sorted[sorted.size() / 2];
  topic->gaps = std::count_if(dt.begin(), dt.end(),
                              [&](double d) { return d > 2.0 * topic->median_interval_s; });
}

bool InspectMessages(internal::MessageRecording* recording, const std::string& path,
                     const LogReaderOptions& options, RecordingSummary* summary,
                     std::string* error) {
  const std::vector<internal::RecordingTopic> topics = recording->topics();
  std::vector<TopicSummary> out(topics.size());
  // Times of IMU topics are kept for the interval statistics (8 bytes per
  // message); other topics only count.
  std::vector<std::vector<double>> imu_times(topics.size());
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
        failed_message = static_cast<int64_t>(imu_times[m.topic].size());
        return false;
      }
      if (!options.record_time) t = static_cast<double>(stamp_ns) * 1e-9;
      imu_times[m.topic].push_back(t);
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
      SummariseTimes(imu_times[i], &s);
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
      ImuLog log;
      if (!ReadImuLog(path, options, &log, error)) return false;
      TopicSummary topic;
      topic.type = log.has_gyro() ? "accelerometer and gyroscope" : "accelerometer";
      topic.imu = true;
      SummariseTimes(log.t, &topic);
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
