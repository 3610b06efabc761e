// gravcal record's terminal UI (record_tui.h).
#include "cli/record_tui.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

namespace gravcal {
namespace cli {

namespace {

// Each hemisphere is a disc of this radius in rows (twice in columns).
constexpr int kRadius = 5;
constexpr int kBarWidth = 30;
constexpr size_t kLogLines = 6;

std::string Fixed(double v, int digits) {
  char b[64];
  std::snprintf(b, sizeof(b), "%.*f", digits, v);
  return b;
}

std::string Bar(double fraction, int width) {
  const int filled = std::clamp(static_cast<int>(std::lround(fraction * width)), 0, width);
  return std::string(filled, '#') + std::string(width - filled, '.');
}

// The two discs side by side, the poses numbered 1-9 then a-z, the
// suggestion as '*'.
std::vector<std::string> Hemispheres(const RecorderStatus& s) {
  const int w = 4 * kRadius + 1, h = 2 * kRadius + 1, gap = 6;
  std::vector<std::string> grid(h, std::string(2 * w + gap, ' '));
  for (int half = 0; half < 2; ++half) {
    const int x0 = half * (w + gap);
    for (int r = 0; r < h; ++r) {
      for (int c = 0; c < w; ++c) {
        const double x = (c - 2 * kRadius) / (2.0 * kRadius), y = (kRadius - r) / double(kRadius);
        const double d = std::hypot(x, y);
        if (d <= 1.0) grid[r][x0 + c] = (r == kRadius || c == 2 * kRadius) ? '+' : '.';
        if (std::abs(d - 1.0) < 0.12) grid[r][x0 + c] = 'o';
      }
    }
  }
  auto put = [&](const Eigen::Vector3d& given, char mark) {
    const Eigen::Vector3d d = given.normalized();
    if (!d.allFinite()) return;
    const int half = d.z() >= 0 ? 0 : 1;
    const double rho = std::sqrt(std::max(0.0, 1.0 - std::abs(d.z())));
    const double planar = std::hypot(d.x(), d.y());
    const double ux = planar > 1e-12 ? d.x() / planar : 0.0;
    const double uy = planar > 1e-12 ? d.y() / planar : 0.0;
    const int c = static_cast<int>(std::lround(2 * kRadius + 2 * kRadius * rho * ux));
    const int r = static_cast<int>(std::lround(kRadius - kRadius * rho * uy));
    grid[std::clamp(r, 0, h - 1)][half * (w + gap) + std::clamp(c, 0, w - 1)] = mark;
  };
  for (size_t k = 0; k < s.poses.size(); ++k) {
    const char mark =
        k < 9 ? static_cast<char>('1' + k) : (k < 35 ? static_cast<char>('a' + k - 9) : '#');
    put(s.poses[k], mark);
  }
  if (s.has_suggestion) put(s.suggestion.up, '*');
  return grid;
}

}  // namespace

std::string RenderRecordScreen(const RecorderStatus& s, bool stalled,
                               const std::deque<std::string>& log) {
  std::ostringstream o;
  o << "gravcal record   " << Fixed(s.sample_rate, 1) << " Hz   t " << Fixed(s.stream_seconds, 1)
    << " s   samples " << s.samples << "   poses " << s.poses.size();
  if (s.plan_poses > 0) o << " (plan: " << s.plan_poses << ")";
  o << "   garbage lines " << s.garbage_lines << "\n";
  if (stalled) {
    o << "state: NO DATA\n";
  } else if (s.done) {
    o << "state: DONE (" << s.done_reason << ")\n";
  } else if (s.holding) {
    const double need = std::max(s.hold_needed_seconds, 1e-9);
    o << "state: HOLDING [" << Bar(s.hold_seconds / need, kBarWidth) << "] "
      << Fixed(s.hold_seconds, 1) << " / " << Fixed(s.hold_needed_seconds, 1) << " s\n";
  } else {
    o << "state: MOVING (or settling)\n";
  }
  o << "\n  z >= 0 (seen from +z)       z < 0 (seen through)     +x right, +y up, * next\n";
  for (const std::string& line : Hemispheres(s)) o << "  " << line << "\n";
  o << "\nsigma / target (bar full = target met; undetermined: ?)\n";
  for (size_t i = 0; i < s.names.size(); ++i) {
    const double sigma = s.sigma[i], target = s.target[i];
    char name[16];
    std::snprintf(name, sizeof(name), "%-7s", s.names[i].c_str());
    o << "  " << name << " ";
    if (!std::isfinite(sigma)) {
      o << "[" << std::string(kBarWidth, '?') << "] undetermined";
    } else if (std::isfinite(target)) {
      o << "[" << Bar(std::min(1.0, target / sigma), kBarWidth) << "] " << Fixed(sigma, 3) << " "
        << s.units[i] << " / " << Fixed(target, 3) << (sigma <= target ? "  met" : "");
    } else {
      o << "[" << std::string(kBarWidth, ' ') << "] " << Fixed(sigma, 3) << " " << s.units[i];
    }
    o << "\n";
  }
  o << "\nnext: ";
  if (s.has_suggestion) {
    o << s.suggestion.instruction << ", hold " << Fixed(s.suggestion.hold_seconds, 0) << " s";
  } else {
    o << (s.done ? "nothing: done" : "-");
  }
  o << "\n\nwarnings:\n";
  const size_t first = s.warnings.size() > 3 ? s.warnings.size() - 3 : 0;
  for (size_t i = first; i < s.warnings.size(); ++i) o << "  " << s.warnings[i] << "\n";
  o << "\nevents:\n";
  for (const std::string& line : log) o << "  " << line << "\n";
  return o.str();
}

void RecordTui::Begin(bool active) {
  active_ = active;
  if (!active_) return;
  std::fputs("\x1b[?25l\x1b[2J", stderr);
}

void RecordTui::Log(const std::string& text) {
  if (!active_) return;
  log_.push_back(text);
  while (log_.size() > kLogLines) log_.pop_front();
}

void RecordTui::Draw(const RecorderStatus& status, bool stalled) {
  if (!active_) return;
  const auto now = std::chrono::steady_clock::now();
  last_status_ = status;
  if (drawn_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
  drawn_ = true;
  last_draw_ = now;
  std::string screen = RenderRecordScreen(status, stalled, log_);
  // Each line cleared to its end.
  std::string out = "\x1b[H";
  size_t at = 0;
  while (at < screen.size()) {
    const size_t end = screen.find('\n', at);
    out += screen.substr(at, end - at) + "\x1b[K\n";
    at = end == std::string::npos ? screen.size() : end + 1;
  }
  out += "\x1b[J";
  std::fputs(out.c_str(), stderr);
  std::fflush(stderr);
}

void RecordTui::End() {
  if (!active_) return;
  drawn_ = false;
  Draw(last_status_, false);
  std::fputs("\x1b[?25h", stderr);
  std::fflush(stderr);
}

}  // namespace cli
}  // namespace gravcal
