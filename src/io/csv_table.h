// The one CSV tokeniser of the library (io/csv_table.h, private), used by the
// batch manifests and summaries, the log reader's header row and the
// attitudes file: comma separated, a field in double quotes may hold commas
// and "" for a quote, unquoted fields are trimmed of blanks (space, tab, CR),
// lines starting with '#' and blank lines are skipped. A quoted field does
// not span lines. Every cell knows its line and column, so errors can say
// "units.csv:7:12". (The log reader's data rows are numbers only and keep
// their own fused split-and-parse loop for speed.)
#ifndef GRAVCAL_SRC_IO_CSV_TABLE_H_
#define GRAVCAL_SRC_IO_CSV_TABLE_H_

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace gravcal {

struct CsvCell {
  std::string text;
  // 1-based character column where the field starts.
  size_t column = 1;
};

struct CsvRecord {
  // 1-based line number.
  size_t line = 0;
  std::vector<CsvCell> cells;
};

namespace internal {

// Splits one line (without its line break) into fields by the rules above.
// An empty line is one empty field. False on a quoted field that is not
// closed or has text after its closing quote, with the 1-based column in
// *error_column and the message (without a location) in *what.
bool SplitCsvLine(std::string_view line, std::vector<CsvCell>* cells, size_t* error_column,
                  std::string* what);

}  // namespace internal

// Errors: "<name>:<line>:<column>: <what>".
bool ParseCsvRecords(std::string_view text, const std::string& name,
                     std::vector<CsvRecord>* records, std::string* error);

// "<name>:<line>:<column>: " for messages.
std::string CsvWhere(const std::string& name, size_t line, size_t column);

// A cell that is one number and nothing else (util/numbers.h ParseNumber,
// as std::from_chars: no blanks, no leading '+'); false otherwise. "nan" and
// "inf" parse: callers that need a finite value check it.
bool ParseCsvNumber(std::string_view text, double* value);

// The field as written to a CSV file: quoted when it holds a comma, a quote,
// a '#' at the start, blanks at either end or a line break (replaced by a
// space).
std::string CsvField(std::string_view text);

}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_CSV_TABLE_H_
