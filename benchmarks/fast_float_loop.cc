// The limit run of benchmarks/reading_throughput.sh: the least a reader of a
// numeric CSV must do, with the parser gravcal uses (fast_float). Reads the
// file in 1 MiB blocks, skips the first line (the header), parses every
// comma- or newline-separated field as a double and prints the number of
// fields and their sum (so that nothing is optimised away). No checks, no
// storage: what gravcal's reader could reach at best.
//   g++ -O2 -std=c++17 benchmarks/fast_float_loop.cc -o fast_float_loop
//   ./fast_float_loop log.csv
#include <fast_float/fast_float.h>

#include <cstdio>
#include <cstring>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fast_float_loop FILE\n");
    return 2;
  }
  std::FILE* file = std::fopen(argv[1], "rb");
  if (file == nullptr) {
    std::perror(argv[1]);
    return 1;
  }
  std::vector<char> buffer(size_t{1} << 20);
  size_t begin = 0, end = 0;
  bool header = true;
  long long fields = 0;
  double sum = 0.0;
  for (;;) {
    std::memmove(buffer.data(), buffer.data() + begin, end - begin);
    end -= begin;
    begin = 0;
    const size_t n = std::fread(buffer.data() + end, 1, buffer.size() - end, file);
    end += n;
    // Only whole lines: up to the last newline (all of it at the end).
    const char* data = buffer.data();
    size_t stop = end;
    if (n > 0) {
      while (stop > 0 && data[stop - 1] != '\n') --stop;
    }
    const char* p = data;
    const char* const last = data + stop;
    if (header) {
      const char* nl = static_cast<const char*>(std::memchr(p, '\n', last - p));
      if (nl == nullptr) break;
      p = nl + 1;
      header = false;
    }
    while (p < last) {
      double x = 0.0;
      const fast_float::from_chars_result r = fast_float::from_chars(p, last, x);
      sum += x;
      ++fields;
      p = r.ptr + 1;  // past ',' or '\n'
    }
    begin = stop;
    if (n == 0) break;
  }
  std::fclose(file);
  std::printf("%lld fields, sum %.17g\n", fields, sum);
  return 0;
}
