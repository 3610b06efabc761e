// The lines of a live text stream (io/line_source.h).
#include "io/line_source.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <cstring>

namespace gravcal {
namespace internal {

namespace {

// The termios constant of a baud rate; B0 when it has none.
speed_t BaudConstant(int baud) {
  switch (baud) {
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
#ifdef B460800
    case 460800:
      return B460800;
#endif
#ifdef B921600
    case 921600:
      return B921600;
#endif
    default:
      return B0;
  }
}

// HOST:PORT (HOST may be empty) into its parts.
bool SplitHostPort(const std::string& text, std::string* host, std::string* port) {
  const size_t colon = text.rfind(':');
  if (colon == std::string::npos || colon + 1 >= text.size()) return false;
  *host = text.substr(0, colon);
  *port = text.substr(colon + 1);
  return port->find_first_not_of("0123456789") == std::string::npos;
}

}  // namespace

LineSource::~LineSource() {
  if (owned_ && fd_ >= 0) close(fd_);
}

bool LineSource::Open(const std::string& spec, int baud, std::string* error) {
  name_ = spec == "-" ? "standard input" : spec;
  if (spec == "-") {
    fd_ = 0;
    return true;
  }
  const bool udp = spec.rfind("udp://", 0) == 0;
  const bool tcp = spec.rfind("tcp://", 0) == 0;
  if (udp || tcp) {
    std::string host, port;
    if (!SplitHostPort(spec.substr(6), &host, &port)) {
      *error = spec + ": expected " + (udp ? "udp://:PORT or udp://HOST:PORT" : "tcp://HOST:PORT");
      return false;
    }
    if (tcp && host.empty()) {
      *error = spec + ": a TCP source needs the host to connect to (tcp://HOST:PORT)";
      return false;
    }
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = udp ? SOCK_DGRAM : SOCK_STREAM;
    hints.ai_flags = udp ? AI_PASSIVE : 0;
    addrinfo* found = nullptr;
    const int rc = getaddrinfo(host.empty() ? nullptr : host.c_str(), port.c_str(), &hints, &found);
    if (rc != 0) {
      *error = spec + ": " + gai_strerror(rc);
      return false;
    }
    std::string why;
    for (addrinfo* a = found; a != nullptr; a = a->ai_next) {
      const int fd = socket(a->ai_family, a->ai_socktype, a->ai_protocol);
      if (fd < 0) continue;
      if ((udp ? bind(fd, a->ai_addr, a->ai_addrlen) : connect(fd, a->ai_addr, a->ai_addrlen)) ==
          0) {
        fd_ = fd;
        break;
      }
      why = std::strerror(errno);
      close(fd);
    }
    freeaddrinfo(found);
    if (fd_ < 0) {
      *error = spec + ": cannot " + (udp ? "listen" : "connect") + ": " + why;
      return false;
    }
    owned_ = true;
    datagram_ = udp;
    return true;
  }
  // A serial device (or any file or FIFO).
  fd_ = open(spec.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK);
  if (fd_ < 0) {
    *error = spec + ": cannot open: " + std::strerror(errno);
    return false;
  }
  owned_ = true;
  termios tty{};
  if (tcgetattr(fd_, &tty) == 0) {
    if (baud > 0) {
      const speed_t speed = BaudConstant(baud);
      if (speed == B0) {
        *error = spec + ": baud rate " + std::to_string(baud) +
                 " is not one of 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600";
        return false;
      }
      cfsetispeed(&tty, speed);
      cfsetospeed(&tty, speed);
    }
    cfmakeraw(&tty);
    tty.c_cflag |= CLOCAL | CREAD;
    tty.c_cflag &= ~(CSTOPB | PARENB | CRTSCTS);
    if (tcsetattr(fd_, TCSANOW, &tty) != 0) {
      *error = spec + ": cannot set the serial line: " + std::strerror(errno);
      return false;
    }
  } else if (baud > 0) {
    *error = spec + ": --baud given but this is not a serial device";
    return false;
  }
  return true;
}

void LineSource::Split(const char* data, size_t size, std::vector<std::string>* lines) {
  for (size_t i = 0; i < size; ++i) {
    const char c = data[i];
    if (c == '\n' && last_was_return_) {
      last_was_return_ = false;
      continue;
    }
    last_was_return_ = c == '\r';
    if (c == '\n' || c == '\r') {
      lines->push_back(std::move(partial_));
      partial_.clear();
    } else if (partial_.size() < kMaxLineBytes) {
      partial_.push_back(c);
    }
  }
}

LineSource::Status LineSource::Read(int timeout_ms, std::vector<std::string>* lines,
                                    std::string* error) {
  pollfd p{};
  p.fd = fd_;
  p.events = POLLIN;
  const int ready = poll(&p, 1, timeout_ms);
  if (ready < 0) {
    if (errno == EINTR) return Status::kInterrupted;
    *error = name_ + ": " + std::strerror(errno);
    return Status::kError;
  }
  if (ready == 0) return Status::kTimeout;
  char buffer[65536];
  const ssize_t n =
      datagram_ ? recv(fd_, buffer, sizeof(buffer), 0) : read(fd_, buffer, sizeof(buffer));
  if (n < 0) {
    if (errno == EINTR) return Status::kInterrupted;
    if (errno == EAGAIN || errno == EWOULDBLOCK) return Status::kTimeout;
    // A serial adapter unplugged reads EIO: the end, said.
    *error = name_ + ": " + std::strerror(errno);
    if (!partial_.empty()) lines->push_back(std::move(partial_));
    partial_.clear();
    return Status::kEnd;
  }
  if (n == 0 && !datagram_) {
    if (!partial_.empty()) lines->push_back(std::move(partial_));
    partial_.clear();
    return Status::kEnd;
  }
  Split(buffer, static_cast<size_t>(n), lines);
  // A datagram ends its last line.
  if (datagram_ && !partial_.empty()) {
    lines->push_back(std::move(partial_));
    partial_.clear();
  }
  return lines->empty() ? Status::kTimeout : Status::kLines;
}

}  // namespace internal
}  // namespace gravcal
