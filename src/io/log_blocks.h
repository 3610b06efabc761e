// io/log_blocks.h (private): the rest of a long text log parsed on several
// threads, with the rows, values, checks and messages that LogRowParser::Line
// gives line by line (io/log_text.h).
//
// One thread reads the file in blocks of whole lines, `threads` workers parse
// blocks into rows (each on its own copy of the row rules), and the caller
// takes the blocks' rows in file order. A block in which anything is not a
// plain row, a comment or a blank line (a bad cell, a line too long, a time
// that does not increase, a cancel request) is parsed again line by line on
// the caller's thread by LogRowParser::Line, so its error is the one Line
// gives, at the same line. Memory: a fixed number of blocks in flight.
#ifndef GRAVCAL_SRC_IO_LOG_BLOCKS_H_
#define GRAVCAL_SRC_IO_LOG_BLOCKS_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include "io/log_text.h"

namespace gravcal {
namespace internal {

// `count` rows of kNumSlots values each, in slot order, t in seconds (as
// LogRowParser::value gives them after Line).
using LogRowSink = std::function<void(const double* rows, size_t count)>;

// A file with fewer bytes left than this is read line by line: threads
// would not pay for themselves.
constexpr uint64_t kMinBlockParseBytes = uint64_t{16} << 20;
// Text read per block (tests use smaller blocks), and the most blocks in
// flight (read, parsed or being taken). A block's rows cost at most about
// 11 times its text (8 doubles for a row of at least 6 bytes, "1,2,3\n"), so
// the blocks cost at most about 100 MB whatever the log and the threads (2
// MB for rows of 40 bytes).
constexpr size_t kLogBlockBytes = size_t{1} << 20;
constexpr size_t kMaxLogBlocksInFlight = 8;

// Whether ParseLogBlocks can take over `source` now: a file (not text in
// memory) whose line ends are newlines, read by `parser` up to a row (its
// layout known), not the second file of a two-file log.
bool CanParseLogBlocks(const LogLines& source, const LogRowParser& parser);

// Parses the rest of `source` (above) with `threads` workers (at least 1);
// the rows go to `sink` in file order. Afterwards *parser holds what Line
// would have left (rows, last time) and source->number() is the last line.
// False with the first error of the rest of the file, as Line and
// LogLines::Next give it.
bool ParseLogBlocks(LogLines* source, LogRowParser* parser, int threads, const LogRowSink& sink,
                    std::string* error, size_t block_bytes = kLogBlockBytes);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_IO_LOG_BLOCKS_H_
