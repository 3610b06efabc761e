#include "gravcal/io/log_reader.h"

#include <sys/stat.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "io/csv_table.h"
#include "io/file_text.h"
#include "io/formats/file_format.h"
#include "io/formats/message_log.h"
#include "util/cancellation.h"
#include "util/error.h"
#include "util/numbers.h"

namespace gravcal {
namespace {

using internal::FileText;

// The contract's column names, in the order of the slots a row fills.
enum Slot : int { kT = 0, kAx, kAy, kAz, kGx, kGy, kGz, kTemp, kNumSlots };
constexpr const char* kSlotNames[kNumSlots] = {"t", "ax", "ay", "az", "gx", "gy", "gz", "temp"};

// Longer lines and more columns are not a log: refused before they cost
// memory or time.
constexpr size_t kMaxLineBytes = size_t{1} << 16;
constexpr size_t kMaxColumns = 4096;

// Two times agree when they differ by at most this, relative.
constexpr double kRelativeTimeTolerance = 1e-9;

inline bool IsSpaceOrTab(char c) { return c == ' ' || c == '\t'; }

std::string_view TrimBlanks(std::string_view s) {
  while (!s.empty() && IsSpaceOrTab(s.front())) s.remove_prefix(1);
  while (!s.empty() && IsSpaceOrTab(s.back())) s.remove_suffix(1);
  return s;
}

using internal::ExactNumber;
using internal::SetError;

// Bytes of the file as they appear in a message: at most `max_chars` of
// them, control bytes and bytes that are not UTF-8 written as \xNN, so a
// binary or garbled file never sends raw bytes to the terminal.
std::string Printable(std::string_view text, size_t max_chars) {
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  size_t i = 0;
  for (; i < text.size() && i < max_chars; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    // A valid UTF-8 sequence passes whole.
    size_t length = c >= 0xC2 && c <= 0xDF   ? 2
                    : c >= 0xE0 && c <= 0xEF ? 3
                    : c >= 0xF0 && c <= 0xF4 ? 4
                                             : 1;
    for (size_t k = 1; k < length; ++k) {
      if (i + k >= text.size() || (static_cast<unsigned char>(text[i + k]) & 0xC0) != 0x80)
        length = 1;
    }
    if (length > 1) {
      out.append(text.data() + i, length);
      i += length - 1;
    } else if (c < 0x20 || c >= 0x7f) {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  if (i < text.size()) out += "...";
  return out;
}

// A cell as it appears in a message: quoted, bounded, printable.
std::string Quote(std::string_view cell) { return "'" + Printable(cell, 40) + "'"; }

std::string JoinNames(const std::vector<std::string>& names) {
  constexpr size_t kMaxNames = 32;
  std::string out;
  for (size_t i = 0; i < names.size() && i < kMaxNames; ++i) {
    if (i > 0) out += ", ";
    out += names[i].empty() ? std::string("''") : Printable(names[i], 40);
  }
  if (names.size() > kMaxNames) out += ", ...";
  if (names.empty()) out = "nothing";
  return out;
}

std::string Where(const std::string& name, size_t line) {
  return name + ":" + std::to_string(line) + ": ";
}

// The name the file uses for a contract column.
std::string FileColumnName(const LogReaderOptions& options, int slot) {
  const auto it = options.rename.find(kSlotNames[slot]);
  return it == options.rename.end() ? std::string(kSlotNames[slot]) : it->second;
}

bool IsContractName(const std::string& name) {
  for (const char* contract : kSlotNames) {
    if (name == contract) return true;
  }
  return false;
}

bool CheckColumnNames(const std::vector<std::string>& names, const char* what, std::string* error) {
  std::set<std::string> seen;
  for (const std::string& name : names) {
    if (name.empty()) return SetError(error, std::string(what) + " has an empty name");
    if (!seen.insert(name).second) {
      return SetError(error, std::string(what) + " names '" + name + "' twice");
    }
  }
  return true;
}

// A whole file in memory, read without initialising the buffer first.
// Raw counts are plain integers; reading them digit by digit is several
// times cheaper than from_chars and gives the same double bit for bit (at
// most 15 digits, so exact). Returns false, leaving the field to from_chars,
// when it is not an optional '-' and 1 to 15 digits not followed by '.', 'e',
// 'E' or another digit.
bool ParsePlainInteger(const char* p, const char* end, double* x, const char** after) {
  const bool negative = p < end && *p == '-';
  const char* const digits = p + (negative ? 1 : 0);
  const char* q = digits;
  int64_t value = 0;
  while (q < end && q - digits <= 15 && static_cast<unsigned>(*q - '0') < 10u) {
    value = value * 10 + (*q - '0');
    ++q;
  }
  if (q == digits || q - digits > 15) return false;
  if (q < end && (*q == '.' || *q == 'e' || *q == 'E' || static_cast<unsigned>(*q - '0') < 10u)) {
    return false;
  }
  *x = negative ? -static_cast<double>(value) : static_cast<double>(value);
  *after = q;
  return true;
}

// Rows in `text`, estimated from the line length of its first 64 KiB.
size_t EstimateRows(std::string_view text) {
  constexpr size_t kSample = size_t{1} << 16;
  const size_t sample = std::min(text.size(), kSample);
  const size_t newlines = static_cast<size_t>(std::count(text.data(), text.data() + sample, '\n'));
  if (sample == text.size()) return newlines + 1;
  if (newlines == 0) return 16;
  const double rows = static_cast<double>(text.size()) * static_cast<double>(newlines) /
                      static_cast<double>(sample);
  return static_cast<size_t>(rows * 1.02) + 16;
}

// Parses one file: the main log, or the second file holding the gyroscope.
class Parser {
 public:
  // `reference` is the main log when parsing the gyroscope file, else null.
  // The gyroscope file has the whitespace layout with gyro_columns; rename,
  // skip_lines and time_scale apply to it as to the main file.
  Parser(const std::string& name, const LogReaderOptions& options, const ImuLog* reference,
         const std::string& reference_name)
      : name_(name),
        options_(options),
        reference_(reference),
        reference_name_(reference_name),
        format_(reference != nullptr ? LogFormat::kWhitespace : options.format),
        columns_(reference != nullptr ? options.gyro_columns : options.columns) {}

  // Fills out->t, accel, gyro, temperature (only out->gyro for the gyroscope
  // file). Does not check for an empty result.
  bool Parse(std::string_view text, ImuLog* out, std::string* error) {
    const char* p = text.data();
    const char* const end = p + text.size();
    if (text.size() >= 3 && std::memcmp(p, "\xEF\xBB\xBF", 3) == 0) p += 3;  // UTF-8 BOM.
    const bool csv = format_ == LogFormat::kCsv;
    const size_t skip_lines = static_cast<size_t>(options_.skip_lines);
    bool have_layout = false;
    size_t line = 0;
    size_t index = 0;
    double values[kNumSlots] = {};
    while (p < end) {
      const char* newline = static_cast<const char*>(std::memchr(p, '\n', end - p));
      const char* line_end = newline != nullptr ? newline : end;
      const char* s = p;
      p = newline != nullptr ? newline + 1 : end;
      ++line;
      if ((line & 0xffff) == 0 && internal::CancelRequested()) {
        return SetError(error, Where(name_, line) + "reading was cancelled (time limit)");
      }
      if (line <= skip_lines) continue;
      if (static_cast<size_t>(line_end - s) > kMaxLineBytes) {
        return SetError(error, Where(name_, line) + "the line is " + std::to_string(line_end - s) +
                                   " bytes long; a log line has at "
                                   "most " +
                                   std::to_string(kMaxLineBytes) +
                                   " (is this a text log? are the line ends newlines?)");
      }
      if (line_end > s && line_end[-1] == '\r') --line_end;
      while (s < line_end && IsSpaceOrTab(*s)) ++s;
      if (s == line_end || *s == '#') continue;  // Blank or comment.
      if (!have_layout) {
        if (!BuildLayout(s, line_end, line, error)) return false;
        have_layout = true;
        Reserve(EstimateRows(std::string_view(s, end - s)), out);
        // A CSV file always has a header row; with `columns` given it is
        // skipped and `columns` names the fields instead.
        if (csv) continue;
      }
      const bool ok = csv ? ParseRow<true>(s, line_end, line, values, error)
                          : ParseRow<false>(s, line_end, line, values, error);
      if (!ok || !Store(values, line, index, out, error)) return false;
      ++index;
    }
    lines_ = line;
    rows_ = index;
    return true;
  }

  size_t lines() const { return lines_; }
  size_t rows() const { return rows_; }

 private:
  bool IsGyroFile() const { return reference_ != nullptr; }

  // Works out which field fills which slot, from the header row (CSV) or
  // from `columns`.
  bool BuildLayout(const char* begin, const char* end, size_t line, std::string* error) {
    std::vector<std::string> names = columns_;
    const char* source = "the columns are";
    if (names.empty()) {  // CSV header row.
      source = "the header has";
      std::vector<CsvCell> cells;
      size_t column = 0;
      std::string what;
      if (!internal::SplitCsvLine(std::string_view(begin, end - begin), &cells, &column, &what)) {
        return SetError(error, Where(name_, line) + what);
      }
      for (CsvCell& cell : cells) names.push_back(std::move(cell.text));
    }
    if (names.size() > kMaxColumns) {
      return SetError(error, Where(name_, line) +
                                 (columns_.empty() ? "the header has " : "columns lists ") +
                                 std::to_string(names.size()) + " columns; a log has at most " +
                                 std::to_string(kMaxColumns));
    }
    const std::string listing = std::string(source) + ": " + JoinNames(names);
    const std::string where = Where(name_, line);

    slot_of_field_.assign(names.size(), -1);
    field_label_.assign(names.size(), std::string());
    for (size_t i = 0; i < names.size(); ++i) field_label_[i] = Quote(names[i]);
    for (int slot = 0; slot < kNumSlots; ++slot) {
      has_[slot] = false;
      if (IsGyroFile() && slot != kT && slot != kGx && slot != kGy && slot != kGz) continue;
      const std::string wanted = FileColumnName(options_, slot);
      for (size_t i = 0; i < names.size(); ++i) {
        if (names[i] != wanted) continue;
        if (has_[slot]) {
          return SetError(error, where + "column '" + wanted + "' appears twice; " + listing);
        }
        has_[slot] = true;
        slot_of_field_[i] = slot;
        if (wanted != kSlotNames[slot])
          field_label_[i] += std::string(" (") + kSlotNames[slot] + ")";
      }
    }
    auto missing = [&](int slot) {
      const std::string wanted = FileColumnName(options_, slot);
      std::string what = "no column '" + wanted + "'";
      if (wanted != kSlotNames[slot]) what += std::string(" (for '") + kSlotNames[slot] + "')";
      return what;
    };

    const int required[] = {kAx, kAy, kAz};
    if (!IsGyroFile()) {
      for (int slot : required) {
        if (!has_[slot]) return SetError(error, where + missing(slot) + "; " + listing);
      }
      if (!has_[kT] && options_.sample_rate <= 0.0) {
        return SetError(
            error, where + missing(kT) + " (give sample_rate for a log without time); " + listing);
      }
    }
    const bool any_gyro = has_[kGx] || has_[kGy] || has_[kGz];
    if (!IsGyroFile() && any_gyro && !options_.gyro_path.empty()) {
      return SetError(error, where + "has gyroscope columns and gyro_path '" + options_.gyro_path +
                                 "' is given too");
    }
    if (any_gyro || IsGyroFile()) {
      for (int slot : {kGx, kGy, kGz}) {
        if (!has_[slot]) {
          return SetError(
              error, where + missing(slot) + " (the gyroscope needs gx, gy and gz); " + listing);
        }
      }
    }
    return true;
  }

  void Reserve(size_t rows, ImuLog* out) const {
    if (IsGyroFile()) {
      out->gyro.reserve(reference_->t.size());
      return;
    }
    out->t.reserve(rows);
    out->accel.reserve(rows);
    if (has_[kGx]) out->gyro.reserve(rows);
    if (has_[kTemp]) out->temperature.reserve(rows);
  }

  // Splits one non-blank line into fields and parses the ones in use.
  template <bool kCsv>
  bool ParseRow(const char* begin, const char* end, size_t line, double* values,
                std::string* error) const {
    const size_t expected = slot_of_field_.size();
    const char* p = begin;
    size_t field = 0;
    for (;;) {
      if (field == expected) return FieldCountError<kCsv>(begin, end, line, error);
      const int slot = slot_of_field_[field];
      if (slot >= 0) {
        const char* number = p;
        if (kCsv) {
          while (number < end && IsSpaceOrTab(*number)) ++number;
        }
        // from_chars takes no leading '+'.
        if (number + 1 < end && number[0] == '+' && number[1] != '-' && number[1] != '+') {
          ++number;
        }
        double x = 0.0;
        const char* after = nullptr;
        std::from_chars_result result{number, std::errc()};
        if (!ParsePlainInteger(number, end, &x, &after)) {
          result = std::from_chars(number, end, x);
          after = result.ptr;
        }
        bool ok = result.ec == std::errc();
        if (kCsv) {
          while (after < end && IsSpaceOrTab(*after)) ++after;
          ok = ok && (after == end || *after == ',');
        } else {
          ok = ok && (after == end || IsSpaceOrTab(*after));
        }
        if (!ok || !std::isfinite(x)) {
          return CellError<kCsv>(p, end, line, field, ok, result.ec, error);
        }
        values[slot] = x;
        p = after;
      } else if (kCsv) {
        const char* comma = static_cast<const char*>(std::memchr(p, ',', end - p));
        p = comma != nullptr ? comma : end;
      } else {
        while (p < end && !IsSpaceOrTab(*p)) ++p;
      }
      ++field;
      if (kCsv) {
        if (p == end) break;
        ++p;  // The comma.
      } else {
        while (p < end && IsSpaceOrTab(*p)) ++p;
        if (p == end) break;
      }
    }
    if (field != expected) return FieldCountError<kCsv>(begin, end, line, error);
    return true;
  }

  template <bool kCsv>
  bool FieldCountError(const char* begin, const char* end, size_t line, std::string* error) const {
    size_t fields = 0;
    if (kCsv) {
      fields = 1 + static_cast<size_t>(std::count(begin, end, ','));
    } else {
      for (const char* p = begin; p < end;) {
        while (p < end && IsSpaceOrTab(*p)) ++p;
        if (p == end) break;
        ++fields;
        while (p < end && !IsSpaceOrTab(*p)) ++p;
      }
    }
    return SetError(error, Where(name_, line) + std::to_string(fields) + " fields, expected " +
                               std::to_string(slot_of_field_.size()));
  }

  template <bool kCsv>
  bool CellError(const char* cell_begin, const char* end, size_t line, size_t field, bool parsed,
                 std::errc ec, std::string* error) const {
    const char* cell_end = cell_begin;
    if (kCsv) {
      while (cell_end < end && *cell_end != ',') ++cell_end;
    } else {
      while (cell_end < end && !IsSpaceOrTab(*cell_end)) ++cell_end;
    }
    const std::string_view cell = TrimBlanks(std::string_view(cell_begin, cell_end - cell_begin));
    std::string what = Where(name_, line) + "column " + field_label_[field];
    if (cell.empty()) {
      what += " is empty";
    } else if (parsed) {
      what += ": " + Quote(cell) + " is not finite";
    } else if (ec == std::errc::result_out_of_range) {
      what += ": " + Quote(cell) + " is out of range";
    } else {
      what += ": " + Quote(cell) + " is not a number";
    }
    return SetError(error, what);
  }

  // Appends one parsed row.
  bool Store(const double* values, size_t line, size_t index, ImuLog* out, std::string* error) {
    if (IsGyroFile()) {
      const std::vector<double>& reference_t = reference_->t;
      if (index >= reference_t.size()) {
        return SetError(error, Where(name_, line) + "more samples than " + reference_name_ + " (" +
                                   std::to_string(reference_t.size()) + ")");
      }
      if (has_[kT]) {
        const double t = values[kT] * options_.time_scale;
        const double r = reference_t[index];
        if (!(std::fabs(t - r) <= kRelativeTimeTolerance * std::max(std::fabs(t), std::fabs(r)))) {
          return SetError(error, Where(name_, line) + "time " + ExactNumber(t) +
                                     " differs from time " + ExactNumber(r) + " of sample " +
                                     std::to_string(index) + " in " + reference_name_);
        }
      }
      out->gyro.emplace_back(values[kGx], values[kGy], values[kGz]);
      return true;
    }
    double t;
    if (has_[kT]) {
      t = values[kT] * options_.time_scale;
      if (!std::isfinite(t)) {
        return SetError(error, Where(name_, line) + "time " + ExactNumber(values[kT]) +
                                   " times time_scale is not finite");
      }
    } else {
      t = static_cast<double>(index) / options_.sample_rate;
    }
    if (index > 0 && !(t > previous_t_)) {
      return SetError(error, Where(name_, line) + "time " + ExactNumber(t) +
                                 " does not increase (previous " + ExactNumber(previous_t_) + ")");
    }
    previous_t_ = t;
    out->t.push_back(t);
    out->accel.emplace_back(values[kAx], values[kAy], values[kAz]);
    if (has_[kGx]) out->gyro.emplace_back(values[kGx], values[kGy], values[kGz]);
    if (has_[kTemp]) out->temperature.push_back(values[kTemp]);
    return true;
  }

  const std::string& name_;
  const LogReaderOptions& options_;
  const ImuLog* const reference_;
  const std::string& reference_name_;
  const LogFormat format_;
  const std::vector<std::string>& columns_;

  std::vector<int> slot_of_field_;
  // Per field, the name used in messages: "'acc_y' (ay)".
  std::vector<std::string> field_label_;
  bool has_[kNumSlots] = {};
  double previous_t_ = 0.0;
  size_t lines_ = 0;
  size_t rows_ = 0;
};

bool ParseImpl(std::string_view text, const std::string& name, const LogReaderOptions& options,
               ImuLog* log, std::string* error) {
  std::string why;
  if (!options.IsValid(&why)) return SetError(error, name + ": invalid options: " + why);
  internal::FileFormat format = internal::FileFormat::kText;
  if (!internal::DetectFileFormat(text.substr(0, 4096), &format, &why)) {
    return SetError(error, name + ": " + why);
  }
  if (internal::NewMessageRecording(format) != nullptr) {
    return SetError(error, name + ": a " + internal::FileFormatName(format) +
                               " is read from its file, not from memory");
  }
  // An EuRoC / TUM-VI header is the header row once its '#' is dropped.
  const bool euroc = format == internal::FileFormat::kEuroc && internal::LayoutFromFile(options);
  const LogReaderOptions& layout = euroc ? internal::EurocOptions(options) : options;
  if (euroc) text.remove_prefix(1);
  ImuLog parsed;
  Parser parser(name, layout, nullptr, name);
  if (!parser.Parse(text, &parsed, error)) return false;
  if (parsed.t.empty()) return SetError(error, name + ": no samples");

  if (!options.gyro_path.empty()) {
    FileText gyro_text;
    if (!gyro_text.Read(options.gyro_path, error)) return false;
    Parser gyro_parser(options.gyro_path, options, &parsed, name);
    ImuLog gyro;
    if (!gyro_parser.Parse(gyro_text.view(), &gyro, error)) return false;
    if (gyro.gyro.size() != parsed.t.size()) {
      return SetError(error, Where(options.gyro_path, std::max<size_t>(gyro_parser.lines(), 1)) +
                                 "ends after " + std::to_string(gyro.gyro.size()) + " samples; " +
                                 name + " has " + std::to_string(parsed.t.size()));
    }
    parsed.gyro = std::move(gyro.gyro);
  }
  parsed.source = name;
  *log = std::move(parsed);
  return true;
}

// Checks what the writer needs without ImuLog::Validate's per-sample cost.
bool CheckWritable(const ImuLog& log, std::string* why) {
  const size_t n = log.t.size();
  if (n == 0) return SetError(why, "no samples");
  if (log.accel.size() != n) return SetError(why, "accelerometer and time have different lengths");
  if (!log.gyro.empty() && log.gyro.size() != n) {
    return SetError(why, "gyroscope and time have different lengths");
  }
  if (!log.temperature.empty() && log.temperature.size() != n) {
    return SetError(why, "temperature and time have different lengths");
  }
  for (size_t i = 0; i < n; ++i) {
    const bool finite = std::isfinite(log.t[i]) && log.accel[i].allFinite() &&
                        (log.gyro.empty() || log.gyro[i].allFinite()) &&
                        (log.temperature.empty() || std::isfinite(log.temperature[i]));
    if (!finite) return SetError(why, "sample " + std::to_string(i) + ": a value is not finite");
    if (i > 0 && !(log.t[i] > log.t[i - 1])) {
      return SetError(why, "sample " + std::to_string(i) + ": time does not increase");
    }
  }
  return true;
}

}  // namespace

bool LogReaderOptions::IsValid(std::string* error) const {
  if (format != LogFormat::kCsv && format != LogFormat::kWhitespace) {
    return SetError(error, "format is not csv or whitespace");
  }
  if (skip_lines < 0) {
    return SetError(error, "skip_lines is " + std::to_string(skip_lines) + ", must be >= 0");
  }
  if (!std::isfinite(sample_rate) || sample_rate < 0.0) {
    return SetError(error,
                    "sample_rate is " + ExactNumber(sample_rate) + ", must be finite and >= 0");
  }
  if (!std::isfinite(time_scale) || time_scale <= 0.0) {
    return SetError(error, "time_scale is " + ExactNumber(time_scale) + ", must be finite and > 0");
  }
  if (format == LogFormat::kWhitespace && columns.empty()) {
    return SetError(error, "the whitespace format needs columns");
  }
  if (!CheckColumnNames(columns, "columns", error)) return false;
  if (!gyro_path.empty()) {
    if (gyro_columns.empty())
      return SetError(error, "gyro_path is given but gyro_columns is empty");
    if (!CheckColumnNames(gyro_columns, "gyro_columns", error)) return false;
  }
  for (const auto& [contract, file_name] : rename) {
    if (!IsContractName(contract)) {
      return SetError(error, "rename: '" + contract +
                                 "' is not a column of the contract (t, ax, ay, az, gx, gy, gz, "
                                 "temp)");
    }
    if (file_name.empty()) return SetError(error, "rename: '" + contract + "' maps to ''");
  }
  // Two contract columns must not read the same column of the file.
  for (int a = 0; a < kNumSlots; ++a) {
    for (int b = a + 1; b < kNumSlots; ++b) {
      const std::string name = FileColumnName(*this, a);
      if (name == FileColumnName(*this, b)) {
        return SetError(error, std::string("rename: '") + kSlotNames[a] + "' and '" +
                                   kSlotNames[b] + "' would both read column '" + name + "'");
      }
    }
  }
  return true;
}

bool ReadImuLog(const std::string& path, const LogReaderOptions& options, ImuLog* log,
                std::string* error) {
  if (log == nullptr) return SetError(error, path + ": no log to read into");
  try {
    internal::FileFormat format = internal::FileFormat::kText;
    if (!internal::DetectFileFormatOf(path, &format, error)) return false;
    if (std::unique_ptr<internal::MessageRecording> recording =
            internal::NewMessageRecording(format)) {
      std::string why;
      if (!options.IsValid(&why)) return SetError(error, path + ": invalid options: " + why);
      return recording->Open(path, error) &&
             internal::ReadMessageLog(recording.get(), path, options, log, error);
    }
    struct stat st;
    if (stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
        !internal::CheckLogFitsInMemory(path, static_cast<uint64_t>(st.st_size),
                                        internal::AvailableMemoryBytes(), error)) {
      return false;
    }
    FileText text;
    if (!text.Read(path, error)) return false;
    return ParseImpl(text.view(), path, options, log, error);
  } catch (const std::exception& e) {
    return SetError(error, path + ": " + e.what());
  }
}

// With options.gyro_path set, the gyroscope file is read from disk.
bool ParseImuLog(std::string_view text, const std::string& name, const LogReaderOptions& options,
                 ImuLog* log, std::string* error) {
  if (log == nullptr) return SetError(error, name + ": no log to read into");
  try {
    return ParseImpl(text, name, options, log, error);
  } catch (const std::exception& e) {
    return SetError(error, name + ": " + e.what());
  }
}

bool WriteImuLogCsv(const ImuLog& log, const std::string& path, std::string* error) {
  try {
    std::string why;
    if (!CheckWritable(log, &why)) return SetError(error, path + ": cannot write log: " + why);
    const bool gyro = log.has_gyro();
    const bool temperature = log.has_temperature();
    std::string header = "t,ax,ay,az";
    if (gyro) header += ",gx,gy,gz";
    if (temperature) header += ",temp";
    header += '\n';
    const size_t columns = 4 + (gyro ? 3 : 0) + (temperature ? 1 : 0);
    // The shortest round-trip form of a double has at most 24 characters;
    // one more for the separator.
    constexpr size_t kMaxField = 25;
    std::string contents;
    contents.resize(header.size() + log.size() * columns * kMaxField);
    char* p = contents.data();
    std::memcpy(p, header.data(), header.size());
    p += header.size();
    char* const end = contents.data() + contents.size();
    auto put = [&](double x, char separator) {
      p = std::to_chars(p, end, x).ptr;
      *p++ = separator;
    };
    for (size_t i = 0; i < log.size(); ++i) {
      put(log.t[i], ',');
      put(log.accel[i].x(), ',');
      put(log.accel[i].y(), ',');
      put(log.accel[i].z(), gyro || temperature ? ',' : '\n');
      if (gyro) {
        put(log.gyro[i].x(), ',');
        put(log.gyro[i].y(), ',');
        put(log.gyro[i].z(), temperature ? ',' : '\n');
      }
      if (temperature) put(log.temperature[i], '\n');
    }
    contents.resize(static_cast<size_t>(p - contents.data()));
    return WriteFileAtomically(path, contents, error);
  } catch (const std::exception& e) {
    return SetError(error, path + ": cannot write: " + e.what());
  }
}

}  // namespace gravcal
