// io/file_text.h (private): a whole file read into memory in one piece, for
// the parsers that work on a string_view of it.
#ifndef GRAVCAL_SRC_IO_FILE_TEXT_H_
#define GRAVCAL_SRC_IO_FILE_TEXT_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace gravcal {
namespace internal {

class FileText {
 public:
  // False with "<path>: cannot open|read: <why>" in *error.
  bool Read(const std::string& path, std::string* error);

  std::string_view view() const { return std::string_view(data_.get(), size_); }

 private:
  std::unique_ptr<char[]> data_;
  size_t size_ = 0;
};

// Memory the system can still give (MemAvailable of /proc/meminfo, else
// the free physical pages); 0 when unknown.
uint64_t AvailableMemoryBytes();

// A log of `file_bytes` parsed in memory needs its samples (8 doubles a
// row; the text is read block by block, never whole): about
// kLogMemoryPerFileByte times its size for raw counts (rows of ~40 bytes). False with a message
// saying how large the file is, what it needs and what to do, when that exceeds `available_bytes`
// (0 = unknown: no check).
constexpr double kLogMemoryPerFileByte = 1.7;
bool CheckLogFitsInMemory(const std::string& path, uint64_t file_bytes, uint64_t available_bytes,
                          std::string* error);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_FILE_TEXT_H_
