#include "gravcal/io/files.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
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

namespace {

constexpr char kTemporaryMarker[] = ".gravcal-tmp.";
constexpr int kMaxLinks = 40;

// "d/" of "d/x.json", "" for a bare name; the root stays "/".
std::string FolderPart(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "" : path.substr(0, slash + 1);
}

std::string NamePart(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// The folder for system calls ("." for "").
std::string FolderForCalls(const std::string& folder) { return folder.empty() ? "." : folder; }

const char* KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// The file a write to `path` lands on: symbolic links followed (a relative
// link from its own folder), also a link whose target does not exist yet.
bool ResolveLinks(const std::string& path, std::string* target, std::string* error) {
  std::string current = path;
  for (int hops = 0; hops <= kMaxLinks; ++hops) {
    struct stat st;
    if (lstat(current.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) {
      *target = current;
      return true;
    }
    std::string link(static_cast<size_t>(st.st_size > 0 ? st.st_size : 255) + 1, '\0');
    const ssize_t n = readlink(current.c_str(), &link[0], link.size());
    if (n < 0) return SetError(error, path + ": cannot read the link: " + ErrnoMessage(errno));
    link.resize(static_cast<size_t>(n));
    current = !link.empty() && link[0] == '/' ? link : FolderPart(current) + link;
  }
  return SetError(error, path + ": too many levels of symbolic links");
}

// Where a file destination lands, checked: links resolved, not an existing
// non-regular file, in a folder that exists and can be written. *exists and
// *st say what is there now.
bool CheckFileTarget(const std::string& path, std::string* target, bool* exists, struct stat* st,
                     std::string* error) {
  if (path.empty()) return SetError(error, "cannot write a file with an empty name");
  if (path == "-") {
    return SetError(error,
                    "-: standard output is not accepted for this output; name a file (./- for "
                    "a file called '-')");
  }
  if (!ResolveLinks(path, target, error)) return false;
  const std::string folder = FolderPart(*target);
  if (NamePart(*target).empty() || NamePart(*target) == "." || NamePart(*target) == "..") {
    return SetError(error, path + ": names a folder, not a file");
  }
  struct stat fs;
  if (stat(FolderForCalls(folder).c_str(), &fs) != 0) {
    const int errnum = errno;
    if (errnum == ENOENT) return SetError(error, path + ": folder '" + folder + "' does not exist");
    if (errnum == ENOTDIR) return SetError(error, path + ": '" + folder + "' is not a folder");
    return SetError(error, path + ": folder '" + folder + "': " + ErrnoMessage(errnum));
  }
  if (!S_ISDIR(fs.st_mode)) return SetError(error, path + ": '" + folder + "' is not a folder");
  *exists = stat(target->c_str(), st) == 0;
  if (!*exists && errno != ENOENT) {
    return SetError(error, path + ": cannot write: " + ErrnoMessage(errno));
  }
  if (*exists && !S_ISREG(st->st_mode)) {
    return SetError(error, path + ": exists and is " + KindOf(st->st_mode) +
                               ": gravcal replaces only regular files");
  }
  if (access(FolderForCalls(folder).c_str(), W_OK | X_OK) != 0) {
    return SetError(error, path + ": cannot write in folder '" +
                               (folder.empty() ? std::string("./") : folder) +
                               "': " + ErrnoMessage(errno));
  }
  return true;
}

// A name no other run (or earlier open) uses: the clock, a counter and the
// address space mixed (splitmix64), shown as 8 hex digits.
std::string RandomPart() {
  static std::atomic<uint64_t> counter{0};
  struct timespec now;
  clock_gettime(CLOCK_REALTIME, &now);
  uint64_t x = static_cast<uint64_t>(now.tv_nsec) ^ (static_cast<uint64_t>(now.tv_sec) << 30) ^
               (counter.fetch_add(1) * 0x9E3779B97F4A7C15ull) ^
               reinterpret_cast<uintptr_t>(&counter);
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  x ^= x >> 31;
  char text[16];
  std::snprintf(text, sizeof(text), "%08x", static_cast<unsigned>(x & 0xffffffffu));
  return text;
}

// The identity of a file: device and inode.
struct FileId {
  dev_t dev = 0;
  ino_t ino = 0;
  bool operator==(const FileId& o) const { return dev == o.dev && ino == o.ino; }
};

}  // namespace

bool IsGravcalTemporaryName(const std::string& name) {
  const size_t marker = sizeof(kTemporaryMarker) - 1;
  if (name.compare(0, marker, kTemporaryMarker) != 0) return false;
  size_t i = marker;
  const size_t pid_begin = i;
  while (i < name.size() && name[i] >= '0' && name[i] <= '9') ++i;
  if (i == pid_begin || i - pid_begin > 10 || i >= name.size() || name[i] != '.') return false;
  const size_t random_begin = ++i;
  while (i < name.size() && std::isxdigit(static_cast<unsigned char>(name[i]))) ++i;
  return i - random_begin == 8 && i + 1 < name.size() && name[i] == '.';
}

int RemoveStaleTemporaries(const std::string& folder) {
  DIR* dir = opendir(FolderForCalls(folder).c_str());
  if (dir == nullptr) return 0;
  int removed = 0;
  while (const dirent* entry = readdir(dir)) {
    const std::string name = entry->d_name;
    if (!IsGravcalTemporaryName(name)) continue;
    const long pid = std::strtol(name.c_str() + sizeof(kTemporaryMarker) - 1, nullptr, 10);
    // A process of that number exists (or may: EPERM): not provably stale.
    if (pid <= 0 || kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    const int fd = openat(dirfd(dir), name.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) continue;
    struct stat st;
    // The writer holds its lock until the rename: a free lock and a gone
    // process prove that nobody will finish this file.
    if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && flock(fd, LOCK_EX | LOCK_NB) == 0 &&
        unlinkat(dirfd(dir), name.c_str(), 0) == 0) {
      ++removed;
    }
    close(fd);
  }
  closedir(dir);
  return removed;
}

AtomicFile::~AtomicFile() { Abort(); }

bool AtomicFile::Open(const std::string& path, std::string* error) {
  Abort();
  path_ = path;
  bool exists = false;
  struct stat st;
  if (!CheckFileTarget(path, &target_, &exists, &st, error)) return false;
  const std::string folder = FolderPart(target_);
  std::string name = NamePart(target_);
  const std::string prefix =
      std::string(kTemporaryMarker) + std::to_string(getpid()) + "." + RandomPart() + ".";
  constexpr size_t kNameMax = 255;
  if (prefix.size() + name.size() > kNameMax) name.resize(kNameMax - prefix.size());
  for (int attempt = 0; attempt < 16; ++attempt) {
    temporary_ = folder + std::string(kTemporaryMarker) + std::to_string(getpid()) + "." +
                 RandomPart() + "." + name;
    fd_ = open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd_ >= 0 || errno != EEXIST) break;
  }
  if (fd_ < 0) {
    const int errnum = errno;
    temporary_.clear();
    return SetError(error, path + ": cannot write: " + ErrnoMessage(errnum));
  }
  flock(fd_, LOCK_EX);
  // A replaced file keeps its permissions.
  if (exists) fchmod(fd_, st.st_mode & 07777);
  return true;
}

bool AtomicFile::Write(const char* data, size_t size, std::string* error) {
  if (fd_ < 0) return SetError(error, path_ + ": not open");
  while (size > 0) {
    const ssize_t n = write(fd_, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int errnum = errno;
      Abort();
      return SetError(error, path_ + ": cannot write: " + ErrnoMessage(errnum));
    }
    data += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

bool AtomicFile::Close(std::string* error) {
  if (fd_ < 0) return temporary_.empty() ? SetError(error, path_ + ": not open") : true;
  // What is at the destination now: a FIFO or device put there since Open
  // is still never replaced.
  struct stat st;
  if (stat(target_.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    Abort();
    return SetError(error, path_ + ": exists and is " + KindOf(st.st_mode) +
                               ": gravcal replaces only regular files");
  }
  const int fd = fd_;
  fd_ = -1;
  if (close(fd) != 0) {
    const int errnum = errno;
    Abort();
    return SetError(error, path_ + ": cannot write: " + ErrnoMessage(errnum));
  }
  return true;
}

bool AtomicFile::Commit(std::string* error) {
  if (!Close(error)) return false;
  if (rename(temporary_.c_str(), target_.c_str()) != 0) {
    const int errnum = errno;
    Abort();
    return SetError(error, path_ + ": cannot put the file in place: " + ErrnoMessage(errnum));
  }
  temporary_.clear();
  return true;
}

void AtomicFile::Abort() {
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
  if (!temporary_.empty()) unlink(temporary_.c_str());
  temporary_.clear();
}

bool WriteFileAtomically(const std::string& path, const std::string& contents, std::string* error) {
  try {
    AtomicFile file;
    return file.Open(path, error) && file.Write(contents.data(), contents.size(), error) &&
           file.Commit(error);
  } catch (const std::exception& e) {
    return SetError(error, path + ": cannot write: " + e.what());
  }
}

bool WriteFilesAtomically(const std::vector<FileContents>& files, std::string* error) {
  try {
    std::vector<std::unique_ptr<AtomicFile>> open;
    for (const FileContents& f : files) {
      if (f.path.empty()) continue;
      open.push_back(std::make_unique<AtomicFile>());
      AtomicFile& file = *open.back();
      if (!file.Open(f.path, error) || !file.Write(f.contents.data(), f.contents.size(), error) ||
          !file.Close(error)) {
        return false;  // every temporary removed by its destructor
      }
    }
    for (const std::unique_ptr<AtomicFile>& file : open) {
      if (!file->Commit(error)) return false;
    }
    return true;
  } catch (const std::exception& e) {
    return SetError(error, std::string("cannot write the outputs: ") + e.what());
  }
}

bool MakeFolders(const std::string& path, std::string* error) {
  for (size_t end = 1; end <= path.size(); ++end) {
    if (end != path.size() && path[end] != '/') continue;
    const std::string level = path.substr(0, end);
    if (mkdir(level.c_str(), 0777) != 0 && errno != EEXIST) {
      return SetError(error,
                      path + ": cannot create the folder '" + level + "': " + ErrnoMessage(errno));
    }
  }
  struct stat st;
  if (stat(path.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    return SetError(error, path + ": is not a folder");
  }
  return true;
}

bool CheckDestinations(const std::vector<Destination>& destinations,
                       const std::vector<Source>& sources, std::string* error) {
  try {
    std::vector<std::pair<FileId, const Source*>> read;
    for (const Source& s : sources) {
      struct stat st;
      if (s.path.empty() || s.path == "-" || stat(s.path.c_str(), &st) != 0) continue;
      read.push_back({{st.st_dev, st.st_ino}, &s});
    }
    // Destinations seen so far: by identity when they exist, else by their
    // folder's identity and name; by path inside a folder still to make.
    std::vector<std::pair<FileId, std::string>> seen_key;
    std::vector<const Destination*> seen;
    std::vector<std::string> new_folders;
    const Destination* standard_output = nullptr;
    auto named = [](const std::string& flag, const std::string& path) {
      return flag.empty() ? "'" + path + "'" : flag + " (" + path + ")";
    };
    for (const Destination& d : destinations) {
      if (d.path.empty()) continue;
      const std::string flag = d.flag.empty() ? "this output" : d.flag;
      if (d.path == "-") {
        if (!d.standard_output) {
          return SetError(error, "-: " + flag +
                                     " cannot be standard output; name a file (./- for a file "
                                     "called '-')");
        }
        if (standard_output != nullptr) {
          return SetError(error, "-: " + flag + " and " + standard_output->flag +
                                     " cannot both be standard output");
        }
        standard_output = &d;
        // `gravcal apply --input s.csv --output - >> s.csv` would read what
        // it appends.
        struct stat out;
        if (fstat(STDOUT_FILENO, &out) == 0 && S_ISREG(out.st_mode)) {
          for (const auto& [id, source] : read) {
            if (id == FileId{out.st_dev, out.st_ino}) {
              return SetError(error, "-: " + flag + " is standard output, which is the input " +
                                         named(source->flag, source->path) +
                                         ": gravcal never overwrites its input");
            }
          }
        }
        continue;
      }
      std::string target;
      if (!ResolveLinks(d.path, &target, error)) return false;
      struct stat st;
      const bool exists = stat(target.c_str(), &st) == 0;
      FileId key;
      std::string name;
      if (d.folder) {
        if (exists && !S_ISDIR(st.st_mode)) {
          return SetError(error, d.path + ": exists and is not a folder (" + flag + ")");
        }
        if (!exists) {
          // The nearest existing ancestor must be a folder gravcal can write in.
          std::string up = target;
          while (!up.empty() && up.back() == '/') up.pop_back();
          struct stat as;
          for (;;) {
            up = FolderPart(up);
            while (up.size() > 1 && up.back() == '/') up.pop_back();
            if (stat(FolderForCalls(up).c_str(), &as) == 0 || errno != ENOENT) break;
          }
          if (stat(FolderForCalls(up).c_str(), &as) != 0 || !S_ISDIR(as.st_mode)) {
            return SetError(error,
                            d.path + ": cannot create the folder: '" + up + "' is not a folder");
          }
          if (access(FolderForCalls(up).c_str(), W_OK | X_OK) != 0) {
            return SetError(error, d.path + ": cannot create the folder in '" + FolderForCalls(up) +
                                       "': " + ErrnoMessage(errno));
          }
          std::string clean = d.path;
          while (clean.size() > 1 && clean.back() == '/') clean.pop_back();
          new_folders.push_back(clean);
          continue;
        }
        if (access(target.c_str(), W_OK | X_OK) != 0) {
          return SetError(error, d.path + ": cannot write in the folder: " + ErrnoMessage(errno));
        }
        key = {st.st_dev, st.st_ino};
      } else {
        std::string folder = FolderPart(d.path);
        while (folder.size() > 1 && folder.back() == '/') folder.pop_back();
        bool in_new_folder = false;
        for (const std::string& f : new_folders) in_new_folder = in_new_folder || f == folder;
        if (in_new_folder) {
          // Nothing there yet: only another destination can collide.
          name = d.path;
        } else {
          bool file_exists = false;
          struct stat fs;
          if (!CheckFileTarget(d.path, &target, &file_exists, &fs, error)) return false;
          if (file_exists) {
            key = {fs.st_dev, fs.st_ino};
          } else {
            struct stat ds;
            if (stat(FolderForCalls(FolderPart(target)).c_str(), &ds) != 0) {
              return SetError(error, d.path + ": cannot write: " + ErrnoMessage(errno));
            }
            key = {ds.st_dev, ds.st_ino};
            name = NamePart(target);
          }
        }
      }
      if (name.empty()) {
        for (const auto& [id, source] : read) {
          if (id == key) {
            return SetError(error, d.path + ": " + flag + " is the same " +
                                       (d.folder ? "folder" : "file") + " as the input " +
                                       named(source->flag, source->path) +
                                       ": gravcal never overwrites its input");
          }
        }
      }
      for (size_t k = 0; k < seen.size(); ++k) {
        if (seen_key[k].first == key && seen_key[k].second == name) {
          return SetError(error, d.path + ": " + flag + " is the same " +
                                     (d.folder ? "folder" : "file") + " as " +
                                     named(seen[k]->flag, seen[k]->path));
        }
      }
      seen.push_back(&d);
      seen_key.push_back({key, name});
    }
    return true;
  } catch (const std::exception& e) {
    return SetError(error, std::string("cannot check the outputs: ") + e.what());
  }
}

}  // namespace gravcal
