#include "io/formats/ros1_bag_structure.h"

// Built with librosbag_storage only (cmake/recording_formats.cmake), whose
// bz2 and roslz4 it uses as rosbag does.
#ifdef GRAVCAL_HAVE_ROSBAG
#include <bzlib.h>
#include <roslz4/lz4s.h>

#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <vector>

#include "io/formats/byte_cursor.h"

namespace gravcal {
namespace internal {
namespace {

// Record kinds (the header's "op" field) of format 2.0.
enum RecordOp : uint8_t {
  kOpMessageDefinition = 0x01,
  kOpMessageData,
  kOpBagHeader,
  kOpIndexData,
  kOpChunk,
  kOpChunkInfo,
  kOpConnection,
};

constexpr uint64_t kMagicBytes = 13;  // "#ROSBAG V2.0\n"
constexpr uint32_t kIndexEntryBytes = 12;
constexpr uint32_t kChunkInfoEntryBytes = 8;

using Fields = std::map<std::string, std::string>;

// A field block: field_len (uint32 LE), then "name=value" of that length,
// repeated until the block is filled exactly.
bool ParseFields(const uint8_t* data, size_t size, Fields* fields) {
  fields->clear();
  ByteCursor block(data, size);
  while (block.ok() && block.remaining() > 0) {
    const uint32_t field_len = block.U32();
    const uint8_t* field = block.Bytes(field_len);
    if (field == nullptr) return false;
    const void* equals = std::memchr(field, '=', field_len);
    if (equals == nullptr) return false;
    const size_t name_len = static_cast<const uint8_t*>(equals) - field;
    (*fields)[std::string(reinterpret_cast<const char*>(field), name_len)] =
        std::string(reinterpret_cast<const char*>(field) + name_len + 1, field_len - name_len - 1);
  }
  return block.ok();
}

// A little-endian unsigned field of exactly `bytes` bytes.
bool UnsignedField(const Fields& fields, const char* name, int bytes, uint64_t* value) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.size() != static_cast<size_t>(bytes)) return false;
  *value = 0;
  for (int i = 0; i < bytes; ++i) {
    *value |= uint64_t{static_cast<uint8_t>(it->second[i])} << (8 * i);
  }
  return true;
}

// The records of one level (the file, or one chunk's uncompressed bytes).
struct Record {
  Fields header;
  uint8_t op = 0;
  uint64_t data_start = 0;
  uint32_t data_len = 0;
};

// Reads the record at `pos` of a byte source of `size` bytes through
// `read(at, n, out)`: false with *what when it does not lie inside or its
// header is malformed.
template <typename Read>
bool ReadRecord(uint64_t pos, uint64_t size, const Read& read, Record* r, std::string* what) {
  const std::string where = "the record at byte " + std::to_string(pos);
  uint8_t len[4];
  if (pos + 4 > size || !read(pos, 4, len)) {
    *what = where + " runs past the end";
    return false;
  }
  ByteCursor header_len_bytes(len, 4);
  const uint32_t header_len = header_len_bytes.U32();
  if (pos + 4 + uint64_t{header_len} + 4 > size) {
    *what = where + " runs past the end";
    return false;
  }
  if (header_len > kMaxRos1ChunkBytes) {
    *what = where + " has a header of " + std::to_string(header_len) + " bytes";
    return false;
  }
  std::vector<uint8_t> header(header_len);
  if (!read(pos + 4, header_len, header.data()) || !read(pos + 4 + header_len, 4, len)) {
    *what = "cannot read " + where;
    return false;
  }
  ByteCursor data_len_bytes(len, 4);
  r->data_len = data_len_bytes.U32();
  r->data_start = pos + 8 + header_len;
  if (r->data_start + r->data_len > size) {
    *what = where + " runs past the end";
    return false;
  }
  uint64_t op = 0;
  if (!ParseFields(header.data(), header.size(), &r->header) ||
      !UnsignedField(r->header, "op", 1, &op)) {
    *what = where + " has a damaged header";
    return false;
  }
  r->op = static_cast<uint8_t>(op);
  return true;
}

// A connection record's data: a field block (its data_len is the block's
// length, which rosbag reads as a header's).
bool ConnectionDataValid(const uint8_t* data, uint32_t size) {
  Fields fields;
  return ParseFields(data, size, &fields);
}

// One chunk's data uncompressed to exactly `size` bytes, or false.
bool Uncompress(const std::string& compression, std::vector<uint8_t>* data, uint32_t size,
                std::string* what) {
  if (size > kMaxRos1ChunkBytes) {
    *what = "declares " + std::to_string(size) + " bytes uncompressed (at most " +
            std::to_string(kMaxRos1ChunkBytes) + " read)";
    return false;
  }
  if (compression == "none") {
    if (data->size() != size) *what = "holds another size than it declares";
    return data->size() == size;
  }
  std::vector<uint8_t> out(size);
  unsigned int produced = size;
  bool ok = false;
  if (compression == "bz2") {
    ok = BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(out.data()), &produced,
                                    reinterpret_cast<char*>(data->data()),
                                    static_cast<unsigned int>(data->size()), 0, 0) == BZ_OK;
  } else if (compression == "lz4") {
    ok = roslz4_buffToBuffDecompress(reinterpret_cast<char*>(data->data()),
                                     static_cast<unsigned int>(data->size()),
                                     reinterpret_cast<char*>(out.data()), &produced) == ROSLZ4_OK;
  } else {
    *what = "has an unknown compression";
    return false;
  }
  if (!ok || produced != size) {
    *what = "does not uncompress to its declared size";
    return false;
  }
  data->swap(out);
  return true;
}

// The records of one uncompressed chunk: all well formed and filling it.
// *messages: the offsets of its message records (what the index may name).
bool CheckChunkRecords(const std::vector<uint8_t>& chunk, std::set<uint32_t>* messages,
                       std::string* what) {
  messages->clear();
  auto read = [&chunk](uint64_t at, uint64_t n, uint8_t* out) {
    if (n > 0) std::memcpy(out, chunk.data() + at, n);
    return true;
  };
  uint64_t pos = 0;
  while (pos < chunk.size()) {
    Record r;
    if (!ReadRecord(pos, chunk.size(), read, &r, what)) return false;
    if (r.op == kOpMessageData) {
      messages->insert(static_cast<uint32_t>(pos));
    } else if (r.op == kOpConnection) {
      if (!ConnectionDataValid(chunk.data() + r.data_start, r.data_len)) {
        *what = "the connection record at byte " + std::to_string(pos) + " is damaged";
        return false;
      }
    } else if (r.op != kOpMessageDefinition) {
      *what = "the record at byte " + std::to_string(pos) + " may not be inside a chunk";
      return false;
    }
    pos = r.data_start + r.data_len;
  }
  return true;
}

}  // namespace

bool CheckRos1BagStructure(const std::string& path, std::string* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *what = "cannot open";
    return false;
  }
  in.seekg(0, std::ios::end);
  const uint64_t size = static_cast<uint64_t>(in.tellg());
  auto read = [&in](uint64_t at, uint64_t n, uint8_t* out) {
    if (n == 0) return true;
    in.clear();
    in.seekg(static_cast<std::streamoff>(at));
    return static_cast<bool>(
        in.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(n)));
  };
  std::set<uint64_t> starts, chunks, connections;
  std::vector<uint64_t> chunk_refs;
  uint64_t index_pos = 0;
  // The message records of the chunk the index records that follow belong to.
  std::set<uint32_t> messages;
  bool after_chunk = false;
  // Each index record's position and connection id.
  std::vector<std::pair<uint64_t, uint64_t>> index_connections;
  uint64_t pos = kMagicBytes;
  while (pos < size) {
    Record r;
    if (!ReadRecord(pos, size, read, &r, what)) return false;
    const std::string where = "the record at byte " + std::to_string(pos);
    std::vector<uint8_t> data;
    // Data read whole only where it is checked, each at most
    // kMaxRos1ChunkBytes (chunks; indexes and connections are far smaller).
    auto load = [&]() {
      if (r.data_len > kMaxRos1ChunkBytes) return false;
      data.resize(r.data_len);
      return read(r.data_start, r.data_len, data.data());
    };
    uint64_t value = 0;
    switch (r.op) {
      case kOpBagHeader:
        if (pos != kMagicBytes || !UnsignedField(r.header, "index_pos", 8, &index_pos)) {
          *what = where + " is a misplaced or damaged bag header";
          return false;
        }
        break;
      case kOpChunk: {
        const auto compression = r.header.find("compression");
        if (compression == r.header.end() || !UnsignedField(r.header, "size", 4, &value)) {
          *what = where + " is a damaged chunk header";
          return false;
        }
        if (r.data_len > kMaxRos1ChunkBytes) {
          *what = "the chunk at byte " + std::to_string(pos) + " holds " +
                  std::to_string(r.data_len) + " bytes (at most " +
                  std::to_string(kMaxRos1ChunkBytes) + " read)";
          return false;
        }
        std::string why;
        if (!load() ||
            !Uncompress(compression->second, &data, static_cast<uint32_t>(value), &why) ||
            !CheckChunkRecords(data, &messages, &why)) {
          *what = "the chunk at byte " + std::to_string(pos) + ": " + why;
          return false;
        }
        chunks.insert(pos);
        after_chunk = true;
        break;
      }
      case kOpIndexData: {
        uint64_t version = 0, connection = 0, count = 0;
        if (!after_chunk || !UnsignedField(r.header, "ver", 4, &version) || version != 1 ||
            !UnsignedField(r.header, "conn", 4, &connection) ||
            !UnsignedField(r.header, "count", 4, &count) ||
            uint64_t{r.data_len} != count * kIndexEntryBytes || !load()) {
          *what = where + " is a misplaced or damaged index";
          return false;
        }
        for (uint64_t i = 0; i < count; ++i) {
          ByteCursor entry(data.data() + i * kIndexEntryBytes + 8, 4);
          if (messages.count(entry.U32()) == 0) {
            *what = "the index at byte " + std::to_string(pos) +
                    " names no message of its chunk (entry " + std::to_string(i) + ")";
            return false;
          }
        }
        index_connections.emplace_back(pos, connection);
        break;
      }
      case kOpChunkInfo: {
        uint64_t version = 0, count = 0;
        if (!UnsignedField(r.header, "ver", 4, &version) ||
            !UnsignedField(r.header, "chunk_pos", 8, &value) ||
            !UnsignedField(r.header, "count", 4, &count) ||
            uint64_t{r.data_len} != count * kChunkInfoEntryBytes) {
          *what = where + " is a damaged chunk info";
          return false;
        }
        chunk_refs.push_back(value);
        break;
      }
      case kOpConnection:
        if (!UnsignedField(r.header, "conn", 4, &value) || r.header.count("topic") == 0 ||
            !load() || !ConnectionDataValid(data.data(), r.data_len)) {
          *what = where + " is a damaged connection";
          return false;
        }
        connections.insert(value);
        break;
      case kOpMessageData:
      case kOpMessageDefinition:
        break;
      default:
        *what = where + " is of an unknown kind (op " + std::to_string(r.op) + ")";
        return false;
    }
    starts.insert(pos);
    pos = r.data_start + r.data_len;
  }
  if (starts.count(kMagicBytes) == 0 || index_pos == 0) {
    *what = "no bag header with an index (an unfinished recording: rosbag reindex repairs it)";
    return false;
  }
  if (starts.count(index_pos) == 0) {
    *what = "the index position " + std::to_string(index_pos) + " is not a record";
    return false;
  }
  for (uint64_t chunk : chunk_refs) {
    if (chunks.count(chunk) == 0) {
      *what = "a chunk info names byte " + std::to_string(chunk) + ", not a chunk";
      return false;
    }
  }
  // rosbag looks an index's connection up when it reports a bad time.
  for (const auto& [at, connection] : index_connections) {
    if (connections.count(connection) == 0) {
      *what = "the index at byte " + std::to_string(at) + " names an unknown connection " +
              std::to_string(connection);
      return false;
    }
  }
  return true;
}

}  // namespace internal
}  // namespace gravcal
#endif  // GRAVCAL_HAVE_ROSBAG
