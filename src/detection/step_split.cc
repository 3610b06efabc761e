// Splitting at steps in the accelerometer level (static_detector.h): a
// still run whose level jumps between two holds (SplitRunsAtSteps), and an
// interval whose spread says it is not one pose (SplitOrFlagSpread)
// (detection/static_detector_internal.h).
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "detection/static_detector_internal.h"
#include "util/units.h"

namespace gravcal {
namespace internal {
namespace {

// The line fitted to every window of w samples of one run (window j: the
// run's samples [j, j + w)), from prefix sums over the run of x - r,
// j (x - r) and |x - r|^2 per axis, j the sample's index in the run and r
// its first sample (small magnitudes: no cancellation with raw counts).
// SplitRunAtSteps compares the windows either side of each sample, at every
// level of its recursion: each window's mean and variance are computed once,
// here, and its line (Fit) only where the means differ enough to matter.
// Axis by axis, the same operations as on Eigen vectors: the same bits.
struct WindowLines {
  struct Window {
    // The window's mean; the variance about it, summed over the axes.
    Eigen::Vector3d mean;
    double variance;
  };
  struct Line {
    // The line's slope per sample; the residual variance about the line,
    // summed over the axes.
    Eigen::Vector3d slope;
    double residual;
  };
  std::vector<Window> windows;
  double mean_j;  // the window's mean local position
  double len, sjj;
  // Per sample j the prefix sums s0, s1, s2 (3 axes each), at 9 j.
  std::unique_ptr<double[]> prefix;

  WindowLines(const std::vector<Eigen::Vector3d>& x, size_t begin, size_t end, size_t w) {
    const size_t n = end - begin;
    prefix.reset(new double[9 * (n + 1)]);
    double* const ps = prefix.get();
    std::fill(ps, ps + 9, 0.0);
    const double* const xs = x[begin].data();  // contiguous: 3 doubles per sample
    const double r[3] = {xs[0], xs[1], xs[2]};
    for (size_t j = 0; j < n; ++j) {
      const double* const q = ps + 9 * j;
      double* const o = ps + 9 * (j + 1);
      const double jd = static_cast<double>(j);
      for (int c = 0; c < 3; ++c) {
        const double d = xs[3 * j + c] - r[c];
        o[c] = q[c] + d;
        o[3 + c] = q[3 + c] + jd * d;
        o[6 + c] = q[6 + c] + d * d;
      }
    }
    len = static_cast<double>(w);
    mean_j = 0.5 * (len - 1.0);
    sjj = len * (len * len - 1.0) / 12.0;
    const double variance_dof = std::max(len - 1.0, 1.0);
    windows.resize(n - w + 1);
    for (size_t a = 0; a + w <= n; ++a) {
      const double* const lo = ps + 9 * a;
      const double* const hi = ps + 9 * (a + w);
      Window& window = windows[a];
      double spread[3];
      for (int c = 0; c < 3; ++c) {
        const double sx = hi[c] - lo[c];
        window.mean[c] = sx / len;
        spread[c] = hi[6 + c] - lo[6 + c] - sx * sx / len;
      }
      window.variance = std::max(spread[0] + spread[1] + spread[2], 0.0) / variance_dof;
    }
  }
  // The line of window a.
  Line Fit(size_t a) const {
    const size_t w = static_cast<size_t>(len);
    const double* const lo = prefix.get() + 9 * a;
    const double* const hi = prefix.get() + 9 * (a + w);
    const double ad = static_cast<double>(a);
    Line line;
    double rss[3];
    for (int c = 0; c < 3; ++c) {
      const double sx = hi[c] - lo[c];
      const double sjx = hi[3 + c] - lo[3 + c] - ad * sx;
      const double sxx = hi[6 + c] - lo[6 + c];
      const double slope = (sjx - mean_j * sx) / sjj;
      line.slope[c] = slope;
      rss[c] = sxx - sx * sx / len - slope * slope * sjj;
    }
    line.residual = std::max(rss[0] + rss[1] + rss[2], 0.0) / std::max(len - 2.0, 1.0);
    return line;
  }
  // The line of window a at local position t (0 = its first sample).
  Eigen::Vector3d Value(size_t a, const Line& line, double t) const {
    return windows[a].mean + line.slope * (t - mean_j);
  }
};

// Splits the still run [begin, end) at steps in the level of `x` (top of
// static_detector.h): lines on the w samples either side of each sample,
// the step statistic T, recursively at its maximum while it is above
// step_factor and the levels are step_min_deg apart (the accelerometer) or,
// with min_change2 > 0 (the gyroscope, whose still level is near zero and
// has no direction), |b - a|^2 >= min_change2 apart. `floor` (the noise
// floor, summed over the axes) bounds the residual variances from below
// (quantised data can fit a line exactly). Appends the parts.
void SplitRunAtSteps(const std::vector<Eigen::Vector3d>& x, const WindowLines& fits, size_t base,
                     size_t begin, size_t end, size_t w, double floor, double min_change2,
                     const StaticDetectorOptions& options, std::vector<QuietRun>* parts) {
  if (end - begin < 2 * w) {
    parts->push_back({begin, end});
    return;
  }
  const double len = static_cast<double>(w);
  const double c = (4.0 * len - 2.0) / (len * (len + 1.0));
  const double min_cos = std::cos(options.step_min_deg * internal::kDegToRad);
  const Eigen::Vector3d r = x[base];
  double best = options.step_factor;
  size_t split = 0;
  for (size_t s = begin + w; s + w <= end; ++s) {
    const size_t a_before = s - w - base, a_after = s - base;
    const WindowLines::Window& before = fits.windows[a_before];
    const WindowLines::Window& after = fits.windows[a_after];
    const double t_mean = (after.mean - before.mean).squaredNorm() * len /
                          (std::max(before.variance, floor) + std::max(after.variance, floor));
    // t = min(t_line, t_mean) <= t_mean: not above best (and t_mean not
    // NaN, which std::min would pass over), no need of the lines.
    if (t_mean <= best) continue;
    const WindowLines::Line line_before = fits.Fit(a_before);
    const WindowLines::Line line_after = fits.Fit(a_after);
    const Eigen::Vector3d left = fits.Value(a_before, line_before, len - 0.5);
    const Eigen::Vector3d right = fits.Value(a_after, line_after, -0.5);
    const double t_line =
        (right - left).squaredNorm() /
        (c * (std::max(line_before.residual, floor) + std::max(line_after.residual, floor)));
    const double t = std::min(t_line, t_mean);
    if (!(t > best)) continue;
    const Eigen::Vector3d a = left + r, b = right + r;
    if (min_change2 > 0.0 ? (b - a).squaredNorm() < min_change2
                          : a.dot(b) > min_cos * a.norm() * b.norm()) {
      continue;
    }
    best = t;
    split = s;
  }
  if (split == 0) {
    parts->push_back({begin, end});
    return;
  }
  SplitRunAtSteps(x, fits, base, begin, split, w, floor, min_change2, options, parts);
  SplitRunAtSteps(x, fits, base, split, end, w, floor, min_change2, options, parts);
}

}  // namespace

// Every run split at the steps of `x` (SplitRunAtSteps). Returns the number
// of steps found.
size_t SplitRunsAtSteps(const std::vector<Eigen::Vector3d>& x, size_t w, double floor,
                        double min_change2, const StaticDetectorOptions& options,
                        std::vector<QuietRun>* runs) {
  if (options.step_factor <= 0.0) return 0;
  std::vector<QuietRun> out;
  for (const QuietRun& run : *runs) {
    if (run.end - run.begin < 2 * w) {
      out.push_back(run);
      continue;
    }
    const WindowLines fits(x, run.begin, run.end, w);
    SplitRunAtSteps(x, fits, run.begin, run.begin, run.end, w, floor, min_change2, options, &out);
  }
  const size_t steps = out.size() - runs->size();
  *runs = std::move(out);
  return steps;
}

namespace {

// Splits samples [begin, end) at steps in the accelerometer mean until every
// part's variance (summed over the axes) is within `max_var`: at the split
// point s maximising n1 n2 / n |m1 - m2|^2 (the between-part sum of squares).
// Parts shorter than min_count are dropped (the few samples a run reaches
// across a step). Appends the parts' [begin, end) to *parts and returns
// true, or returns false (and *parts is unspecified) when a part above
// max_var cannot be split into parts within it: a drift, not steps.
bool SplitAtSteps(const ImuLog& log, size_t begin, size_t end, double max_var, size_t min_count,
                  std::vector<QuietRun>* parts) {
  if (end - begin < min_count) return true;
  const StaticInterval whole = MakeInterval(log, begin, end);
  if (whole.accel_cov.trace() <= max_var) {
    parts->push_back({begin, end});
    return true;
  }
  if (end - begin < 2) return false;
  // Prefix sums of deviations from the first sample.
  const Eigen::Vector3d r = log.accel[begin];
  std::vector<Eigen::Vector3d> prefix(end - begin + 1, Eigen::Vector3d::Zero());
  for (size_t i = begin; i < end; ++i) prefix[i - begin + 1] = prefix[i - begin] + log.accel[i] - r;
  const double n = static_cast<double>(end - begin);
  double best = -1.0;
  size_t split = begin + 1;
  for (size_t s = begin + 1; s < end; ++s) {
    const double n1 = static_cast<double>(s - begin);
    const double n2 = n - n1;
    const Eigen::Vector3d m1 = prefix[s - begin] / n1;
    const Eigen::Vector3d m2 = (prefix.back() - prefix[s - begin]) / n2;
    const double between = n1 * n2 / n * (m2 - m1).squaredNorm();
    if (between > best) {
      best = between;
      split = s;
    }
  }
  // A split that leaves no part long enough cannot bring this part within.
  if (split - begin < min_count && end - split < min_count) return false;
  return SplitAtSteps(log, begin, split, max_var, min_count, parts) &&
         SplitAtSteps(log, split, end, max_var, min_count, parts);
}

}  // namespace

// Each interval whose variance is above spread_factor times the noise floor
// is split at its steps (SplitAtSteps) or, when it cannot be, kept and named
// in detection->warnings. Returns the number of intervals split.
size_t SplitOrFlagSpread(const ImuLog& log, size_t min_count, const StaticDetectorOptions& options,
                         StaticDetection* detection) {
  if (options.spread_factor <= 0.0) return 0;
  const double max_var = options.spread_factor * detection->accel_noise_floor;
  std::vector<StaticInterval> out;
  size_t split = 0;
  for (const StaticInterval& s : detection->intervals) {
    const double spread = s.accel_cov.trace();
    if (spread <= max_var) {
      out.push_back(s);
      continue;
    }
    std::vector<QuietRun> parts;
    if (SplitAtSteps(log, s.begin, s.end, max_var, min_count, &parts)) {
      for (const QuietRun& p : parts) out.push_back(MakeInterval(log, p.begin, p.end));
      ++split;
      continue;
    }
    out.push_back(s);
    detection->warnings.push_back(
        "the position at t " + DetectorNumber(s.t_begin) + "-" + DetectorNumber(s.t_end) +
        " s (samples " + std::to_string(s.begin) + "-" + std::to_string(s.end) +
        ") is not one still pose: its " + "spread is " +
        DetectorNumber(std::sqrt(spread / detection->accel_noise_floor)) +
        " times the noise (standard deviations) and it is no set of steps between still "
        "levels: a slow motion or drift; hold the pose still, or drop it");
  }
  detection->intervals = std::move(out);
  return split;
}

}  // namespace internal
}  // namespace gravcal
