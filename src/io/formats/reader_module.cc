// The library's side of the reader module (reader_module.h): finding and
// loading libgravcal_formats.so, and the readers that load it on Open.
#include "io/formats/reader_module.h"

#include <dlfcn.h>
#include <sys/stat.h>
#include <unistd.h>

#include <climits>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <vector>

namespace gravcal {
namespace internal {

namespace {

struct ReaderModuleState {
  ReaderModuleNewFunction create = nullptr;
  std::string where;  // The file loaded.
  std::string why;    // Why it was not, when create is null.
};

std::string ModuleFolderOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

// The folder of the binary this code is in: the tool, the Python
// extension or a program linking the library.
std::string ModuleOwnFolder() {
  Dl_info info{};
  std::string file;
  if (dladdr(reinterpret_cast<void*>(&NewModuleRecording), &info) != 0 &&
      info.dli_fname != nullptr) {
    file = info.dli_fname;
  }
  // The main program is named as it was started (maybe relative, and the
  // folder may have changed since): /proc/self/exe names its file.
  if (file.empty() || file[0] != '/') {
    char exe[PATH_MAX];
    const ssize_t n = readlink("/proc/self/exe", exe, sizeof(exe) - 1);
    if (n <= 0) return std::string();
    file.assign(exe, static_cast<size_t>(n));
  }
  return ModuleFolderOf(file);
}

std::vector<std::string> ModuleFolders() {
  std::vector<std::string> folders;
  // Given, it is the only place looked in.
  if (const char* dir = std::getenv("GRAVCAL_MODULE_DIR"); dir != nullptr && *dir != '\0') {
    folders.push_back(dir);
    return folders;
  }
  const std::string own = ModuleOwnFolder();
  if (!own.empty()) {
    folders.push_back(own);
    folders.push_back(own + "/../" GRAVCAL_MODULE_INSTALL_LIBDIR "/gravcal");
    folders.push_back(own + "/../lib/gravcal");
  }
  folders.push_back(GRAVCAL_MODULE_INSTALL_DIR);
  folders.push_back(GRAVCAL_MODULE_BUILD_DIR);
  return folders;
}

ReaderModuleState LoadReaderModuleOnce() {
  ReaderModuleState m;
  std::string looked;
  for (const std::string& folder : ModuleFolders()) {
    const std::string file = folder + "/" + kReaderModuleFile;
    struct stat st;
    if (stat(file.c_str(), &st) != 0) {
      if (looked.find(folder + ",") == std::string::npos) looked += folder + ", ";
      continue;
    }
    void* handle = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* e = dlerror();
      m.why = file + " cannot be loaded: " + (e != nullptr ? e : "dlopen failed");
      return m;
    }
    const auto version =
        reinterpret_cast<ReaderModuleVersionFunction>(dlsym(handle, kReaderModuleVersion));
    const auto create = reinterpret_cast<ReaderModuleNewFunction>(dlsym(handle, kReaderModuleNew));
    if (version == nullptr || create == nullptr) {
      m.why = file + " is not gravcal's reader module (no " + kReaderModuleNew + ")";
      return m;
    }
    if (std::strcmp(version(), GRAVCAL_VERSION) != 0) {
      m.why = file + " is of gravcal " + version() +
              ", this is gravcal " GRAVCAL_VERSION " (reinstall, or set GRAVCAL_MODULE_DIR)";
      return m;
    }
    m.create = create;
    m.where = file;
    return m;
  }
  if (looked.size() >= 2) looked.resize(looked.size() - 2);
  m.why = std::string("its reader module ") + kReaderModuleFile + " was not found (looked in " +
          looked + "; set GRAVCAL_MODULE_DIR to its folder)";
  return m;
}

const ReaderModuleState& TheReaderModule() {
  static const ReaderModuleState module = LoadReaderModuleOnce();  // Thread-safe, once.
  return module;
}

// A reader of a message-based format that loads the module when opened.
class ModuleRecording : public MessageRecording {
 public:
  ModuleRecording(int format, const char* format_name)
      : format_(format), format_name_(format_name) {}
  const char* FormatName() const override { return format_name_; }
  bool Open(const std::string& path, std::string* error) override {
    const ReaderModuleState& m = TheReaderModule();
    if (m.create == nullptr) {
      *error = path + ": cannot read a " + format_name_ + ": " + m.why;
      return false;
    }
    impl_.reset(m.create(format_));
    if (impl_ == nullptr) {
      *error = path + ": cannot read a " + format_name_ + ": " + m.where + " has no reader for it";
      return false;
    }
    return impl_->Open(path, error);
  }
  const std::vector<RecordingTopic>& topics() const override {
    return impl_ != nullptr ? impl_->topics() : no_topics_;
  }
  bool Read(const std::vector<bool>& wanted, const MessageVisitor& visit,
            std::string* error) override {
    if (impl_ == nullptr) {
      *error = std::string(format_name_) + ": not open";
      return false;
    }
    return impl_->Read(wanted, visit, error);
  }

 private:
  const int format_;
  const char* const format_name_;
  std::unique_ptr<MessageRecording> impl_;
  const std::vector<RecordingTopic> no_topics_;
};

}  // namespace

std::unique_ptr<MessageRecording> NewModuleRecording(int format, const char* format_name) {
  return std::make_unique<ModuleRecording>(format, format_name);
}

bool LoadReaderModule(std::string* where, std::string* why) {
  const ReaderModuleState& m = TheReaderModule();
  *where = m.where;
  *why = m.why;
  return m.create != nullptr;
}

}  // namespace internal
}  // namespace gravcal
