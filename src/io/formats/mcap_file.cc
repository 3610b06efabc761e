// MCAP (https://mcap.dev/spec), read record by record from the file: the
// magic "\x89MCAP0\r\n", records (opcode u8, length u64, content), the
// footer and the magic again. Channels and schemas come from the summary
// section when the footer points to one, otherwise from a first pass over
// the data section. Chunks are decompressed one at a time (none, zstd, lz4
// frame) and checked against their CRC, so memory stays bounded by the
// largest chunk.
#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "io/formats/byte_cursor.h"
#include "io/formats/message_recording.h"

namespace gravcal {
namespace internal {
namespace {

constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr uint8_t kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05, kChunk = 0x06,
                  kStatistics = 0x0B, kDataEnd = 0x0F;
// Opcode + length + the footer's 20 bytes, then the closing magic.
constexpr uint64_t kFooterRecord = 1 + 8 + 20;
// A chunk that claims more than this uncompressed is refused as corrupt.
constexpr uint64_t kMaxChunkBytes = uint64_t{1} << 30;
// The topic index of a channel first seen while reading.
constexpr size_t kNotListed = static_cast<size_t>(-1);

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f != nullptr) std::fclose(f);
  }
};

class McapFile : public MessageRecording {
 public:
  const char* FormatName() const override { return "MCAP file"; }
  const std::vector<RecordingTopic>& topics() const override { return topics_; }

  bool Open(const std::string& path, std::string* error) override {
    path_ = path;
    file_.reset(std::fopen(path.c_str(), "rb"));
    if (file_ == nullptr) return Fail(error, "cannot open: " + std::string(std::strerror(errno)));
    if (std::fseek(file_.get(), 0, SEEK_END) != 0) return Fail(error, "cannot seek");
    const long size = std::ftell(file_.get());
    if (size < 0) return Fail(error, "cannot tell its size");
    size_ = static_cast<uint64_t>(size);
    uint8_t magic[8];
    if (size_ < 8 || !ReadAt(0, magic, 8) || std::memcmp(magic, kMagic, 8) != 0) {
      return Fail(error, "not an MCAP file (no magic)");
    }
    if (size_ < 8 + kFooterRecord + 8 || !ReadAt(size_ - 8, magic, 8) ||
        std::memcmp(magic, kMagic, 8) != 0) {
      return Fail(error, "truncated MCAP file (no footer and closing magic)");
    }
    footer_at_ = size_ - 8 - kFooterRecord;
    uint8_t footer[kFooterRecord];
    if (!ReadAt(footer_at_, footer, kFooterRecord)) return Fail(error, "cannot read the footer");
    ByteCursor c(footer, kFooterRecord);
    const uint8_t opcode = c.U8();
    const uint64_t length = c.U64();
    const uint64_t summary_start = c.U64();
    if (opcode != kFooter || length != 20 || summary_start > footer_at_ ||
        (summary_start != 0 && summary_start < 8)) {
      return Fail(error, "corrupt MCAP footer");
    }
    // The summary, when there is one, repeats every schema and channel.
    const bool from_summary = summary_start != 0;
    const uint64_t begin = from_summary ? summary_start : 8;
    if (!Scan(begin, footer_at_, !from_summary, nullptr, error)) return false;
    if (from_summary) {
      for (auto& [id, index] : topic_of_channel_) {
        const auto count = message_counts_.find(id);
        if (count != message_counts_.end())
          topics_[index].messages = static_cast<int64_t>(count->second);
      }
    }
    return true;
  }

  bool Read(const std::vector<bool>& wanted, const MessageVisitor& visit,
            std::string* error) override {
    wanted_ = wanted;
    return Scan(8, footer_at_, true, &visit, error);
  }

 private:
  bool Fail(std::string* error, const std::string& what) const {
    if (error != nullptr) *error = path_ + ": " + what;
    return false;
  }

  bool ReadAt(uint64_t offset, uint8_t* out, size_t n) {
    return std::fseek(file_.get(), static_cast<long>(offset), SEEK_SET) == 0 &&
           std::fread(out, 1, n, file_.get()) == n;
  }

  // Reads the records in [begin, end); in the data section (`data`) stops
  // at DataEnd or at the summary section. With `visit`, hands out messages.
  bool Scan(uint64_t begin, uint64_t end, bool data, const MessageVisitor* visit,
            std::string* error) {
    if (std::fseek(file_.get(), static_cast<long>(begin), SEEK_SET) != 0) {
      return Fail(error, "cannot seek");
    }
    uint64_t at = begin;
    std::vector<uint8_t> record;
    while (at < end) {
      uint8_t head[9];
      if (end - at < 9 || std::fread(head, 1, 9, file_.get()) != 9) {
        return Fail(error, "truncated record at byte " + std::to_string(at));
      }
      ByteCursor h(head, 9);
      const uint8_t opcode = h.U8();
      const uint64_t length = h.U64();
      if (length > end - at - 9) {
        return Fail(error, "record at byte " + std::to_string(at) + " claims " +
                               std::to_string(length) + " bytes, past the end of the section");
      }
      if (opcode == kDataEnd && data) return true;
      // Attachments and indexes are skipped without reading them.
      const bool wanted = opcode == kSchema || opcode == kChannel || opcode == kStatistics ||
                          (opcode == kMessage && visit != nullptr) || opcode == kChunk;
      if (!wanted || (opcode == kChunk && !data)) {
        if (std::fseek(file_.get(), static_cast<long>(length), SEEK_CUR) != 0) {
          return Fail(error, "cannot seek");
        }
      } else {
        record.resize(length);
        if (length > 0 && std::fread(record.data(), 1, length, file_.get()) != length) {
          return Fail(error, "truncated record at byte " + std::to_string(at));
        }
        const std::string where = "record at byte " + std::to_string(at) + ": ";
        if (!Record(opcode, record.data(), record.size(), visit, where, error)) return false;
      }
      at += 9 + length;
    }
    return true;
  }

  // One record (inside a chunk too).
  bool Record(uint8_t opcode, const uint8_t* p, size_t n, const MessageVisitor* visit,
              const std::string& where, std::string* error) {
    ByteCursor c(p, n);
    if (opcode == kSchema) {
      const uint16_t id = c.U16();
      std::string name = c.String();
      c.String();  // The schema encoding ("ros2msg", "ros1msg").
      c.String();  // The definition itself.
      if (!c.ok()) return Fail(error, where + "corrupt schema record");
      schema_names_[id] = std::move(name);
      return true;
    }
    if (opcode == kChannel) {
      const uint16_t id = c.U16();
      const uint16_t schema = c.U16();
      std::string topic = c.String();
      const std::string encoding = c.String();
      if (!c.ok()) return Fail(error, where + "corrupt channel record");
      if (topic_of_channel_.count(id) != 0) return true;
      // While reading, topics() must not change: a channel the summary did
      // not list is not asked for, and its messages are passed over.
      if (visit != nullptr) {
        topic_of_channel_[id] = kNotListed;
        return true;
      }
      RecordingTopic t;
      t.name = std::move(topic);
      const auto s = schema_names_.find(schema);
      t.type = s != schema_names_.end() ? s->second : (schema == 0 ? "(no schema)" : "?");
      t.encoding = encoding == "cdr"    ? MessageEncoding::kCdr
                   : encoding == "ros1" ? MessageEncoding::kRos1
                                        : MessageEncoding::kOther;
      topic_of_channel_[id] = topics_.size();
      topics_.push_back(std::move(t));
      return true;
    }
    if (opcode == kStatistics) {
      c.U64();  // message count
      c.U16();  // schema count
      c.U32();  // channel count
      c.U32();  // attachment count
      c.U32();  // metadata count
      c.U32();  // chunk count
      c.U64();  // message start time
      c.U64();  // message end time
      const uint32_t map_bytes = c.U32();
      const uint8_t* map = c.Bytes(map_bytes);
      if (!c.ok()) return Fail(error, where + "corrupt statistics record");
      ByteCursor m(map, map_bytes);
      while (m.ok() && m.remaining() > 0) {
        const uint16_t channel = m.U16();
        const uint64_t count = m.U64();
        if (m.ok()) message_counts_[channel] = count;
      }
      return true;
    }
    if (opcode == kMessage) {
      if (visit == nullptr) return true;
      const uint16_t channel = c.U16();
      c.U32();  // sequence
      const uint64_t log_time = c.U64();
      c.U64();  // publish time
      if (!c.ok()) return Fail(error, where + "corrupt message record");
      const auto t = topic_of_channel_.find(channel);
      if (t == topic_of_channel_.end()) {
        return Fail(error, where + "message on channel " + std::to_string(channel) +
                               ", which no channel record defines");
      }
      if (t->second >= wanted_.size() || !wanted_[t->second]) return true;
      RecordedMessage message;
      message.topic = t->second;
      message.record_time_ns = static_cast<int64_t>(log_time);
      message.data = c.position();
      message.size = c.remaining();
      return (*visit)(message);
    }
    if (opcode == kChunk) return Chunk(&c, visit, where, error);
    return true;
  }

  bool Chunk(ByteCursor* c, const MessageVisitor* visit, const std::string& where,
             std::string* error) {
    c->U64();  // message start time
    c->U64();  // message end time
    const uint64_t uncompressed_size = c->U64();
    const uint32_t crc = c->U32();  // CRC-32 of the uncompressed records; 0 = none.
    const std::string compression = c->String();
    const uint64_t records_size = c->U64();
    const uint8_t* records = c->Bytes(records_size);
    if (!c->ok()) return Fail(error, where + "corrupt chunk record");
    if (uncompressed_size > kMaxChunkBytes) {
      return Fail(error, where + "chunk claims " + std::to_string(uncompressed_size) +
                             " bytes uncompressed, more than gravcal accepts");
    }
    const uint8_t* plain = records;
    if (compression.empty()) {
      if (records_size != uncompressed_size) {
        return Fail(error, where + "uncompressed chunk size does not match its records");
      }
    } else {
      chunk_.resize(uncompressed_size);
      if (compression == "zstd") {
        const size_t got = ZSTD_decompress(chunk_.data(), chunk_.size(), records, records_size);
        if (ZSTD_isError(got) || got != uncompressed_size) {
          return Fail(error, where + "zstd chunk does not decompress");
        }
      } else if (compression == "lz4") {
        if (!Lz4Frame(records, records_size)) {
          return Fail(error, where + "lz4 chunk does not decompress");
        }
      } else {
        return Fail(error,
                    where + "chunk compression '" + OneLine(compression) + "' is not supported");
      }
      plain = chunk_.data();
    }
    if (crc != 0 && crc32(0L, plain, static_cast<uInt>(uncompressed_size)) != crc) {
      return Fail(error, where + "chunk fails its CRC check (damaged)");
    }
    // Records inside a chunk are never chunks, so chunk_ stays as it is
    // while they are read.
    ByteCursor r(plain, uncompressed_size);
    while (r.remaining() > 0) {
      const uint8_t opcode = r.U8();
      const uint64_t length = r.U64();
      const uint8_t* body = r.Bytes(length);
      if (!r.ok()) return Fail(error, where + "corrupt record inside a chunk");
      if (opcode == kChunk) return Fail(error, where + "a chunk inside a chunk");
      if (!Record(opcode, body, length, visit, where, error)) return false;
    }
    return true;
  }

  bool Lz4Frame(const uint8_t* src, size_t src_size) {
    LZ4F_dctx* context = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION))) return false;
    size_t out_done = 0;
    size_t in_done = 0;
    bool ok = true;
    while (ok && in_done < src_size) {
      size_t out_size = chunk_.size() - out_done;
      size_t in_size = src_size - in_done;
      const size_t hint = LZ4F_decompress(context, chunk_.data() + out_done, &out_size,
                                          src + in_done, &in_size, nullptr);
      ok = !LZ4F_isError(hint) && (in_size > 0 || out_size > 0);
      out_done += out_size;
      in_done += in_size;
      if (hint == 0) break;
    }
    LZ4F_freeDecompressionContext(context);
    return ok && out_done == chunk_.size();
  }

  std::string path_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  uint64_t size_ = 0;
  uint64_t footer_at_ = 0;
  std::vector<RecordingTopic> topics_;
  std::map<uint16_t, std::string> schema_names_;
  std::map<uint16_t, size_t> topic_of_channel_;
  std::map<uint16_t, uint64_t> message_counts_;
  std::vector<bool> wanted_;
  std::vector<uint8_t> chunk_;
};

}  // namespace

std::unique_ptr<MessageRecording> NewMcapFile() { return std::make_unique<McapFile>(); }

}  // namespace internal
}  // namespace gravcal
