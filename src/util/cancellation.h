// util/cancellation.h (private): asking the work running on a thread to stop.
//
// A batch unit over its time limit cannot be killed safely (a thread has no
// safe kill); instead its worker sets a flag that long loops check (the
// Ceres solver through an iteration callback, the log reader between
// lines). The flag is per thread, so no function signature has to carry it.
#ifndef GRAVCAL_SRC_UTIL_CANCELLATION_H_
#define GRAVCAL_SRC_UTIL_CANCELLATION_H_

#include <atomic>

namespace gravcal {
namespace internal {

// The flag of the work on this thread; null when nobody can cancel it.
inline const std::atomic<bool>*& ThreadCancelFlag() {
  thread_local const std::atomic<bool>* flag = nullptr;
  return flag;
}

// True once the work on this thread has been asked to stop.
inline bool CancelRequested() {
  const std::atomic<bool>* flag = ThreadCancelFlag();
  return flag != nullptr && flag->load(std::memory_order_relaxed);
}

// Installs `flag` for this thread for the object's lifetime.
class ScopedCancelFlag {
 public:
  explicit ScopedCancelFlag(const std::atomic<bool>* flag) : previous_(ThreadCancelFlag()) {
    ThreadCancelFlag() = flag;
  }
  ~ScopedCancelFlag() { ThreadCancelFlag() = previous_; }
  ScopedCancelFlag(const ScopedCancelFlag&) = delete;
  ScopedCancelFlag& operator=(const ScopedCancelFlag&) = delete;

 private:
  const std::atomic<bool>* const previous_;
};

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_CANCELLATION_H_
