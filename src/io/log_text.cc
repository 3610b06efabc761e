#include "io/log_text.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <system_error>
#include <utility>

#include "io/csv_table.h"
#include "util/cancellation.h"
#include "util/error.h"
#include "util/numbers.h"

namespace gravcal {
namespace internal {

const char* const kLogSlotNames[kNumSlots] = {"t", "ax", "ay", "az", "gx", "gy", "gz", "temp"};

namespace {

// A file is read in pieces of this size (at least kMaxLogLineBytes + 2).
constexpr size_t kChunkBytes = size_t{1} << 20;
static_assert(kChunkBytes > kMaxLogLineBytes + 2, "a chunk holds a whole line");

inline bool IsSpaceOrTab(char c) { return c == ' ' || c == '\t'; }

std::string_view TrimBlanks(std::string_view s) {
  while (!s.empty() && IsSpaceOrTab(s.front())) s.remove_prefix(1);
  while (!s.empty() && IsSpaceOrTab(s.back())) s.remove_suffix(1);
  return s;
}

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

}  // namespace

std::string LogWhere(const std::string& name, size_t line) {
  return name + ":" + std::to_string(line) + ": ";
}

std::string LongLineMessage(const std::string& name, size_t line, uint64_t bytes) {
  return LogWhere(name, line) + "the line is " + std::to_string(bytes) +
         " bytes long; a log line has at most " + std::to_string(kMaxLogLineBytes) +
         " (is this a text log? are the line ends newlines?)";
}

std::string LogFileColumnName(const LogReaderOptions& options, int slot) {
  const auto it = options.rename.find(kLogSlotNames[slot]);
  return it == options.rename.end() ? std::string(kLogSlotNames[slot]) : it->second;
}

// --- LogLines ----------------------------------------------------------------

LogLines::LogLines(std::string_view text, std::string name)
    : name_(std::move(name)), data_(text.data()), end_(text.size()), eof_(true) {}

LogLines::LogLines(std::FILE* file, std::string name)
    : name_(std::move(name)), file_(file), buffer_(kChunkBytes), eof_(false) {
  data_ = buffer_.data();
}

bool LogLines::Fill(std::string* error) {
  if (begin_ > 0) {
    std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  const size_t n = std::fread(buffer_.data() + end_, 1, buffer_.size() - end_, file_);
  if (n == 0) {
    if (std::ferror(file_)) {
      return SetError(error, name_ + ": cannot read: " + std::generic_category().message(errno));
    }
    eof_ = true;
  }
  if (hash_ != nullptr) hash_->Append(std::string_view(buffer_.data() + end_, n));
  bytes_read_ += n;
  end_ += n;
  return true;
}

std::string_view LogLines::TakeBuffered() {
  const std::string_view rest(data_ + begin_, end_ - begin_);
  begin_ = end_;
  return rest;
}

size_t LogLines::ReadRaw(char* out, size_t size, std::string* error) {
  if (file_ == nullptr || eof_) return 0;
  const size_t n = std::fread(out, 1, size, file_);
  if (n == 0) {
    if (std::ferror(file_)) {
      SetError(error, name_ + ": cannot read: " + std::generic_category().message(errno));
      return 0;
    }
    eof_ = true;
  }
  if (hash_ != nullptr) hash_->Append(std::string_view(out, n));
  bytes_read_ += n;
  return n;
}

std::string_view LogLines::Head(size_t bytes, std::string* error) {
  while (file_ != nullptr && end_ - begin_ < bytes && !eof_) {
    if (!Fill(error)) return {};
  }
  return std::string_view(data_ + begin_, std::min(bytes, end_ - begin_));
}

bool LogLines::FindLineEnd(size_t from, size_t* at, size_t* length) {
  if (from >= end_) return false;  // (memchr on an empty text's null data)
  const char* const p = data_ + from;
  const size_t n = end_ - from;
  if (ends_ == Ends::kNewline) {
    const char* q = static_cast<const char*>(std::memchr(p, '\n', n));
    if (q == nullptr) return false;
    *at = static_cast<size_t>(q - data_);
    *length = 1;
    return true;
  }
  // A lone '\r' (kReturn), or the first line end of the file, which decides.
  const char* newline =
      ends_ == Ends::kReturn ? nullptr : static_cast<const char*>(std::memchr(p, '\n', n));
  const size_t span = newline != nullptr ? static_cast<size_t>(newline - p) : n;
  const char* ret = static_cast<const char*>(std::memchr(p, '\r', span));
  if (ret == nullptr) {
    if (newline == nullptr) return false;
    ends_ = Ends::kNewline;
    *at = static_cast<size_t>(newline - data_);
    *length = 1;
    return true;
  }
  const size_t r = static_cast<size_t>(ret - data_);
  if (r + 1 == end_ && !eof_) return false;  // "\r\n" or a lone '\r': more bytes tell.
  const bool crlf = r + 1 < end_ && data_[r + 1] == '\n';
  if (ends_ == Ends::kUnknown) ends_ = crlf ? Ends::kNewline : Ends::kReturn;
  if (ends_ == Ends::kNewline) {
    // A '\r' inside a line of a newline file stays in the line (a cell with
    // it is refused by the row rules, escaped in the message).
    if (!crlf) return FindLineEnd(r + 1, at, length);
    *at = r + 1;
    *length = 1;
    return true;
  }
  *at = r;
  *length = crlf ? 2 : 1;
  return true;
}

bool LogLines::Next(std::string_view* line, std::string* error) {
  for (;;) {
    size_t at = 0, length = 0;
    const bool found = FindLineEnd(begin_, &at, &length);
    if (found || eof_ || end_ - begin_ > kMaxLogLineBytes + 1) {
      if (!found && begin_ == end_) return false;  // The end of the text.
      ++number_;
      size_t stop = found ? at : end_;
      size_t bytes = stop - begin_;
      if (bytes > kMaxLogLineBytes) {
        // Counted to its end without keeping it: a file without line ends
        // costs one buffer, however long it is.
        while (!found && file_ != nullptr && !eof_) {
          begin_ = end_;
          if (!Fill(error)) return false;
          size_t more_at = 0, more_length = 0;
          if (FindLineEnd(begin_, &more_at, &more_length)) {
            bytes += more_at - begin_;
            break;
          }
          bytes += end_ - begin_;
        }
        return SetError(error, LongLineMessage(name_, number_, bytes));
      }
      if (found && ends_ == Ends::kNewline && stop > begin_ && data_[stop - 1] == '\r') --stop;
      *line = std::string_view(data_ + begin_, stop - begin_);
      begin_ = found ? at + length : end_;
      if (number_ == 1 && line->size() >= 3 && std::memcmp(line->data(), "\xEF\xBB\xBF", 3) == 0) {
        line->remove_prefix(3);  // A UTF-8 byte order mark.
      }
      return true;
    }
    if (!Fill(error)) return false;
  }
}

// --- LogRowParser ------------------------------------------------------------

namespace {

// Whether `text`, without surrounding blanks, is one number as the reader
// parses a cell (internal::ParseNumber).
bool IsNumberText(std::string_view text) {
  const size_t first = text.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return false;
  const size_t last = text.find_last_not_of(" \t\r");
  double x;
  const char* end = text.data() + last + 1;
  const std::from_chars_result r = internal::ParseNumber(text.data() + first, end, &x);
  return r.ec == std::errc() && r.ptr == end;
}

// Whether every comma-separated cell of [begin, end) is a number: a first
// line that a CSV file with `columns` given holds as data, not as a header.
bool CellsAreNumbers(const char* begin, const char* end) {
  while (begin <= end) {
    const char* comma = std::find(begin, end, ',');
    if (!IsNumberText(std::string_view(begin, static_cast<size_t>(comma - begin)))) return false;
    begin = comma + 1;
  }
  return true;
}

}  // namespace

LogRowParser::LogRowParser(std::string name, const LogReaderOptions& options, bool gyro_file)
    : name_(std::move(name)),
      options_(options),
      gyro_file_(gyro_file),
      format_(gyro_file ? LogFormat::kWhitespace : options.format),
      columns_(gyro_file ? options.gyro_columns : options.columns) {}

bool LogRowParser::Line(std::string_view text, size_t line, bool* row, std::string* error) {
  *row = false;
  if ((line & 0xffff) == 0 && CancelRequested()) {
    return SetError(error, LogWhere(name_, line) + "reading was cancelled (time limit)");
  }
  if (line <= static_cast<size_t>(options_.skip_lines)) return true;
  const char* s = text.data();
  const char* const end = s + text.size();
  while (s < end && IsSpaceOrTab(*s)) ++s;
  if (s == end || *s == '#') return true;  // Blank or comment.
  const bool csv = format_ == LogFormat::kCsv;
  if (!have_layout_) {
    if (!BuildLayout(s, end, line, error)) return false;
    have_layout_ = true;
    // A CSV file has a header row; with `columns` given it is skipped and
    // `columns` names the fields instead, unless that first line is numbers:
    // then the file has no header row and the line is the first sample.
    if (csv && (columns_.empty() || !CellsAreNumbers(s, end))) return true;
  }
  const bool ok = ParseFields(s, end, line, error);
  if (!ok || !CheckTime(line, error)) return false;
  ++rows_;
  *row = true;
  return true;
}

bool LogRowParser::CheckTime(size_t line, std::string* error) {
  if (gyro_file_) {
    values_[kT] *= options_.time_scale;  // Matched to the main file's by the caller.
    return true;
  }
  double t;
  if (has_[kT]) {
    t = values_[kT] * options_.time_scale;
    if (!std::isfinite(t)) {
      return SetError(error, LogWhere(name_, line) + "time " + ExactNumber(values_[kT]) +
                                 " times time_scale is not finite");
    }
  } else {
    t = static_cast<double>(rows_) / options_.sample_rate;
  }
  if (rows_ > 0 && !(t > previous_t_)) {
    return SetError(error, LogWhere(name_, line) + "time " + ExactNumber(t) +
                               " does not increase (previous " + ExactNumber(previous_t_) + ")");
  }
  previous_t_ = t;
  values_[kT] = t;
  return true;
}

// Works out which field fills which slot, from the header row (CSV) or
// from `columns`.
bool LogRowParser::BuildLayout(const char* begin, const char* end, size_t line,
                               std::string* error) {
  std::vector<std::string> names = columns_;
  const char* source = "the columns are";
  if (names.empty()) {  // CSV header row.
    source = "the header has";
    std::vector<CsvCell> cells;
    size_t column = 0;
    std::string what;
    if (!internal::SplitCsvLine(std::string_view(begin, end - begin), &cells, &column, &what)) {
      return SetError(error, LogWhere(name_, line) + what);
    }
    for (CsvCell& cell : cells) names.push_back(std::move(cell.text));
  }
  if (names.size() > kMaxLogColumns) {
    return SetError(error, LogWhere(name_, line) +
                               (columns_.empty() ? "the header has " : "columns lists ") +
                               std::to_string(names.size()) + " columns; a log has at most " +
                               std::to_string(kMaxLogColumns));
  }
  std::string listing = std::string(source) + ": " + JoinNames(names);
  // A first line of numbers is a log without a header row: say so, with
  // the way to name its columns (and its separator, when the numbers are
  // apart by spaces in a comma-separated read).
  if (columns_.empty()) {
    size_t numbers = 0;
    bool spaced = false, only_numbers = !names.empty();
    for (const std::string& name : names) {
      size_t from = name.find_first_not_of(" \t");
      if (from == std::string::npos) only_numbers = false;
      while (only_numbers && from != std::string::npos) {
        const size_t to = std::min(name.find_first_of(" \t", from), name.size());
        only_numbers = IsNumberText(std::string_view(name).substr(from, to - from));
        ++numbers;
        from = name.find_first_not_of(" \t", to);
        spaced = spaced || from != std::string::npos;
      }
    }
    if (only_numbers) {
      listing += " (numbers, not names: the log has no header row; name its " +
                 std::to_string(numbers) + " columns with the columns key, e.g. --columns " +
                 "t,ax,ay,az,..." + (spaced ? ", and give --format whitespace" : "") + ")";
    }
  }
  const std::string where = LogWhere(name_, line);

  slot_of_field_.assign(names.size(), -1);
  field_label_.assign(names.size(), std::string());
  for (size_t i = 0; i < names.size(); ++i) field_label_[i] = Quote(names[i]);
  for (int slot = 0; slot < kNumSlots; ++slot) {
    has_[slot] = false;
    if (gyro_file_ && slot != kT && slot != kGx && slot != kGy && slot != kGz) continue;
    const std::string wanted = LogFileColumnName(options_, slot);
    for (size_t i = 0; i < names.size(); ++i) {
      if (names[i] != wanted) continue;
      if (has_[slot]) {
        return SetError(error, where + "column '" + wanted + "' appears twice; " + listing);
      }
      has_[slot] = true;
      slot_of_field_[i] = slot;
      if (wanted != kLogSlotNames[slot])
        field_label_[i] += std::string(" (") + kLogSlotNames[slot] + ")";
    }
  }
  auto missing = [&](int slot) {
    const std::string wanted = LogFileColumnName(options_, slot);
    std::string what = "no column '" + wanted + "'";
    if (wanted != kLogSlotNames[slot]) what += std::string(" (for '") + kLogSlotNames[slot] + "')";
    return what;
  };

  const int required[] = {kAx, kAy, kAz};
  if (!gyro_file_) {
    for (int slot : required) {
      if (!has_[slot]) return SetError(error, where + missing(slot) + "; " + listing);
    }
    if (!has_[kT] && options_.sample_rate <= 0.0) {
      return SetError(
          error, where + missing(kT) + " (give sample_rate for a log without time); " + listing);
    }
  }
  const bool any_gyro = has_[kGx] || has_[kGy] || has_[kGz];
  if (!gyro_file_ && any_gyro && !options_.gyro_path.empty()) {
    return SetError(error, where + "has gyroscope columns and gyro_path '" + options_.gyro_path +
                               "' is given too");
  }
  if (any_gyro || gyro_file_) {
    for (int slot : {kGx, kGy, kGz}) {
      if (!has_[slot]) {
        return SetError(error,
                        where + missing(slot) + " (the gyroscope needs gx, gy and gz); " + listing);
      }
    }
  }
  return true;
}

// Splits one non-blank line into fields and parses the ones in use.
template <bool kCsv>
bool LogRowParser::ParseRow(const char* begin, const char* end, size_t line, std::string* error) {
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
      // ParseNumber takes no leading '+'.
      if (number + 1 < end && number[0] == '+' && number[1] != '-' && number[1] != '+') {
        ++number;
      }
      double x = 0.0;
      const std::from_chars_result result = ParseNumber(number, end, &x);
      const char* after = result.ptr;
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
      values_[slot] = x;
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
bool LogRowParser::FieldCountError(const char* begin, const char* end, size_t line,
                                   std::string* error) const {
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
  return SetError(error, LogWhere(name_, line) + std::to_string(fields) + " fields, expected " +
                             std::to_string(slot_of_field_.size()));
}

template <bool kCsv>
bool LogRowParser::CellError(const char* cell_begin, const char* end, size_t line, size_t field,
                             bool parsed, std::errc ec, std::string* error) const {
  const char* cell_end = cell_begin;
  if (kCsv) {
    while (cell_end < end && *cell_end != ',') ++cell_end;
  } else {
    while (cell_end < end && !IsSpaceOrTab(*cell_end)) ++cell_end;
  }
  const std::string_view cell = TrimBlanks(std::string_view(cell_begin, cell_end - cell_begin));
  std::string what = LogWhere(name_, line) + "column " + field_label_[field];
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

}  // namespace internal
}  // namespace gravcal
