// io/formats/ros1_bag_structure.h (private): the whole structure of a ROS 1
// bag (format 2.0) checked before librosbag_storage reads it.
//
// librosbag_storage trusts the lengths and offsets a bag holds: it
// allocates what a length field says, parses record headers in place and
// reads a message at whatever offset the index names inside a chunk, with
// no bounds check. A damaged bag then asks for gigabytes or reads outside
// its buffers (all three found by fuzz/fuzz_ros1_bag and
// fuzz/fuzz_rosbag2_db3). So every record is checked here first, in bounded
// memory (one chunk at a time):
// - top-level records: header_len (uint32 LE), header, data_len, data, all
//   inside the file; every header a sequence of field_len + "name=value"
//   that fills it exactly, with an op field;
// - the file header's index_pos and every chunk info's chunk_pos name the
//   start of a top-level record (a chunk for chunk_pos);
// - every chunk decompresses ("none", "bz2", "lz4") to exactly its declared
//   size, at most kMaxRos1ChunkBytes, and its records fill it exactly, each
//   well formed as above;
// - every index entry after a chunk names the start of a message record
//   in that chunk;
// - every connection record's data is itself a well-formed field block.
#ifndef GRAVCAL_SRC_IO_FORMATS_ROS1_BAG_STRUCTURE_H_
#define GRAVCAL_SRC_IO_FORMATS_ROS1_BAG_STRUCTURE_H_

#include <cstdint>
#include <string>

namespace gravcal {
namespace internal {

// A chunk larger than this uncompressed, or a record header or checked
// record data larger than this, is refused (rosbag writes chunks of 768 kB
// by default).
constexpr uint32_t kMaxRos1ChunkBytes = 256u << 20;

// True when the bag at `path` is well formed as above; else false and
// *what says where it is not (without the path).
bool CheckRos1BagStructure(const std::string& path, std::string* what);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_FORMATS_ROS1_BAG_STRUCTURE_H_
