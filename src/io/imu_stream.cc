#include "gravcal/io/imu_stream.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <system_error>

#include "gravcal/core/imu_log.h"
#include "io/formats/file_format.h"
#include "io/log_text.h"
#include "util/error.h"
#include "util/shortest_double.h"

namespace gravcal {

namespace {

constexpr size_t kBufferSize = size_t{1} << 20;

std::string ErrnoText() { return std::generic_category().message(errno); }

}  // namespace

struct ImuCsvStreamReader::State {
  ~State() {
    if (owns_file && file != nullptr) std::fclose(file);
  }
  std::FILE* file = nullptr;
  bool owns_file = false;
  std::unique_ptr<internal::LogLines> lines;
  std::unique_ptr<internal::LogRowParser> parser;
  // A row read while looking for the layout (`columns` given: no header).
  bool pending = false;
  // A log read whole (bags, MCAP, gyro_path), served from memory.
  bool whole = false;
  ImuLog log;
  size_t next = 0;
};

ImuCsvStreamReader::ImuCsvStreamReader() = default;
ImuCsvStreamReader::~ImuCsvStreamReader() = default;

bool ImuCsvStreamReader::Open(const std::string& path, std::string* error) {
  return Open(path, LogReaderOptions(), error);
}

bool ImuCsvStreamReader::Open(const std::string& path, const LogReaderOptions& options,
                              std::string* error) {
  using internal::SetError;
  name_ = path == "-" ? "standard input" : path;
  state_ = std::make_unique<State>();
  State& s = *state_;
  std::string why;
  if (!options.IsValid(&why)) return SetError(error, name_ + ": invalid options: " + why);
  auto read_whole = [&]() {
    if (!ReadImuLog(path, options, &s.log, error)) return false;
    s.whole = true;
    has_gyro_ = s.log.has_gyro();
    has_temperature_ = !s.log.temperature.empty();
    return true;
  };
  if (!options.gyro_path.empty()) {
    if (path == "-") return SetError(error, "standard input: gyro_path needs the log in a file");
    return read_whole();
  }
  if (path == "-") {
    s.file = stdin;
  } else {
    s.file = std::fopen(path.c_str(), "rb");
    if (s.file == nullptr) return SetError(error, path + ": cannot open: " + ErrnoText());
    s.owns_file = true;
  }
  s.lines = std::make_unique<internal::LogLines>(s.file, name_);
  why.clear();
  const std::string_view head = s.lines->Head(4096, &why);
  if (!why.empty()) return SetError(error, why);
  internal::FileFormat format = internal::FileFormat::kText;
  if (!internal::DetectFileFormat(head, &format, &why)) return SetError(error, name_ + ": " + why);
  if (internal::NewMessageRecording(format) != nullptr) {
    if (path == "-") {
      return SetError(error, name_ + ": a " + internal::FileFormatName(format) +
                                 " is read from its file, not from standard input");
    }
    s.lines.reset();
    std::fclose(s.file);
    s.file = nullptr;
    return read_whole();
  }
  // An EuRoC / TUM-VI header is the header row once its '#' is dropped.
  const bool euroc = format == internal::FileFormat::kEuroc && internal::LayoutFromFile(options);
  s.parser = std::make_unique<internal::LogRowParser>(
      name_, euroc ? internal::EurocOptions(options) : options, false);
  std::string_view line;
  while (!s.parser->has_layout()) {
    if (!s.lines->Next(&line, &why)) {
      return SetError(error, why.empty() ? name_ + ": no samples" : why);
    }
    if (euroc && s.lines->number() == 1 && !line.empty() && line[0] == '#') line.remove_prefix(1);
    if (!s.parser->Line(line, s.lines->number(), &s.pending, error)) return false;
  }
  has_gyro_ = s.parser->has(internal::kGx);
  has_temperature_ = s.parser->has(internal::kTemp);
  return true;
}

bool ImuCsvStreamReader::Next(ImuSample* sample, std::string* error) {
  error->clear();
  if (state_ == nullptr) return internal::SetError(error, name_ + ": not open");
  State& s = *state_;
  if (s.whole) {
    if (s.next >= s.log.size()) return false;
    const size_t i = s.next++;
    sample->t = s.log.t[i];
    sample->accel = s.log.accel[i];
    sample->gyro = has_gyro_ ? s.log.gyro[i] : Eigen::Vector3d::Zero();
    sample->temperature = has_temperature_ ? s.log.temperature[i] : NAN;
    return true;
  }
  if (s.pending) {
    s.pending = false;
  } else {
    std::string_view line;
    for (bool row = false; !row;) {
      if (!s.lines->Next(&line, error)) {
        if (error->empty() && s.parser->rows() == 0) *error = name_ + ": no samples";
        return false;
      }
      if (!s.parser->Line(line, s.lines->number(), &row, error)) return false;
    }
  }
  const internal::LogRowParser& p = *s.parser;
  sample->t = p.value(internal::kT);
  sample->accel =
      Eigen::Vector3d(p.value(internal::kAx), p.value(internal::kAy), p.value(internal::kAz));
  sample->gyro = has_gyro_ ? Eigen::Vector3d(p.value(internal::kGx), p.value(internal::kGy),
                                             p.value(internal::kGz))
                           : Eigen::Vector3d::Zero();
  sample->temperature = has_temperature_ ? p.value(internal::kTemp) : NAN;
  return true;
}

std::string ImuCsvStreamReader::where() const { return where(position()); }

size_t ImuCsvStreamReader::position() const {
  if (state_ == nullptr) return 0;
  if (state_->whole) return state_->next > 0 ? state_->next - 1 : 0;
  return state_->lines != nullptr ? state_->lines->number() : 0;
}

std::string ImuCsvStreamReader::where(size_t position) const {
  if (state_ == nullptr) return name_;
  return name_ + (state_->whole ? ": sample " : ":") + std::to_string(position);
}

ImuCsvStreamWriter::~ImuCsvStreamWriter() { Abort(); }

bool ImuCsvStreamWriter::Open(const std::string& path, bool gyro, bool temperature,
                              const std::vector<std::string>& comment, std::string* error) {
  Abort();
  path_ = path;
  gyro_ = gyro;
  temperature_ = temperature;
  if (path == "-") {
    stdout_ = stdout;
  } else if (!file_.Open(path, error)) {
    return false;
  }
  open_ = true;
  buffer_.reserve(kBufferSize + 4096);
  for (const std::string& line : comment) buffer_ += "# " + line + "\n";
  buffer_ += "t,ax,ay,az";
  if (gyro_) buffer_ += ",gx,gy,gz";
  if (temperature_) buffer_ += ",temp";
  buffer_ += "\n";
  return true;
}

bool ImuCsvStreamWriter::WriteOut(const char* data, size_t size, std::string* error) {
  if (stdout_ == nullptr) return file_.Write(data, size, error);
  if (size > 0 && std::fwrite(data, 1, size, stdout_) != size) {
    *error = "standard output: cannot write: " + ErrnoText();
    return false;
  }
  return true;
}

bool ImuCsvStreamWriter::Flush(std::string* error) {
  if (!WriteOut(buffer_.data(), buffer_.size(), error)) return false;
  buffer_.clear();
  return true;
}

char* ImuCsvStreamWriter::FormatRow(const ImuSample& s, bool gyro, bool temperature, char* p) {
  static_assert(kMaxRowBytes >= 8 * (internal::kMaxShortestDouble + 1), "room for a row");
  auto put = [&](double v, char separator) {
    p = internal::WriteShortestDouble(v, p);
    *p++ = separator;
  };
  put(s.t, ',');
  put(s.accel(0), ',');
  put(s.accel(1), ',');
  put(s.accel(2), gyro || temperature ? ',' : '\n');
  if (gyro) {
    put(s.gyro(0), ',');
    put(s.gyro(1), ',');
    put(s.gyro(2), temperature ? ',' : '\n');
  }
  if (temperature) put(s.temperature, '\n');
  return p;
}

bool ImuCsvStreamWriter::Write(const ImuSample& s, std::string* error) {
  char text[kMaxRowBytes];
  buffer_.append(text, FormatRow(s, gyro_, temperature_, text));
  return buffer_.size() < kBufferSize || Flush(error);
}

bool ImuCsvStreamWriter::WriteRows(const char* text, size_t size, std::string* error) {
  if (buffer_.size() + size < kBufferSize) {
    buffer_.append(text, size);
    return true;
  }
  return Flush(error) && WriteOut(text, size, error);
}

bool ImuCsvStreamWriter::Commit(std::string* error) {
  if (!open_) {
    *error = path_ + ": not open";
    return false;
  }
  if (!Flush(error)) {
    Abort();
    return false;
  }
  open_ = false;
  if (stdout_ != nullptr) {
    const bool ok = std::fflush(stdout_) == 0;
    stdout_ = nullptr;
    if (!ok) *error = "standard output: cannot write: " + ErrnoText();
    return ok;
  }
  return file_.Commit(error);
}

void ImuCsvStreamWriter::Abort() {
  file_.Abort();
  stdout_ = nullptr;
  open_ = false;
  buffer_.clear();
}

}  // namespace gravcal
