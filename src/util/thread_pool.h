// A fixed pool of worker threads for one parallel loop: each worker takes the
// next index from a shared counter until none is left, so uneven items
// balance themselves. The only shared state is that counter.
#ifndef GRAVCAL_SRC_UTIL_THREAD_POOL_H_
#define GRAVCAL_SRC_UTIL_THREAD_POOL_H_

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace gravcal {
namespace internal {

// Runs body(i) for every i in [0, n) on min(threads, n) threads (the calling
// thread is one of them). `body` must not throw.
template <typename Body>
void ParallelFor(size_t n, int threads, const Body& body) {
  std::atomic<size_t> next{0};
  auto work = [&]() {
    for (size_t i = next.fetch_add(1); i < n; i = next.fetch_add(1)) body(i);
  };
  const size_t workers = std::min(n, static_cast<size_t>(std::max(threads, 1)));
  std::vector<std::thread> pool;
  pool.reserve(workers > 0 ? workers - 1 : 0);
  for (size_t w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_THREAD_POOL_H_
