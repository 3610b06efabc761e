// rosbag2's SQLite storage (.db3): table `topics` (id, name, type,
// serialization_format, ...) and table `messages` (id, topic_id, timestamp
// in ns, data = the CDR bytes). Messages are stepped through one row at a
// time in the order they were written, so memory does not grow with the file.
#include <sqlite3.h>

#include <memory>
#include <string>
#include <vector>

#include "io/formats/message_recording.h"

namespace gravcal {
namespace internal {
namespace {

struct DatabaseCloser {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
struct StatementFinalizer {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};
using Statement = std::unique_ptr<sqlite3_stmt, StatementFinalizer>;

class Rosbag2Sqlite : public MessageRecording {
 public:
  const char* FormatName() const override { return "rosbag2 SQLite bag"; }
  const std::vector<RecordingTopic>& topics() const override { return topics_; }

  bool Open(const std::string& path, std::string* error) override {
    path_ = path;
    sqlite3* db = nullptr;
    const int opened = sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
    db_.reset(db);
    if (opened != SQLITE_OK) return Fail(error, "cannot open the SQLite database");
    Statement tables;
    if (!Prepare("SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name IN "
                 "('topics', 'messages')",
                 &tables, error)) {
      return false;
    }
    if (sqlite3_step(tables.get()) != SQLITE_ROW) return Fail(error, Why("cannot list tables"));
    if (sqlite3_column_int(tables.get(), 0) != 2) {
      return Fail(error,
                  "an SQLite file that is not a rosbag2 bag (no 'topics' and 'messages' "
                  "tables)");
    }
    Statement list;
    if (!Prepare("SELECT t.id, t.name, t.type, t.serialization_format, (SELECT count(*) FROM "
                 "messages m WHERE m.topic_id = t.id) FROM topics t ORDER BY t.id",
                 &list, error)) {
      return false;
    }
    int step;
    while ((step = sqlite3_step(list.get())) == SQLITE_ROW) {
      RecordingTopic topic;
      ids_.push_back(sqlite3_column_int64(list.get(), 0));
      topic.name = Text(list.get(), 1);
      topic.type = Text(list.get(), 2);
      const std::string format = Text(list.get(), 3);
      topic.encoding = format == "cdr" ? MessageEncoding::kCdr : MessageEncoding::kOther;
      topic.messages = sqlite3_column_int64(list.get(), 4);
      topics_.push_back(std::move(topic));
    }
    if (step != SQLITE_DONE) return Fail(error, Why("cannot read the topics"));
    return true;
  }

  bool Read(const std::vector<bool>& wanted, const MessageVisitor& visit,
            std::string* error) override {
    Statement rows;
    if (!Prepare("SELECT topic_id, timestamp, data FROM messages ORDER BY id", &rows, error)) {
      return false;
    }
    int step;
    while ((step = sqlite3_step(rows.get())) == SQLITE_ROW) {
      const int64_t id = sqlite3_column_int64(rows.get(), 0);
      size_t topic = 0;
      while (topic < ids_.size() && ids_[topic] != id) ++topic;
      if (topic == ids_.size()) {
        return Fail(error, "a message has topic_id " + std::to_string(id) +
                               ", which the topics table does not have");
      }
      if (topic >= wanted.size() || !wanted[topic]) continue;
      RecordedMessage message;
      message.topic = topic;
      message.record_time_ns = sqlite3_column_int64(rows.get(), 1);
      message.data = static_cast<const uint8_t*>(sqlite3_column_blob(rows.get(), 2));
      message.size = static_cast<size_t>(sqlite3_column_bytes(rows.get(), 2));
      if (!visit(message)) return false;
    }
    if (step != SQLITE_DONE) return Fail(error, Why("cannot read the messages"));
    return true;
  }

 private:
  bool Fail(std::string* error, const std::string& what) const {
    if (error != nullptr) *error = path_ + ": " + what;
    return false;
  }
  std::string Why(const std::string& what) const {
    return what + " (" + OneLine(sqlite3_errmsg(db_.get())) + ")";
  }
  bool Prepare(const char* sql, Statement* statement, std::string* error) {
    sqlite3_stmt* s = nullptr;
    const int prepared = sqlite3_prepare_v2(db_.get(), sql, -1, &s, nullptr);
    statement->reset(s);
    if (prepared != SQLITE_OK) return Fail(error, Why("not a readable rosbag2 bag"));
    return true;
  }
  static std::string Text(sqlite3_stmt* s, int column) {
    const unsigned char* text = sqlite3_column_text(s, column);
    return text == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(text));
  }

  std::string path_;
  std::unique_ptr<sqlite3, DatabaseCloser> db_;
  std::vector<RecordingTopic> topics_;
  std::vector<int64_t> ids_;
};

}  // namespace

std::unique_ptr<MessageRecording> NewRosbag2Sqlite() { return std::make_unique<Rosbag2Sqlite>(); }

}  // namespace internal
}  // namespace gravcal
