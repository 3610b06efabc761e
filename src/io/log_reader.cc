#include "gravcal/io/log_reader.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "core/warnings.h"
#include "gravcal/io/long_log.h"
#include "io/block_averager.h"
#include "io/csv_table.h"
#include "io/file_text.h"
#include "io/formats/file_format.h"
#include "io/formats/message_log.h"
#include "io/log_blocks.h"
#include "io/log_pair.h"
#include "io/log_text.h"
#include "util/cancellation.h"
#include "util/content_hash.h"
#include "util/error.h"
#include "util/numbers.h"

namespace gravcal {
namespace {

using internal::BlockAverager;
using internal::FileText;

using internal::ExactNumber;
using internal::kGx;
using internal::kGy;
using internal::kGz;
using internal::kLogSlotNames;
using internal::kNumSlots;
using internal::kT;
using internal::kTemp;
using internal::LogWhere;
using internal::SetError;

using internal::kRelativeTimeTolerance;

bool IsContractName(const std::string& name) {
  for (const char* contract : kLogSlotNames) {
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

// Rows in the `total` bytes left of a text, estimated from the line length
// of the first 64 KiB of `rest` (its start).
size_t EstimateRows(std::string_view rest, uint64_t total) {
  constexpr size_t kSample = size_t{1} << 16;
  const size_t sample = std::min(rest.size(), kSample);
  const size_t newlines = static_cast<size_t>(std::count(rest.data(), rest.data() + sample, '\n'));
  if (sample == total) return newlines + 1;
  if (newlines == 0) return 16;
  const double rows =
      static_cast<double>(total) * static_cast<double>(newlines) / static_cast<double>(sample);
  return static_cast<size_t>(rows * 1.02) + 16;
}

// Threads that parse a long log (LongLogReading::threads; 0: the cores, at
// most as many as blocks can be in flight).
int ReadingThreads(const LongLogReading& reading) {
  if (reading.threads > 0) return reading.threads;
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  return static_cast<int>(std::min<unsigned>(cores, internal::kMaxLogBlocksInFlight - 2));
}

// The plain CSV rows that follow the last line `source` gave
// (LogRowParser::ParsePlainCsvRow), into `sink` in batches, without the line
// reader: its buffered whole lines for a file, the rest of text in memory.
// Stops before the first line that is not a plain row, whose time Line
// would refuse, or on which Line would check for cancellation: Line reads
// that one, with the same value or message. False when the first line was
// not a plain row.
bool ReadPlainRows(internal::LogLines* source, internal::LogRowParser* parser,
                   const internal::LogRowSink& sink) {
  using internal::kNumSlots;
  using internal::kT;
  std::string_view text = source->rest();
  const char* const readable_end = text.data() + text.size();
  if (source->is_file()) {  // Only whole lines: the rest is read again.
    const size_t last = text.rfind('\n');
    text = text.substr(0, last == std::string_view::npos ? 0 : last + 1);
  }
  const char* p = text.data();
  const char* const end = p + text.size();
  const bool timed = parser->has(kT);
  const double time_scale = parser->options().time_scale;
  const double sample_rate = parser->options().sample_rate;
  size_t rows = parser->rows();
  double previous_t = parser->previous_t();
  size_t number = source->number();
  constexpr size_t kBatch = 256;
  double batch[kBatch * kNumSlots];
  size_t count = 0;
  bool plain = true;
  while (p < end && ((number + 1) & 0xffff) != 0) {
    double* row = batch + count * kNumSlots;
    const char* next = parser->ParsePlainCsvRow(p, end, readable_end, row);
    if (next == nullptr) {
      plain = number > source->number();
      break;
    }
    // As LogRowParser::CheckTime.
    const double t = timed ? row[kT] * time_scale : static_cast<double>(rows) / sample_rate;
    if (!std::isfinite(t) || (rows > 0 && !(t > previous_t))) break;
    row[kT] = t;
    previous_t = t;
    ++rows;
    ++number;
    p = next;
    if (++count == kBatch) {
      sink(batch, count);
      count = 0;
    }
  }
  if (count > 0) sink(batch, count);
  parser->Resume(rows, previous_t);
  source->Skip(static_cast<size_t>(p - text.data()), number - source->number());
  return plain;
}

// Parses the lines of one text log (io/log_text.h; text in memory or a file
// read block by block, `bytes` long, 0 for text in memory): the main log, or
// (`reference` not null) the second file holding the gyroscope, whose times
// must match the main log's sample for sample. `euroc`: the '#' opening the
// first line is dropped (an EuRoC / TUM-VI header is the header row without
// it). Fills out->t, accel, gyro, temperature (only out->gyro for the
// gyroscope file); does not check for an empty result. *lines is the number
// of lines.
bool ParseText(internal::LogLines* source, uint64_t bytes, bool euroc, const std::string& name,
               const LogReaderOptions& options, const ImuLog* reference,
               const std::string& reference_name, ImuLog* out, size_t* lines,
               LongLogReading* bounded, std::string* error) {
  internal::LogRowParser parser(name, options, reference != nullptr);
  // A second gyroscope file is matched row for row: never averaged.
  const size_t max_samples =
      bounded != nullptr && options.gyro_path.empty() ? bounded->max_samples : 0;
  BlockAverager averager(max_samples, out);
  // Rows of kNumSlots values (LogRowParser::values) into the log.
  const internal::LogRowSink add_rows = [&](const double* rows, size_t count) {
    const bool gyro = parser.has(kGx), temperature = parser.has(kTemp);
    if (gyro && temperature) averager.AddRows<true, true>(rows, count);
    if (gyro && !temperature) averager.AddRows<true, false>(rows, count);
    if (!gyro && temperature) averager.AddRows<false, true>(rows, count);
    if (!gyro && !temperature) averager.AddRows<false, false>(rows, count);
  };
  const int threads = bounded != nullptr ? ReadingThreads(*bounded) : 1;
  std::string_view line;
  std::string why;
  bool reserved = false;
  constexpr int kMaxPlainMisses = 16;
  int plain_misses = 0;
  while (source->Next(&line, &why)) {
    if (euroc && source->number() == 1 && !line.empty() && line[0] == '#') line.remove_prefix(1);
    bool row = false;
    if (!parser.Line(line, source->number(), &row, &why)) break;
    if (!row) continue;
    const size_t index = parser.rows() - 1;
    if (reference != nullptr) {
      const std::vector<double>& reference_t = reference->t;
      if (!reserved) out->gyro.reserve(reference_t.size());
      reserved = true;
      if (index >= reference_t.size()) {
        return SetError(error, LogWhere(name, source->number()) + "more samples than " +
                                   reference_name + " (" + std::to_string(reference_t.size()) +
                                   ")");
      }
      if (parser.has(kT)) {
        const double t = parser.value(kT);
        const double r = reference_t[index];
        if (!(std::fabs(t - r) <= kRelativeTimeTolerance * std::max(std::fabs(t), std::fabs(r)))) {
          return SetError(error, LogWhere(name, source->number()) + "time " + ExactNumber(t) +
                                     " differs from time " + ExactNumber(r) + " of sample " +
                                     std::to_string(index) + " in " + reference_name);
        }
      }
      out->gyro.emplace_back(parser.value(kGx), parser.value(kGy), parser.value(kGz));
      continue;
    }
    if (!reserved) {
      const std::string_view rest = source->rest();
      const uint64_t left = bytes == 0 ? rest.size() : bytes - (source->bytes_read() - rest.size());
      size_t rows = EstimateRows(rest, left) + 1;
      // Bounded: never more than max_samples; a pipe (no length) reserves
      // them at once rather than grow to twice as many.
      if (max_samples > 0) rows = bytes == 0 ? max_samples : std::min(rows, max_samples);
      out->t.reserve(rows);
      out->accel.reserve(rows);
      if (parser.has(kGx)) out->gyro.reserve(rows);
      if (parser.has(kTemp)) out->temperature.reserve(rows);
      reserved = true;
    }
    add_rows(parser.values(), 1);
    // The plain rows that follow, without the line reader; after a few
    // tries that read none (a whitespace log), no more.
    if (plain_misses < kMaxPlainMisses && source->newline_ends() && reference == nullptr &&
        !ReadPlainRows(source, &parser, add_rows)) {
      ++plain_misses;
    }
    // The rest of a long file on several threads (io/log_blocks.h): the
    // same rows and errors. Not a pipe (bytes 0): its reader thread could
    // wait on the writer after an error.
    if (threads > 1 && internal::CanParseLogBlocks(*source, parser) && bytes > 0 &&
        bytes - source->bytes_read() >= internal::kMinBlockParseBytes) {
      if (!internal::ParseLogBlocks(source, &parser, threads, add_rows, &why)) break;
    }
  }
  if (!why.empty()) return SetError(error, why);
  *lines = source->number();
  if (bounded != nullptr) {
    bounded->samples_averaged = averager.block();
    bounded->rows_read = parser.rows();
  }
  return true;
}

// A file opened for reading, closed when it goes.
struct FileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};
using OpenFile = std::unique_ptr<std::FILE, FileCloser>;

bool OpenForReading(const std::string& path, OpenFile* file, std::string* error) {
  file->reset(std::fopen(path.c_str(), "rb"));
  if (*file == nullptr) {
    return SetError(error, path + ": cannot open: " + std::generic_category().message(errno));
  }
  return true;
}

// The log in the lines of `source` (a text of `format`, `bytes` long as in
// ParseText), and the gyroscope file options.gyro_path names, read block by
// block.
bool ParseLog(internal::LogLines* source, uint64_t bytes, internal::FileFormat format,
              const std::string& name, const LogReaderOptions& options, ImuLog* log,
              LongLogReading* bounded, std::string* error) {
  const bool euroc = format == internal::FileFormat::kEuroc && internal::LayoutFromFile(options);
  const LogReaderOptions& layout = euroc ? internal::EurocOptions(options) : options;
  if (bounded != nullptr && bounded->max_samples > 0 && !options.gyro_path.empty() && !euroc) {
    // Both files in step, in bounded memory.
    return internal::ParseLogPair(source, name, options, bounded->max_samples, log,
                                  &bounded->samples_averaged, &bounded->rows_read, error);
  }
  ImuLog parsed;
  size_t lines = 0;
  if (!ParseText(source, bytes, euroc, name, layout, nullptr, name, &parsed, &lines, bounded,
                 error)) {
    return false;
  }
  if (parsed.t.empty()) return SetError(error, name + ": no samples");

  if (!options.gyro_path.empty()) {
    OpenFile file;
    if (!OpenForReading(options.gyro_path, &file, error)) return false;
    internal::LogLines gyro_lines(file.get(), options.gyro_path);
    ImuLog gyro;
    size_t gyro_lines_read = 0;
    if (!ParseText(&gyro_lines, 0, false, options.gyro_path, options, &parsed, name, &gyro,
                   &gyro_lines_read, nullptr, error)) {
      return false;
    }
    if (gyro.gyro.size() != parsed.t.size()) {
      return SetError(error, LogWhere(options.gyro_path, std::max<size_t>(gyro_lines_read, 1)) +
                                 "ends after " + std::to_string(gyro.gyro.size()) + " samples; " +
                                 name + " has " + std::to_string(parsed.t.size()));
    }
    parsed.gyro = std::move(gyro.gyro);
  }
  parsed.source = name;
  *log = std::move(parsed);
  return true;
}

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
  internal::LogLines source(text, name);
  return ParseLog(&source, 0, format, name, options, log, nullptr, error);
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
  if (max_log_entries != 0 && max_log_entries < 16) {
    return SetError(error, "max_log_entries is " + std::to_string(max_log_entries) +
                               ", must be 0 (no limit) or at least 16");
  }
  if (!std::isfinite(temp_scale) || temp_scale == 0.0) {
    return SetError(error,
                    "temp_scale is " + ExactNumber(temp_scale) + ", must be finite and not 0");
  }
  if (!std::isfinite(temp_offset)) {
    return SetError(error, "temp_offset is " + ExactNumber(temp_offset) + ", must be finite");
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
      const std::string name = internal::LogFileColumnName(*this, a);
      if (name == internal::LogFileColumnName(*this, b)) {
        return SetError(error, std::string("rename: '") + kLogSlotNames[a] + "' and '" +
                                   kLogSlotNames[b] + "' would both read column '" + name + "'");
      }
    }
  }
  return true;
}

namespace {

// A pipe or device (not a regular file), read once from its start: the
// format from its first bytes. In bounded memory (`bounded`, no `hash`) it is
// streamed; else read whole, since the content hash needs the length first.
bool ReadPipe(const std::string& path, const LogReaderOptions& options, ImuLog* log,
              internal::ContentHash* hash, LongLogReading* bounded, std::string* error) {
  std::string why;
  if (!options.IsValid(&why)) return SetError(error, path + ": invalid options: " + why);
  if (bounded != nullptr && bounded->max_samples > 0 && options.gyro_path.empty() &&
      hash == nullptr) {
    OpenFile file;
    if (!OpenForReading(path, &file, error)) return false;
    internal::LogLines source(file.get(), path);
    const std::string_view head = source.Head(4096, &why);
    if (!why.empty()) return SetError(error, why);
    internal::FileFormat format = internal::FileFormat::kText;
    if (!internal::DetectFileFormat(head, &format, &why)) return SetError(error, path + ": " + why);
    if (internal::NewMessageRecording(format) != nullptr) {
      return SetError(error, path + ": a " + internal::FileFormatName(format) +
                                 " is read from its file, not from a pipe");
    }
    return ParseLog(&source, 0, format, path, options, log, bounded, error);
  }
  FileText text;
  if (!text.Read(path, error)) return false;
  if (!ParseImpl(text.view(), path, options, log, error)) return false;
  if (hash != nullptr) hash->Add(text.view());
  return true;
}

// ReadImuLog; `hash`, when not null, gets the content hash of the file's
// bytes: from the text parsed for a text log, from a second read for a
// message recording (read message by message).
bool ReadLog(const std::string& path, const LogReaderOptions& options, ImuLog* log,
             internal::ContentHash* hash, LongLogReading* bounded, std::string* error) {
  if (log == nullptr) return SetError(error, path + ": no log to read into");
  try {
    struct stat path_stat;
    if (stat(path.c_str(), &path_stat) == 0 && !S_ISREG(path_stat.st_mode) &&
        !S_ISDIR(path_stat.st_mode)) {
      return ReadPipe(path, options, log, hash, bounded, error);
    }
    internal::FileFormat format = internal::FileFormat::kText;
    if (!internal::DetectFileFormatOf(path, &format, error)) return false;
    if (std::unique_ptr<internal::MessageRecording> recording =
            internal::NewMessageRecording(format)) {
      std::string why;
      if (!options.IsValid(&why)) return SetError(error, path + ": invalid options: " + why);
      if (!recording->Open(path, error) ||
          !internal::ReadMessageLog(recording.get(), path, options, log, error)) {
        return false;
      }
      std::string bytes;
      if (hash != nullptr) {
        if (!ReadFileBytes(path, &bytes, error)) return false;
        hash->Add(bytes);
      }
      return true;
    }
    std::string why;
    if (!options.IsValid(&why)) return SetError(error, path + ": invalid options: " + why);
    OpenFile file;
    if (!OpenForReading(path, &file, error)) return false;
    struct stat st;
    if (fstat(fileno(file.get()), &st) != 0 || !S_ISREG(st.st_mode)) {
      file.reset();
      return ReadPipe(path, options, log, hash, bounded, error);
    }
    const uint64_t bytes = static_cast<uint64_t>(st.st_size);
    // Read in bounded memory (max_samples); a second gyroscope file too,
    // in step (io/log_pair.h), unless the main file is an EuRoC one.
    const bool in_bounds = bounded != nullptr && bounded->max_samples > 0 &&
                           (options.gyro_path.empty() || format != internal::FileFormat::kEuroc);
    if (!in_bounds &&
        !internal::CheckLogFitsInMemory(path, bytes, internal::AvailableMemoryBytes(), error)) {
      return false;
    }
    // Block by block (io/log_text.h LogLines): no copy of the whole text.
    internal::LogLines source(file.get(), path);
    if (hash != nullptr) {
      hash->Begin(bytes);
      source.HashInto(hash);
    }
    if (!ParseLog(&source, bytes, format, path, options, log, bounded, error)) return false;
    if (source.bytes_read() != bytes) {
      return SetError(error, path + ": changed while it was read (" + std::to_string(bytes) +
                                 " bytes, then " + std::to_string(source.bytes_read()) + ")");
    }
    if (hash != nullptr) hash->End();
    return true;
  } catch (const std::exception& e) {
    return SetError(error, path + ": " + e.what());
  }
}

}  // namespace

bool ReadImuLog(const std::string& path, const LogReaderOptions& options, ImuLog* log,
                std::string* error) {
  return ReadLog(path, options, log, nullptr, nullptr, error);
}

bool ReadImuLog(const std::string& path, const LogReaderOptions& options, ImuLog* log,
                CalibrationProvenance* provenance, std::string* error) {
  internal::ContentHash hash;
  if (!ReadLog(path, options, log, &hash, nullptr, error)) return false;
  *provenance = {path, hash.Hex(), GRAVCAL_VERSION};
  return true;
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

}  // namespace gravcal

namespace gravcal {

std::string LongLogReading::Describe() const {
  if (samples_averaged <= 1) return "";
  const size_t entries = rows_read / samples_averaged;
  return "the log's " + std::to_string(rows_read) + " rows were read in bounded memory as " +
         std::to_string(entries) + " means of " + std::to_string(samples_averaged) +
         " rows (at most " + std::to_string(max_samples) + " held)";
}

bool ReadImuLogBounded(const std::string& path, const LogReaderOptions& options,
                       LongLogReading* reading, ImuLog* log, CalibrationProvenance* provenance,
                       std::string* error) {
  if (reading->max_samples != 0 && reading->max_samples < 16) {
    return SetError(error, path + ": max_samples is " + std::to_string(reading->max_samples) +
                               ", must be 0 (no limit) or at least 16");
  }
  reading->samples_averaged = 1;
  reading->rows_read = 0;
  LongLogReading result = *reading;
  internal::ContentHash hash;
  if (!ReadLog(path, options, log, provenance != nullptr ? &hash : nullptr, &result, error)) {
    return false;
  }
  *reading = result;
  if (provenance != nullptr) *provenance = {path, hash.Hex(), GRAVCAL_VERSION};
  return true;
}

void AddLongLogWarning(const LongLogReading& reading, Calibration* calibration) {
  if (reading.samples_averaged <= 1) return;
  internal::AddWarning(WarningCode::kParameterSource,
                       reading.Describe() +
                           ": poses and turns come from those means (the turns integrated at "
                           "their rate), and a pose's spread per sample is that of a mean",
                       &calibration->warnings, &calibration->warning_codes);
}

}  // namespace gravcal
