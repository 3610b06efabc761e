#include "gravcal/io/imu_stream.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <system_error>

namespace gravcal {

namespace {

constexpr size_t kBufferSize = size_t{1} << 20;

std::string ErrnoText() { return std::generic_category().message(errno); }

// [begin, end) without spaces, tabs and a carriage return at either end.
void Trim(const char** begin, const char** end) {
  while (*begin < *end && (**begin == ' ' || **begin == '\t')) ++*begin;
  while (*end > *begin && ((*end)[-1] == ' ' || (*end)[-1] == '\t' || (*end)[-1] == '\r')) --*end;
}

bool ParseNumber(const char* begin, const char* end, double* value) {
  Trim(&begin, &end);
  if (begin < end && *begin == '+') ++begin;
  if (begin == end) return false;
  const std::from_chars_result r = std::from_chars(begin, end, *value);
  return r.ec == std::errc() && r.ptr == end;
}

}  // namespace

ImuCsvStreamReader::~ImuCsvStreamReader() {
  if (owns_file_ && file_ != nullptr) std::fclose(file_);
}

bool ImuCsvStreamReader::Fail(const std::string& message, std::string* error) const {
  *error = name_ + ":" + std::to_string(line_) + ": " + message;
  return false;
}

bool ImuCsvStreamReader::ReadLine(const char** begin, const char** end, std::string* error) {
  for (;;) {
    const char* start = buffer_.data() + begin_;
    const char* newline = static_cast<const char*>(std::memchr(start, '\n', end_ - begin_));
    if (newline != nullptr) {
      *begin = start;
      *end = newline;
      begin_ = static_cast<size_t>(newline - buffer_.data()) + 1;
      ++line_;
      return true;
    }
    if (eof_) {
      if (begin_ == end_) return false;
      // The last line has no end of line.
      *begin = start;
      *end = buffer_.data() + end_;
      begin_ = end_;
      ++line_;
      return true;
    }
    // Move the partial line to the front (grow for a line longer than the
    // buffer) and read more.
    std::memmove(buffer_.data(), start, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
    if (end_ == buffer_.size()) buffer_.resize(buffer_.size() * 2);
    const size_t n = std::fread(buffer_.data() + end_, 1, buffer_.size() - end_, file_);
    if (n == 0) {
      if (std::ferror(file_)) {
        *error = name_ + ": cannot read: " + ErrnoText();
        return false;
      }
      eof_ = true;
    }
    end_ += n;
  }
}

bool ImuCsvStreamReader::Open(const std::string& path, std::string* error) {
  name_ = path == "-" ? "standard input" : path;
  if (path == "-") {
    file_ = stdin;
  } else {
    file_ = std::fopen(path.c_str(), "rb");
    if (file_ == nullptr) {
      *error = path + ": cannot open: " + ErrnoText();
      return false;
    }
    owns_file_ = true;
  }
  buffer_.resize(kBufferSize);
  const char* begin;
  const char* end;
  for (;;) {
    error->clear();
    if (!ReadLine(&begin, &end, error)) {
      if (error->empty()) *error = name_ + ": no header row (empty log)";
      return false;
    }
    const char* first = begin;
    Trim(&first, &end);
    if (first != end && *first != '#') break;
  }
  columns_.clear();
  for (const char* field = begin;;) {
    const char* comma = static_cast<const char*>(std::memchr(field, ',', end - field));
    const char* field_end = comma != nullptr ? comma : end;
    const char* a = field;
    const char* b = field_end;
    Trim(&a, &b);
    columns_.emplace_back(a, b);
    if (comma == nullptr) break;
    field = comma + 1;
  }
  auto find = [&](const char* name) {
    const auto it = std::find(columns_.begin(), columns_.end(), name);
    return it == columns_.end() ? -1 : static_cast<int>(it - columns_.begin());
  };
  time_column_ = find("t");
  const char* accel_names[3] = {"ax", "ay", "az"};
  const char* gyro_names[3] = {"gx", "gy", "gz"};
  for (int i = 0; i < 3; ++i) {
    accel_column_[i] = find(accel_names[i]);
    gyro_column_[i] = find(gyro_names[i]);
  }
  temperature_column_ = find("temp");
  for (const char* required : {"t", "ax", "ay", "az"}) {
    if (find(required) < 0) {
      return Fail(std::string("the header has no column '") + required +
                      "' (needs t, ax, ay, az; optional gx, gy, gz, temp)",
                  error);
    }
  }
  const int gyro_count = (gyro_column_[0] >= 0) + (gyro_column_[1] >= 0) + (gyro_column_[2] >= 0);
  if (gyro_count != 0 && gyro_count != 3) {
    return Fail("the header names only some of gx, gy, gz", error);
  }
  last_needed_column_ =
      std::max({time_column_, accel_column_[0], accel_column_[1], accel_column_[2], gyro_column_[0],
                gyro_column_[1], gyro_column_[2], temperature_column_});
  return true;
}

bool ImuCsvStreamReader::Next(ImuSample* sample, std::string* error) {
  error->clear();
  const char* begin;
  const char* end;
  for (;;) {
    if (!ReadLine(&begin, &end, error)) return false;
    const char* first = begin;
    const char* last = end;
    Trim(&first, &last);
    if (first != last && *first != '#') break;
  }
  double values[16];
  std::vector<double> wide;
  double* value = values;
  if (last_needed_column_ >= 16) {
    wide.resize(last_needed_column_ + 1);
    value = wide.data();
  }
  int column = 0;
  for (const char* field = begin; column <= last_needed_column_; ++column) {
    const char* comma = static_cast<const char*>(std::memchr(field, ',', end - field));
    const char* field_end = comma != nullptr ? comma : end;
    const bool needed = column == time_column_ || column == temperature_column_ ||
                        std::count(accel_column_, accel_column_ + 3, column) > 0 ||
                        std::count(gyro_column_, gyro_column_ + 3, column) > 0;
    if (needed && !ParseNumber(field, field_end, &value[column])) {
      const char* a = field;
      const char* b = field_end;
      Trim(&a, &b);
      return Fail("column '" + columns_[column] + "': '" + std::string(a, b) + "' is not a number",
                  error);
    }
    if (comma == nullptr) {
      ++column;
      break;
    }
    field = comma + 1;
  }
  if (column <= last_needed_column_) {
    return Fail("the row has " + std::to_string(column) + " fields, the header names " +
                    std::to_string(columns_.size()),
                error);
  }
  sample->t = value[time_column_];
  for (int i = 0; i < 3; ++i) sample->accel(i) = value[accel_column_[i]];
  if (has_gyro()) {
    for (int i = 0; i < 3; ++i) sample->gyro(i) = value[gyro_column_[i]];
  } else {
    sample->gyro.setZero();
  }
  sample->temperature = has_temperature() ? value[temperature_column_] : NAN;
  return true;
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

bool ImuCsvStreamWriter::Flush(std::string* error) {
  if (stdout_ == nullptr) {
    if (!file_.Write(buffer_.data(), buffer_.size(), error)) return false;
  } else if (!buffer_.empty() &&
             std::fwrite(buffer_.data(), 1, buffer_.size(), stdout_) != buffer_.size()) {
    *error = "standard output: cannot write: " + ErrnoText();
    return false;
  }
  buffer_.clear();
  return true;
}

bool ImuCsvStreamWriter::Write(const ImuSample& s, std::string* error) {
  char text[32 * 8];
  char* p = text;
  char* const end = text + sizeof(text);
  auto put = [&](double v, char separator) {
    p = std::to_chars(p, end, v).ptr;
    *p++ = separator;
  };
  put(s.t, ',');
  put(s.accel(0), ',');
  put(s.accel(1), ',');
  put(s.accel(2), gyro_ || temperature_ ? ',' : '\n');
  if (gyro_) {
    put(s.gyro(0), ',');
    put(s.gyro(1), ',');
    put(s.gyro(2), temperature_ ? ',' : '\n');
  }
  if (temperature_) put(s.temperature, '\n');
  buffer_.append(text, p);
  return buffer_.size() < kBufferSize || Flush(error);
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
