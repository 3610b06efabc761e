#include "workflows/discovery_localisation.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <sstream>

#include "util/statistics.h"

namespace gravcal {
namespace internal {
namespace {

// The dominant axis of a position, up or down.
const char* const kAxis[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};

// The raw reading the model predicts for position k: the vector along the
// measured direction whose corrected magnitude is g, mapped back through
// the effects and U.
Eigen::Vector3d SimulatedAccel(const EffectFitResult& fit, const StaticObservation& o,
                               const Eigen::Vector3d& force, double gravity) {
  const Eigen::Vector3d s = gravity * force.normalized();
  EffectParameters p;
  p.reference_temperature = fit.parameters.reference_temperature;
  p.reference_time = fit.parameters.reference_time;
  for (Effect e : fit.effects) {
    if (Info(e).sensor != EffectSensor::kAccelerometer) continue;
    p.SetValues(e, fit.parameters.Values(e));
  }
  const Eigen::Vector3d m = ApplyAccelEffects(p, s, o.temperature(), o.time());
  return fit.accel.upper.inverse() * m + fit.accel.bias;
}

// Adds the group of the positions k for which in(k) holds, unless empty.
void AddGroup(const std::string& by, const std::string& name,
              const std::vector<PositionDisagreement>& p, bool has_gyro,
              const std::function<bool(size_t)>& in, std::vector<GroupDisagreement>* groups) {
  GroupDisagreement g;
  g.by = by;
  g.group = name;
  double sa = 0.0, sg = 0.0;
  for (size_t k = 0; k < p.size(); ++k) {
    if (!in(k)) continue;
    ++g.count;
    sa += p[k].accel_z * p[k].accel_z;
    sg += p[k].gyro_z.squaredNorm();
  }
  if (g.count == 0) return;
  g.accel_sigma = std::sqrt(sa / g.count);
  if (has_gyro) g.gyro_sigma = std::sqrt(sg / (3.0 * g.count));
  groups->push_back(g);
}

// Groups positions into `bins` equal stretches of a value.
void AddBinnedGroups(const std::string& by, const std::string& unit, const char* format,
                     const std::vector<double>& value, const std::vector<PositionDisagreement>& p,
                     bool has_gyro, int bins, std::vector<GroupDisagreement>* groups) {
  const double lo = *std::min_element(value.begin(), value.end());
  const double hi = *std::max_element(value.begin(), value.end());
  if (!(hi > lo)) return;
  for (int b = 0; b < bins; ++b) {
    const double from = lo + (hi - lo) * b / bins;
    const double to = lo + (hi - lo) * (b + 1) / bins;
    AddGroup(
        by, FormatNumber(format, from) + " to " + FormatNumber(format, to) + " " + unit, p,
        has_gyro, [&](size_t k) { return value[k] >= from && (value[k] < to || b == bins - 1); },
        groups);
  }
}

// Groups: dominant axis, specific-force level on it, time, temperature.
void AddGroups(const DiscoveryContext& ctx, Disagreement* disagreement) {
  Disagreement& d = *disagreement;
  for (const char* axis : kAxis) {
    AddGroup(
        "axis", axis, d.positions, ctx.has_gyro,
        [&](size_t k) { return d.positions[k].axis == axis; }, &d.groups);
  }
  AddGroup(
      "force_level", "axis-aligned (over 0.9 g on one axis)", d.positions, ctx.has_gyro,
      [&](size_t k) { return d.positions[k].axis_level > 0.9; }, &d.groups);
  AddGroup(
      "force_level", "between axes (0.9 g or less)", d.positions, ctx.has_gyro,
      [&](size_t k) { return d.positions[k].axis_level <= 0.9; }, &d.groups);
  std::vector<double> times, temperatures;
  for (const PositionDisagreement& p : d.positions) {
    times.push_back(p.time);
    temperatures.push_back(p.temperature);
  }
  AddBinnedGroups("time", "s", "%.0f", times, d.positions, ctx.has_gyro, 3, &d.groups);
  if (ctx.has_temperature) {
    AddBinnedGroups("temperature", "degC", "%.1f", temperatures, d.positions, ctx.has_gyro, 3,
                    &d.groups);
  }
}

// The one-line summary: the noise-level rms, chi-square and worst position
// of each sensor.
std::string SummaryLine(const DiscoveryContext& ctx, const Disagreement& d, int n) {
  std::ostringstream s;
  s.precision(3);
  double magnitude_chi2 = 0.0;
  for (const PositionDisagreement& p : d.positions) magnitude_chi2 += p.accel_z * p.accel_z;
  s << "accelerometer |a| - g: " << std::sqrt(magnitude_chi2 / std::max(n, 1))
    << " sigma rms (chi2 " << d.accel_chi2 << " on " << d.accel_dof << " dof, p = " << d.accel_p
    << ")";
  if (!d.worst_accel.empty()) {
    const PositionDisagreement& w = d.positions[d.worst_accel[0]];
    s << ", worst position " << w.index << " (" << w.axis << " up, t = " << w.time << " s, "
      << w.accel_z << " sigma)";
  }
  if (ctx.has_gyro && !d.worst_gyro.empty()) {
    const PositionDisagreement& w = d.positions[d.worst_gyro[0]];
    int axis = 0;
    w.gyro_z.cwiseAbs().maxCoeff(&axis);
    s << "; gyroscope: " << std::sqrt(d.gyro_chi2 / std::max(3 * n, 1)) << " sigma rms (chi2 "
      << d.gyro_chi2 << " on " << d.gyro_dof << " dof, p = " << d.gyro_p << "), worst position "
      << w.index << " (gyro "
      << "xyz"[axis] << " " << w.gyro_z(axis) << " sigma, t = " << w.time << " s)";
  }
  return s.str();
}

}  // namespace

Disagreement Locate(const DiscoveryContext& ctx, const EffectFitResult& fit, int where_count) {
  const std::vector<StaticObservation>& obs = *ctx.observations;
  Disagreement d;
  const int n = static_cast<int>(obs.size());
  for (int k = 0; k < n; ++k) {
    PositionDisagreement p;
    p.index = k;
    p.time = obs[k].time();
    p.temperature = obs[k].temperature();
    const Eigen::Vector3d& a = fit.forces[k];
    int axis = 0;
    a.cwiseAbs().maxCoeff(&axis);
    p.axis = kAxis[2 * axis + (a(axis) < 0.0 ? 1 : 0)];
    p.axis_level = std::fabs(a(axis)) / std::max(a.norm(), 1e-300);
    p.accel_measured = obs[k].accel.raw_mean;
    p.accel_simulated = SimulatedAccel(fit, obs[k], a, ctx.gravity);
    p.accel_residual = fit.accel_residuals[k];
    p.accel_z = p.accel_residual / fit.accel_sigmas[k];
    d.accel_chi2 += p.accel_z * p.accel_z;
    if (ctx.has_gyro && fit.gyro_residuals.size() == obs.size()) {
      p.gyro_measured = obs[k].gyro_mean;
      p.gyro_residual = fit.gyro_residuals[k];
      p.gyro_simulated = p.gyro_measured - p.gyro_residual;
      p.gyro_z = p.gyro_residual.cwiseQuotient(fit.gyro_sigmas[k]);
    }
    d.positions.push_back(p);
  }
  // The within-pose trend rows (when the fit used them) are part of the
  // accelerometer's likelihood and of its dof: chi2 and dof count the same rows.
  d.accel_chi2 += fit.accel_fit.trend_chi2;
  d.accel_dof = fit.accel_fit.dof();
  d.accel_p = ChiSquareUpperTail(d.accel_chi2, d.accel_dof);
  if (ctx.has_gyro && fit.gyro_fit.fitted) {
    d.gyro_chi2 = fit.gyro_fit.chi2;
    d.gyro_dof = fit.gyro_fit.dof();
    d.gyro_p = ChiSquareUpperTail(d.gyro_chi2, d.gyro_dof);
  }

  // Worst positions per sensor.
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return std::fabs(d.positions[a].accel_z) > std::fabs(d.positions[b].accel_z);
  });
  d.worst_accel.assign(order.begin(), order.begin() + std::min(n, where_count));
  if (ctx.has_gyro) {
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return d.positions[a].gyro_z.squaredNorm() > d.positions[b].gyro_z.squaredNorm();
    });
    d.worst_gyro.assign(order.begin(), order.begin() + std::min(n, where_count));
  }

  AddGroups(ctx, &d);
  d.summary = SummaryLine(ctx, d, n);
  return d;
}

}  // namespace internal
}  // namespace gravcal
