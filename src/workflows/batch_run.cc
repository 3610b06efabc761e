#include "workflows/batch_run.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

#include "util/cancellation.h"

namespace gravcal {
namespace internal {

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

}  // namespace

// One unit's place in the run (outside the anonymous namespace: State,
// declared in the header, holds these).
struct BatchSlot {
  // Held while a callback of the caller runs for this unit, and to abandon
  // it: an abandoned unit gets no callback after that.
  std::mutex callback;
  bool abandoned = false;  // Guarded by `callback`.
  // The rest is guarded by State::mutex.
  bool started = false;
  bool finished = false;
  Clock::time_point start;
  size_t worker = 0;
  std::atomic<bool> cancel{false};
};

struct BatchRun::State {
  State(const std::vector<BatchUnit>& u, const Config& b, const BatchOptions& o,
        std::vector<BatchResult>* r)
      : units(u), base(std::make_shared<const Config>(b)), options(o), results(r), slots(u.size()) {
    progress.total = u.size();
  }

  // The caller's; used only while the run has not returned (see Worker).
  const std::vector<BatchUnit>& units;
  const std::shared_ptr<const Config> base;
  const BatchOptions& options;
  std::vector<BatchResult>* const results;

  std::mutex mutex;
  std::condition_variable changed;
  std::vector<BatchSlot> slots;
  size_t next = 0;
  // Workers that have not exited and are not abandoned.
  size_t active = 0;
  std::vector<std::thread> threads;
  std::vector<char> thread_abandoned;
  BatchProgress progress;
  Clock::time_point begin = Clock::now();

  bool StopRequested() const {
    return options.stop != nullptr && options.stop->load(std::memory_order_relaxed);
  }

  // Counts a finished unit and tells the caller (State::mutex held).
  void CountDone(const BatchResult& r) {
    ++progress.done;
    if (r.skipped) {
      ++progress.skipped;
    } else if (r.status != BatchStatus::kOk) {
      ++progress.failed;
    }
    progress.elapsed_seconds = Seconds(begin, Clock::now());
    if (options.progress) {
      try {
        options.progress(progress);
      } catch (...) {
        // A progress display must not stop the batch.
      }
    }
  }
};

namespace {

using State = BatchRun::State;

// Runs `work`; an exception it throws fails the unit: "<what_failed>: <why>".
template <typename Work>
void FailOnException(const std::string& what_failed, BatchResult* r, Work&& work) {
  try {
    work();
  } catch (const std::exception& e) {
    r->status = BatchStatus::kFailed;
    r->message = what_failed + ": " + e.what();
  } catch (...) {
    r->status = BatchStatus::kFailed;
    r->message = what_failed;
  }
}

// The loop of one worker thread. `state` is shared: a worker abandoned with
// its unit may come back after the run has returned, and then must touch
// only `state`'s own members (never units, options or results).
void Worker(std::shared_ptr<State> state, size_t worker) {
  for (;;) {
    size_t i = 0;
    BatchUnit unit;
    {
      std::lock_guard<std::mutex> lock(state->mutex);
      if (state->next >= state->slots.size() || state->StopRequested()) {
        --state->active;
        state->changed.notify_all();
        return;
      }
      i = state->next++;
      BatchSlot& slot = state->slots[i];
      slot.started = true;
      slot.start = Clock::now();
      slot.worker = worker;
      unit = state->units[i];  // A copy: the caller's may be gone when we are late.
    }
    BatchSlot& slot = state->slots[i];
    const std::shared_ptr<const Config> base = state->base;
    BatchResult r;
    // The caller's skip, unless the unit has been abandoned meanwhile.
    const SkipFunction skip = [&state, &slot, i](const BatchUnit& u, const std::string& hash) {
      std::lock_guard<std::mutex> lock(slot.callback);
      if (slot.abandoned) return true;
      return state->options.skip && state->options.skip(i, u, hash);
    };
    FailOnException(unit.id + ": internal error", &r, [&] {
      ScopedCancelFlag cancel(&slot.cancel);
      RunUnit(unit, *base, skip, &r);
    });
    std::lock_guard<std::mutex> callback(slot.callback);
    if (slot.abandoned) return;  // Its result was given up; this thread is no longer counted.
    if (state->options.on_result) {
      FailOnException(unit.id + ": the result could not be stored", &r,
                      [&] { state->options.on_result(i, r); });
    }
    if (!state->options.keep_calibrations) r.calibration = Calibration();
    std::lock_guard<std::mutex> lock(state->mutex);
    (*state->results)[i] = std::move(r);
    slot.finished = true;
    state->CountDone((*state->results)[i]);
    state->changed.notify_all();
  }
}

// Starts one more worker (State::mutex held).
void StartWorker(const std::shared_ptr<State>& state) {
  ++state->active;
  state->thread_abandoned.push_back(0);
  state->threads.emplace_back(Worker, state, state->threads.size());
}

std::string SecondsText(double seconds) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", seconds);
  return text;
}

}  // namespace

BatchRun::BatchRun(const std::vector<BatchUnit>& units, const Config& base,
                   const BatchOptions& options, std::vector<BatchResult>* results)
    : state_(std::make_shared<State>(units, base, options, results)) {}

BatchRun::~BatchRun() = default;

namespace {

// Gives up unit i, whose worker is late (State::mutex held): its result
// says why, a fresh worker takes the place of the late one. False when its
// worker is inside a callback for it (try again later).
bool Abandon(const std::shared_ptr<State>& state, size_t i, bool timed_out, double running) {
  State& s = *state;
  BatchSlot& slot = s.slots[i];
  std::unique_lock<std::mutex> callback(slot.callback, std::try_to_lock);
  if (!callback.owns_lock()) return false;
  slot.abandoned = true;
  slot.cancel = true;
  callback.unlock();
  slot.finished = true;
  BatchResult& r = (*s.results)[i];
  r = BatchResult();
  r.unit = s.units[i].id;
  r.status = BatchStatus::kFailed;
  r.timings.total_seconds = running;
  if (timed_out) {
    r.timed_out = true;
    r.message = r.unit + ": timed out after " + SecondsText(s.options.unit_timeout_seconds) +
                " s (unit_timeout); abandoned, the batch went on";
  } else {
    r.not_run = true;
    r.message = r.unit + ": abandoned in flight: the batch was stopped";
  }
  s.thread_abandoned[slot.worker] = 1;
  --s.active;
  s.CountDone(r);
  if (s.next < s.slots.size() && !s.StopRequested()) StartWorker(state);
  return true;
}

// The units no worker started (State::mutex held).
void MarkNotStarted(State& s) {
  for (size_t i = 0; i < s.slots.size(); ++i) {
    if (s.slots[i].started) continue;
    BatchResult& r = (*s.results)[i];
    r.unit = s.units[i].id;
    r.status = BatchStatus::kFailed;
    r.not_run = true;
    r.message = r.unit + ": not run: the batch was stopped before it started";
  }
}

}  // namespace

void BatchRun::Run(int threads) {
  State& s = *state_;
  const BatchOptions& options = s.options;
  std::unique_lock<std::mutex> lock(s.mutex);
  const size_t workers = std::min(s.slots.size(), static_cast<size_t>(std::max(threads, 1)));
  for (size_t w = 0; w < workers; ++w) StartWorker(state_);
  bool stopping = false;
  Clock::time_point stop_time;
  // The watchdog: wakes when a unit finishes, and every 20 ms.
  while (s.active > 0) {
    s.changed.wait_for(lock, std::chrono::milliseconds(20));
    const Clock::time_point now = Clock::now();
    if (!stopping && s.StopRequested()) {
      stopping = true;
      stop_time = now;
    }
    const bool grace_over = stopping && Seconds(stop_time, now) > options.stop_grace_seconds;
    for (size_t i = 0; i < s.slots.size(); ++i) {
      const BatchSlot& slot = s.slots[i];
      if (!slot.started || slot.finished) continue;
      const double running = Seconds(slot.start, now);
      const bool timed_out =
          options.unit_timeout_seconds > 0.0 && running > options.unit_timeout_seconds;
      if (timed_out || grace_over) Abandon(state_, i, timed_out, running);
    }
  }
  MarkNotStarted(s);
  std::vector<std::thread> threads_left = std::move(s.threads);
  const std::vector<char> abandoned = s.thread_abandoned;
  lock.unlock();
  for (size_t w = 0; w < threads_left.size(); ++w) {
    if (abandoned[w]) {
      threads_left[w].detach();
    } else {
      threads_left[w].join();
    }
  }
}

}  // namespace internal
}  // namespace gravcal
