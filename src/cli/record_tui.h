// gravcal record's terminal UI (issue 37), raw ANSI on standard error when
// it is a terminal: the sample rate and state (moving / holding with a
// progress bar), the poses captured on the two hemispheres as the report
// draws them (z >= 0 seen from +z, z < 0 seen through from +z, Lambert
// equal-area, +x right, +y up), each parameter's predicted sigma against
// its target as a bar, the suggested pose and the latest warnings and
// events. Redrawn at most ten times a second.
#ifndef GRAVCAL_SRC_CLI_RECORD_TUI_H_
#define GRAVCAL_SRC_CLI_RECORD_TUI_H_

#include <chrono>
#include <deque>
#include <string>

#include "gravcal/workflows/recorder.h"

namespace gravcal {
namespace cli {

// The screen as text lines (no escape codes): what Draw shows.
std::string RenderRecordScreen(const RecorderStatus& status, bool stalled,
                               const std::deque<std::string>& log);

class RecordTui {
 public:
  // Inactive (every call a no-op) unless `active`.
  void Begin(bool active);
  bool active() const { return active_; }
  // An event's sentence for the log lines at the bottom.
  void Log(const std::string& text);
  void Draw(const RecorderStatus& status, bool stalled);
  // Leaves the last screen and the cursor below it.
  void End();

 private:
  bool active_ = false;
  std::deque<std::string> log_;
  std::chrono::steady_clock::time_point last_draw_;
  RecorderStatus last_status_;
  bool drawn_ = false;
};

}  // namespace cli
}  // namespace gravcal

#endif  // GRAVCAL_SRC_CLI_RECORD_TUI_H_
