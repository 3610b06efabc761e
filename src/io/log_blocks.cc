#include "io/log_blocks.h"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <string_view>
#include <thread>
#include <vector>

#include "util/cancellation.h"
#include "util/error.h"

namespace gravcal {
namespace internal {
namespace {

inline bool IsRowBlank(char c) { return c == ' ' || c == '\t'; }

struct TextBlock {
  // Set by the reader: whole lines (the last block: up to the end of the
  // file), then what ends the file after them, if anything.
  std::vector<char> text;
  size_t size = 0;
  bool last = false;
  std::string read_error;
  uint64_t long_line_bytes = 0;  // > 0: a line this long follows the text
  // Set by the worker: `plain` when every line was a row, a comment or a
  // blank line and each row's time (when the log has one) increased within
  // the block; then `rows` holds `count` rows and the text `lines` lines.
  bool parsed = false;
  bool plain = false;
  std::vector<double> rows;
  size_t count = 0;
  size_t lines = 0;
};

// Parses one block's lines on a worker (TextBlock::plain above).
void ParseBlock(LogRowParser* rules, TextBlock* block) {
  block->plain = false;
  block->count = 0;
  block->lines = 0;
  const bool timed = rules->has(kT);
  const double time_scale = rules->options().time_scale;
  const char* p = block->text.data();
  const char* const end = p + block->size;
  const char* const readable_end = block->text.data() + block->text.size();
  std::string why;
  double previous = 0.0;
  size_t count = 0, lines = 0;
  while (p < end) {
    if ((count + 1) * kNumSlots > block->rows.size()) {
      block->rows.resize(2 * block->rows.size() + 4096 * kNumSlots);
    }
    double* row = block->rows.data() + count * kNumSlots;
    ++lines;
    // Most lines are plain rows, read in one pass (the line and its cells).
    if (const char* next = rules->ParsePlainCsvRow(p, end, readable_end, row)) {
      p = next;
    } else {
      const char* newline = static_cast<const char*>(std::memchr(p, '\n', end - p));
      const char* stop = newline != nullptr ? newline : end;
      if (static_cast<size_t>(stop - p) > kMaxLogLineBytes) return;
      if (newline != nullptr && stop > p && stop[-1] == '\r') --stop;
      const char* s = p;
      p = newline != nullptr ? newline + 1 : end;
      while (s < stop && IsRowBlank(*s)) ++s;
      if (s == stop || *s == '#') continue;
      if (!rules->ParseFields(s, stop, 0, &why)) return;
      std::memcpy(row, rules->values(), sizeof(double) * kNumSlots);
    }
    if (timed) {
      const double t = row[kT] * time_scale;
      if (!std::isfinite(t) || (count > 0 && !(t > previous))) return;
      row[kT] = t;
      previous = t;
    }
    ++count;
  }
  block->count = count;
  block->lines = lines;
  block->plain = true;
}

class BlockPipeline {
 public:
  // Blocks of `block_bytes` of text read, plus the unfinished line carried
  // over from the one before (at most kMaxLogLineBytes).
  BlockPipeline(LogLines* source, const LogRowParser& rules, int threads, size_t block_bytes)
      : source_(source),
        block_bytes_(block_bytes),
        slots_(std::min(2 * static_cast<size_t>(threads) + 2, kMaxLogBlocksInFlight)) {
    // The reader starts with the bytes the line reader held.
    const std::string_view head = source->TakeBuffered();
    head_.assign(head.begin(), head.end());
    for (size_t i = 0; i < slots_; ++i) {
      blocks_.push_back(std::make_unique<TextBlock>());
      // (ParsePlainCsvRow may load bytes after the text.)
      blocks_.back()->text.resize(kMaxLogLineBytes + block_bytes_ +
                                  LogRowParser::kPlainRowReadAhead);
    }
    carry_.resize(std::max(kMaxLogLineBytes, block_bytes_));
    for (int w = 0; w < threads; ++w) rules_.push_back(std::make_unique<LogRowParser>(rules));
    try {
      threads_.emplace_back([this] { Read(); });
      for (int w = 0; w < threads; ++w) {
        threads_.emplace_back([this, w] { Work(rules_[w].get()); });
      }
    } catch (...) {
      Stop();  // A thread could not start: the ones that did are joined.
      throw;
    }
  }

  ~BlockPipeline() { Stop(); }

  // The next block in file order, parsed; Release it when done.
  TextBlock* Next() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return consumed_ < read_ && blocks_[consumed_ % slots_]->parsed; });
    return blocks_[consumed_ % slots_].get();
  }
  void Release() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      blocks_[consumed_ % slots_]->parsed = false;
      ++consumed_;
    }
    changed_.notify_all();
  }

 private:
  // The reader: blocks of whole lines, until the end of the file, a read
  // error or a line longer than a log line may be.
  void Read() {
    for (;;) {
      TextBlock* block;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return stop_ || read_ - consumed_ < slots_; });
        if (stop_) return;
        block = blocks_[read_ % slots_].get();
      }
      FillBlock(block);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++read_;
      }
      changed_.notify_all();
      if (block->last) return;
    }
  }

  void FillBlock(TextBlock* block) {
    block->last = false;
    block->read_error.clear();
    block->long_line_bytes = 0;
    std::memcpy(block->text.data(), carry_.data(), carry_size_);
    const size_t n = Input(block->text.data() + carry_size_, &block->read_error);
    const size_t filled = carry_size_ + n;
    carry_size_ = 0;
    if (!block->read_error.empty()) {
      block->size = 0;  // The unfinished line is lost, as LogLines loses it.
      block->last = true;
      return;
    }
    if (n == 0) {  // The end: the last line may have no line end.
      block->size = filled;
      block->last = true;
      return;
    }
    const char* data = block->text.data();
    const void* newline = memrchr(data, '\n', filled);
    block->size = newline != nullptr ? static_cast<const char*>(newline) - data + 1 : 0;
    const size_t rest = filled - block->size;
    if (rest <= kMaxLogLineBytes) {
      carry_size_ = rest;
      std::memcpy(carry_.data(), data + block->size, rest);
    } else {
      // The line after the block is too long: counted to its end without
      // keeping it, as LogLines counts it.
      uint64_t bytes = rest;
      for (;;) {
        const size_t more = Input(carry_.data(), &block->read_error);
        if (!block->read_error.empty()) break;
        const void* end = std::memchr(carry_.data(), '\n', more);
        if (end != nullptr) {
          bytes += static_cast<const char*>(end) - carry_.data();
          break;
        }
        bytes += more;
        if (more == 0) break;
      }
      block->long_line_bytes = block->read_error.empty() ? bytes : 0;
      block->last = true;
    }
  }

  // Up to block_bytes_ more bytes of the file into `out`: those the line
  // reader held first, then from the file.
  size_t Input(char* out, std::string* error) {
    if (head_used_ < head_.size()) {
      const size_t n = std::min(block_bytes_, head_.size() - head_used_);
      std::memcpy(out, head_.data() + head_used_, n);
      head_used_ += n;
      return n;
    }
    return source_->ReadRaw(out, block_bytes_, error);
  }

  void Work(LogRowParser* rules) {
    for (;;) {
      TextBlock* block;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return stop_ || claimed_ < read_; });
        if (stop_) return;
        block = blocks_[claimed_ % slots_].get();
        ++claimed_;
      }
      try {
        ParseBlock(rules, block);
      } catch (const std::exception&) {
        block->plain = false;  // Parsed again by the caller, which reports it.
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        block->parsed = true;
      }
      changed_.notify_all();
    }
  }

  void Stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    for (std::thread& t : threads_) t.join();
    threads_.clear();
  }

  LogLines* const source_;
  const size_t block_bytes_;
  const size_t slots_;
  std::vector<std::unique_ptr<TextBlock>> blocks_;
  std::vector<std::unique_ptr<LogRowParser>> rules_;
  std::vector<char> head_;
  size_t head_used_ = 0;
  std::vector<char> carry_;  // the unfinished line after the last block
  size_t carry_size_ = 0;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool stop_ = false;
  // Blocks read, claimed by a worker and consumed, counted from 0.
  size_t read_ = 0, claimed_ = 0, consumed_ = 0;
  std::vector<std::thread> threads_;
};

}  // namespace

bool CanParseLogBlocks(const LogLines& source, const LogRowParser& parser) {
  return source.is_file() && source.newline_ends() && parser.has_layout() && !parser.gyro_file();
}

bool ParseLogBlocks(LogLines* source, LogRowParser* parser, int threads, const LogRowSink& sink,
                    std::string* error, size_t block_bytes) {
  const bool timed = parser->has(kT);
  const double sample_rate = parser->options().sample_rate;
  size_t rows = parser->rows();
  double previous_t = parser->previous_t();
  size_t number = source->number();
  BlockPipeline pipeline(source, *parser, std::max(threads, 1), std::max<size_t>(block_bytes, 1));
  for (;;) {
    TextBlock* block = pipeline.Next();
    bool plain = block->plain && !CancelRequested();
    if (plain && block->count > 0) {
      double* first = block->rows.data();
      if (timed) {
        plain = rows == 0 || first[kT] > previous_t;
      } else {
        // t = row index / sample_rate, as LogRowParser::CheckTime sets it.
        double previous = previous_t;
        for (size_t i = 0; i < block->count && plain; ++i) {
          const double t = static_cast<double>(rows + i) / sample_rate;
          plain = rows + i == 0 || t > previous;
          first[i * kNumSlots + kT] = t;
          previous = t;
        }
      }
    }
    if (plain) {
      if (block->count > 0) {
        sink(block->rows.data(), block->count);
        rows += block->count;
        previous_t = block->rows[(block->count - 1) * kNumSlots + kT];
      }
      number += block->lines;
    } else {
      // Line by line, as the lines before were read: the same error.
      parser->Resume(rows, previous_t);
      LogLines lines(std::string_view(block->text.data(), block->size), parser->name());
      lines.ContinueNewlineText(number);
      std::string_view line;
      std::string why;
      while (lines.Next(&line, &why)) {
        bool row = false;
        if (!parser->Line(line, lines.number(), &row, &why)) break;
        if (row) sink(parser->values(), 1);
      }
      if (!why.empty()) {
        source->set_number(lines.number());
        return SetError(error, why);
      }
      rows = parser->rows();
      previous_t = parser->previous_t();
      number = lines.number();
    }
    if (block->long_line_bytes > 0 || !block->read_error.empty()) parser->Resume(rows, previous_t);
    if (block->long_line_bytes > 0) {
      source->set_number(number + 1);
      return SetError(error, LongLineMessage(parser->name(), number + 1, block->long_line_bytes));
    }
    if (!block->read_error.empty()) {
      source->set_number(number);
      return SetError(error, block->read_error);
    }
    const bool last = block->last;
    pipeline.Release();
    if (last) break;
  }
  parser->Resume(rows, previous_t);
  source->set_number(number);
  return true;
}

}  // namespace internal
}  // namespace gravcal
