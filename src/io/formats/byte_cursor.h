// io/formats/byte_cursor.h (private): bounds-checked little-endian reads over
// a block of bytes, for the binary recording formats. A read past the end
// fails and leaves the cursor failed; callers check ok() once per record.
#ifndef GRAVCAL_SRC_IO_FORMATS_BYTE_CURSOR_H_
#define GRAVCAL_SRC_IO_FORMATS_BYTE_CURSOR_H_

#include <cstddef>
#include <cstdint>
#include <string>

namespace gravcal {
namespace internal {

class ByteCursor {
 public:
  ByteCursor(const uint8_t* data, size_t size) : p_(data), end_(data + size) {}

  bool ok() const { return ok_; }
  size_t remaining() const { return static_cast<size_t>(end_ - p_); }
  const uint8_t* position() const { return p_; }

  uint8_t U8() { return static_cast<uint8_t>(Unsigned(1)); }
  uint16_t U16() { return static_cast<uint16_t>(Unsigned(2)); }
  uint32_t U32() { return static_cast<uint32_t>(Unsigned(4)); }
  uint64_t U64() { return Unsigned(8); }

  // `n` bytes; null (and failed) when fewer remain.
  const uint8_t* Bytes(uint64_t n) {
    if (!ok_ || n > remaining()) {
      ok_ = false;
      return nullptr;
    }
    const uint8_t* at = p_;
    p_ += n;
    return at;
  }
  // A uint32 length, then that many bytes.
  std::string String() {
    const uint32_t n = U32();
    const uint8_t* at = Bytes(n);
    return at == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(at), n);
  }

 private:
  uint64_t Unsigned(int bytes) {
    const uint8_t* at = Bytes(static_cast<uint64_t>(bytes));
    uint64_t value = 0;
    if (at == nullptr) return 0;
    for (int i = 0; i < bytes; ++i) value |= uint64_t{at[i]} << (8 * i);
    return value;
  }

  const uint8_t* p_;
  const uint8_t* end_;
  bool ok_ = true;
};

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_FORMATS_BYTE_CURSOR_H_
