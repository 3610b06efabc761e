// io/file_text.h (private): a whole file read into memory in one piece, for
// the parsers that work on a string_view of it.
#ifndef GRAVCAL_SRC_IO_FILE_TEXT_H_
#define GRAVCAL_SRC_IO_FILE_TEXT_H_

#include <cstddef>
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

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_FILE_TEXT_H_
