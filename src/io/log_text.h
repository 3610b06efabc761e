// io/log_text.h (private): the one checked reader of text logs. Every text
// log, read whole (log_reader.h) or streamed (imu_stream.h), is cut into
// lines by LogLines and each line goes through LogRowParser, so that both
// hold every file to the same rules (docs/data_contract.md, "Raw log"):
// - a UTF-8 byte order mark before the first line is dropped;
// - a line ends at "\n", "\r\n" or a lone "\r" (the first line end of the
//   file decides which: a CR-only file from an old tool reads as lines);
// - a line is at most kMaxLogLineBytes long, checked before it is kept, so a
//   file without line ends costs at most one buffer of memory;
// - skip_lines, comments ('#') and blank lines, the header row (CSV) or
//   `columns`, renamed columns, a column named twice, at most kMaxLogColumns;
// - every field in use is a finite number ('+-1' and '0x10' are not);
// - time is finite after time_scale and strictly increasing.
// Messages name the file and line: "log.csv:17: column 'ay': 'abc' is not a
// number".
#ifndef GRAVCAL_SRC_IO_LOG_TEXT_H_
#define GRAVCAL_SRC_IO_LOG_TEXT_H_

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "gravcal/io/log_reader.h"
#include "util/content_hash.h"

namespace gravcal {
namespace internal {

// The contract's column names, in the order of the slots a row fills.
enum LogSlot : int { kT = 0, kAx, kAy, kAz, kGx, kGy, kGz, kTemp, kNumSlots };
extern const char* const kLogSlotNames[kNumSlots];

// Longer lines and more columns are not a log: refused before they cost
// memory or time.
constexpr size_t kMaxLogLineBytes = size_t{1} << 16;
constexpr size_t kMaxLogColumns = 4096;

// "name:line: ".
std::string LogWhere(const std::string& name, size_t line);

// "name:line: the line is 200000 bytes long; ..." (bytes up to its line end).
std::string LongLineMessage(const std::string& name, size_t line, uint64_t bytes);

// The name the file uses for a contract column (options.rename applied).
std::string LogFileColumnName(const LogReaderOptions& options, int slot);

// The lines of a text log, from text in memory or from a file read through
// a buffer of fixed size.
class LogLines {
 public:
  // Text in memory (the view must outlive this).
  LogLines(std::string_view text, std::string name);
  // A file (not closed here); `name` is used in messages.
  LogLines(std::FILE* file, std::string name);

  // The next line without its line end. False at the end of the text (error
  // left empty) or on an error (set): a line longer than kMaxLogLineBytes
  // ("log.csv:2: the line is 200000 bytes long; ...", counted to its end
  // without keeping it) or a read error.
  bool Next(std::string_view* line, std::string* error);
  // The number of the line Next returned last (from 1).
  size_t number() const { return number_; }
  // In memory: the text after that line (for estimates).
  std::string_view rest() const { return std::string_view(data_ + begin_, end_ - begin_); }
  // The first bytes of the file (up to `bytes`, fewer at its end), read
  // without consuming them; for a file they are read into the buffer.
  std::string_view Head(size_t bytes, std::string* error);
  // A file: every byte read from now on is appended to *hash (Begin'd by
  // the caller; call before the first read).
  void HashInto(ContentHash* hash) { hash_ = hash; }
  // A file: the bytes read from it so far.
  uint64_t bytes_read() const { return bytes_read_; }

  // For a reader that takes over the rest of a file (io/log_blocks.h):
  // whether the lines end at "\n" (or "\r\n"), decided by the first line end;
  // the bytes read but not yet returned as lines (taken: Next no longer sees
  // them); the next bytes of the file into `out` (hashed and counted as Next
  // would; 0 at the end, or on a read error with *error set); and the line
  // number to continue from.
  bool newline_ends() const { return ends_ == Ends::kNewline; }
  bool is_file() const { return file_ != nullptr; }
  std::string_view TakeBuffered();
  size_t ReadRaw(char* out, size_t size, std::string* error);
  void set_number(size_t number) { number_ = number; }
  // The first `bytes` of rest(), `lines` whole lines, were read elsewhere.
  void Skip(size_t bytes, size_t lines) {
    begin_ += bytes;
    number_ += lines;
  }
  // Text in memory that continues a newline-ended text after its line
  // `number` (the next line is number + 1).
  void ContinueNewlineText(size_t number) {
    number_ = number;
    ends_ = Ends::kNewline;
  }

 private:
  // Reads more of the file into the buffer; false on a read error.
  bool Fill(std::string* error);
  // The first line end in [from, end_): its position and length (1 or 2),
  // or false when more bytes are needed to know.
  bool FindLineEnd(size_t from, size_t* at, size_t* length);

  std::string name_;
  std::FILE* file_ = nullptr;
  ContentHash* hash_ = nullptr;
  uint64_t bytes_read_ = 0;
  std::vector<char> buffer_;
  const char* data_ = nullptr;
  size_t begin_ = 0;
  size_t end_ = 0;
  bool eof_ = true;
  size_t number_ = 0;
  enum class Ends { kUnknown, kNewline, kReturn } ends_ = Ends::kUnknown;
};

// The rules a line of a text log is held to, and the values of a row.
class LogRowParser {
 public:
  // `gyro_file`: the second file of a two-file log (options.gyro_columns,
  // whitespace layout; only t, gx, gy, gz are read and its time is checked
  // against the main file by the caller). `name` is used in messages.
  LogRowParser(std::string name, const LogReaderOptions& options, bool gyro_file);

  // One line (without its end) and its number. *row is true when the line
  // was a row: its values are value(slot), its time checked and scaled.
  bool Line(std::string_view line, size_t number, bool* row, std::string* error);

  // The fields of one row that is not blank or a comment, [begin, end)
  // without leading blanks, into value(slot), checked as Line checks them
  // (messages name line `line`), the temperature in degC (temp_scale,
  // temp_offset; log_reader.h); time is left as in the file (no
  // time_scale, no order check: Line does those).
  bool ParseFields(const char* begin, const char* end, size_t line, std::string* error) {
    const bool ok = format_ == LogFormat::kCsv ? ParseRow<true>(begin, end, line, error)
                                               : ParseRow<false>(begin, end, line, error);
    if (ok && has_[kTemp]) {
      values_[kTemp] = options_.temp_offset + options_.temp_scale * values_[kTemp];
    }
    return ok;
  }
  // A reader's fast path (io/log_plain_rows.cc, used by io/log_blocks.cc):
  // the CSV row that starts at `begin` (a line start, before `end`, the end
  // of the text), when it is plain: every field in use a number that
  // ParseNumber reads up to the next comma or, for the last field, the line
  // end ("\n", "\r\n" or `end`), no blanks, at most kMaxLogLineBytes.
  // Writes its values into row[kNumSlots] as ParseFields would leave
  // value(slot) (0 for a slot not in the file; time as in the file) and
  // returns where the next line starts. nullptr for anything else (a
  // comment, a blank or header line, a bad cell, a whitespace log...): then
  // LogLines and Line read that line, with the same values or the error they
  // give. Bytes up to `readable_end` (>= end) may be loaded, not used.
  const char* ParsePlainCsvRow(const char* begin, const char* end, const char* readable_end,
                               double* row) const;
  // The bytes after a line start that ParsePlainCsvRow loads when it may.
  static constexpr ptrdiff_t kPlainRowReadAhead = 96;

  // Rows read and the last time, as if Line had read rows up to here (for a
  // reader that parsed some rows elsewhere).
  void Resume(size_t rows, double previous_t) {
    rows_ = rows;
    previous_t_ = previous_t;
  }
  double previous_t() const { return previous_t_; }
  const LogReaderOptions& options() const { return options_; }
  const double* values() const { return values_; }

  bool has_layout() const { return have_layout_; }
  bool has(int slot) const { return has_[slot]; }
  // A row's value: t in seconds (time_scale applied, or index / sample_rate
  // without a time column), the others as in the file.
  double value(int slot) const { return values_[slot]; }
  size_t rows() const { return rows_; }
  const std::string& name() const { return name_; }
  bool gyro_file() const { return gyro_file_; }

 private:
  bool BuildLayout(const char* begin, const char* end, size_t line, std::string* error);
  template <bool kCsv>
  bool ParseRow(const char* begin, const char* end, size_t line, std::string* error);
  template <bool kCsv>
  bool FieldCountError(const char* begin, const char* end, size_t line, std::string* error) const;
  template <bool kCsv>
  bool CellError(const char* cell_begin, const char* end, size_t line, size_t field, bool parsed,
                 std::errc ec, std::string* error) const;
  bool CheckTime(size_t line, std::string* error);

  const std::string name_;
  const LogReaderOptions options_;
  const bool gyro_file_;
  const LogFormat format_;
  const std::vector<std::string> columns_;

  bool have_layout_ = false;
  std::vector<int> slot_of_field_;
  // Per field, the name used in messages: "'acc_y' (ay)".
  std::vector<std::string> field_label_;
  bool has_[kNumSlots] = {};
  double values_[kNumSlots] = {};
  double previous_t_ = 0.0;
  size_t rows_ = 0;
};

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_LOG_TEXT_H_
