#include "gravcal/io/files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <string>
#include <system_error>
#include <utility>

#include "io/file_text.h"
#include "util/error.h"

namespace gravcal {
namespace {

using internal::SetError;

std::string ErrnoMessage(int errnum) { return std::generic_category().message(errnum); }

}  // namespace

namespace internal {

uint64_t AvailableMemoryBytes() {
  if (FILE* f = std::fopen("/proc/meminfo", "r")) {
    char line[256];
    unsigned long long kib = 0;
    bool found = false;
    while (!found && std::fgets(line, sizeof(line), f) != nullptr) {
      found = std::sscanf(line, "MemAvailable: %llu kB", &kib) == 1;
    }
    std::fclose(f);
    if (found) return static_cast<uint64_t>(kib) * 1024;
  }
  const long pages = sysconf(_SC_AVPHYS_PAGES);
  const long page_size = sysconf(_SC_PAGESIZE);
  return pages > 0 && page_size > 0 ? static_cast<uint64_t>(pages) * page_size : 0;
}

namespace {

std::string Gigabytes(double bytes) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f GB", bytes / 1e9);
  return text;
}

}  // namespace

bool CheckLogFitsInMemory(const std::string& path, uint64_t file_bytes, uint64_t available_bytes,
                          std::string* error) {
  const double needed = kLogMemoryPerFileByte * static_cast<double>(file_bytes);
  if (available_bytes == 0 || needed <= static_cast<double>(available_bytes)) return true;
  return SetError(error, path + ": the log is " + Gigabytes(static_cast<double>(file_bytes)) +
                             " and reading it needs about " + Gigabytes(needed) + " of memory; " +
                             Gigabytes(static_cast<double>(available_bytes)) +
                             " is available. Split it into shorter sessions (each calibration "
                             "needs only its own poses) or run on a machine with more memory");
}

bool FileText::Read(const std::string& path, std::string* error) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return SetError(error, path + ": cannot open: " + ErrnoMessage(errno));
  size_t capacity = size_t{1} << 16;
  struct stat st;
  if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) {
    // One more byte than the size, so that end of file shows without a regrow.
    capacity = static_cast<size_t>(st.st_size) + 1;
  }
  data_.reset(new (std::nothrow) char[capacity]);
  size_ = 0;
  if (!data_) {
    close(fd);
    return SetError(error, path + ": cannot read: out of memory");
  }
  for (;;) {
    if (size_ == capacity) {
      const size_t bigger = capacity * 2;
      std::unique_ptr<char[]> grown(new (std::nothrow) char[bigger]);
      if (!grown) {
        close(fd);
        return SetError(error, path + ": cannot read: out of memory");
      }
      std::memcpy(grown.get(), data_.get(), size_);
      data_ = std::move(grown);
      capacity = bigger;
    }
    const ssize_t n = read(fd, data_.get() + size_, capacity - size_);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int errnum = errno;
      close(fd);
      return SetError(error, path + ": cannot read: " + ErrnoMessage(errnum));
    }
    if (n == 0) break;
    size_ += static_cast<size_t>(n);
  }
  close(fd);
  return true;
}

}  // namespace internal

using internal::FileText;

bool ReadFileBytes(const std::string& path, std::string* bytes, std::string* error) {
  try {
    FileText text;
    if (!text.Read(path, error)) return false;
    bytes->assign(text.view());
    return true;
  } catch (const std::exception& e) {
    return SetError(error, path + ": cannot read: " + e.what());
  }
}

bool WriteFileAtomically(const std::string& path, const std::string& contents, std::string* error) {
  if (path.empty()) return SetError(error, "cannot write a file with an empty name");
  try {
    const std::string temporary = path + ".tmp." + std::to_string(getpid());
    const int fd = open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) {
      return SetError(error, path + ": cannot create '" + temporary + "': " + ErrnoMessage(errno));
    }
    auto fail = [&](const std::string& what, int errnum) {
      unlink(temporary.c_str());
      return SetError(error, path + ": " + what + ": " + ErrnoMessage(errnum));
    };
    const char* p = contents.data();
    size_t left = contents.size();
    while (left > 0) {
      const ssize_t n = write(fd, p, left);
      if (n < 0) {
        if (errno == EINTR) continue;
        const int errnum = errno;
        close(fd);
        return fail("cannot write", errnum);
      }
      p += n;
      left -= static_cast<size_t>(n);
    }
    if (close(fd) != 0) return fail("cannot write", errno);
    if (rename(temporary.c_str(), path.c_str()) != 0)
      return fail("cannot rename into place", errno);
    return true;
  } catch (const std::exception& e) {
    return SetError(error, path + ": cannot write: " + e.what());
  }
}

}  // namespace gravcal
