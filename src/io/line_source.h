// io/line_source.h (private): the lines of a live text stream (gravcal
// record): standard input ("-"), a serial device (a path, with a baud rate;
// termios raw mode, 8N1), a UDP port ("udp://:PORT" or "udp://HOST:PORT",
// every datagram one or more lines) or a TCP server to connect to
// ("tcp://HOST:PORT"). Text lines only: a binary protocol (MAVLink, UBX,
// vendor frames) is not read; its bytes come out as garbage lines.
//
// Lines end at "\n", "\r\n" or "\r"; a line longer than kMaxLineBytes is
// returned cut (the caller's parser refuses it as garbage). Read with a
// timeout so that the caller can say "no data for 3 s" on a stall, and
// interrupted by a signal (Ctrl-C) without losing what was read.
#ifndef GRAVCAL_SRC_IO_LINE_SOURCE_H_
#define GRAVCAL_SRC_IO_LINE_SOURCE_H_

#include <cstddef>
#include <string>
#include <vector>

namespace gravcal {
namespace internal {

class LineSource {
 public:
  static constexpr size_t kMaxLineBytes = size_t{1} << 16;

  LineSource() = default;
  ~LineSource();
  LineSource(const LineSource&) = delete;
  LineSource& operator=(const LineSource&) = delete;

  // Opens `spec` (above); baud is used for a serial device only (0 = leave
  // the device's setting). False with a one-line *error naming the source.
  bool Open(const std::string& spec, int baud, std::string* error);

  enum class Status { kLines, kTimeout, kEnd, kInterrupted, kError };
  // Waits up to timeout_ms for data and appends the complete lines read to
  // *lines. kEnd: end of input or the peer closed (a partial last line is
  // returned as a line); kError with *error (a device unplugged reads as
  // kEnd with *error saying so).
  Status Read(int timeout_ms, std::vector<std::string>* lines, std::string* error);

  const std::string& name() const { return name_; }

 private:
  void Split(const char* data, size_t size, std::vector<std::string>* lines);

  int fd_ = -1;
  bool owned_ = false;
  bool datagram_ = false;
  std::string name_;
  std::string partial_;
  bool last_was_return_ = false;
};

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_LINE_SOURCE_H_
