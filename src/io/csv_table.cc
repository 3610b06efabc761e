#include "io/csv_table.h"

#include <charconv>

#include "util/numbers.h"

namespace gravcal {
namespace {

bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

}  // namespace

namespace internal {

bool SplitCsvLine(std::string_view line, std::vector<CsvCell>* cells, size_t* error_column,
                  std::string* what) {
  cells->clear();
  size_t i = 0;
  for (;;) {
    while (i < line.size() && IsBlank(line[i])) ++i;
    CsvCell cell;
    cell.column = i + 1;
    if (i < line.size() && line[i] == '"') {
      ++i;
      bool closed = false;
      while (i < line.size()) {
        if (line[i] == '"') {
          if (i + 1 < line.size() && line[i + 1] == '"') {
            cell.text += '"';
            i += 2;
            continue;
          }
          closed = true;
          ++i;
          break;
        }
        cell.text += line[i++];
      }
      if (!closed) {
        *error_column = cell.column;
        *what = "the quoted field is not closed";
        return false;
      }
      while (i < line.size() && IsBlank(line[i])) ++i;
      if (i < line.size() && line[i] != ',') {
        *error_column = i + 1;
        *what = "unexpected text after a quoted field (a quote inside quotes is written \"\")";
        return false;
      }
    } else {
      const size_t start = i;
      while (i < line.size() && line[i] != ',') ++i;
      size_t stop = i;
      while (stop > start && IsBlank(line[stop - 1])) --stop;
      cell.text.assign(line.substr(start, stop - start));
    }
    cells->push_back(std::move(cell));
    if (i >= line.size()) return true;
    ++i;  // the comma
  }
}

}  // namespace internal

std::string CsvWhere(const std::string& name, size_t line, size_t column) {
  return name + ":" + std::to_string(line) + ":" + std::to_string(column) + ": ";
}

bool ParseCsvRecords(std::string_view text, const std::string& name,
                     std::vector<CsvRecord>* records, std::string* error) {
  records->clear();
  size_t line_number = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    size_t first = 0;
    while (first < line.size() && IsBlank(line[first])) ++first;
    if (first == line.size() || line[first] == '#') continue;

    CsvRecord record;
    record.line = line_number;
    size_t column = 0;
    std::string what;
    if (!internal::SplitCsvLine(line, &record.cells, &column, &what)) {
      *error = CsvWhere(name, line_number, column) + what;
      return false;
    }
    records->push_back(std::move(record));
  }
  return true;
}

bool ParseCsvNumber(std::string_view text, double* value) {
  const char* first = text.data();
  const char* last = first + text.size();
  const auto result = internal::ParseNumber(first, last, value);
  return result.ec == std::errc() && result.ptr == last;
}

std::string CsvField(std::string_view text) {
  std::string field(text);
  for (char& c : field) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  const bool quote =
      field.find_first_of(",\"") != std::string::npos ||
      (!field.empty() && (field[0] == '#' || IsBlank(field.front()) || IsBlank(field.back())));
  if (!quote) return field;
  std::string out = "\"";
  for (char c : field) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

}  // namespace gravcal
