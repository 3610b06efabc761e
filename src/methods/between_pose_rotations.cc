#include "methods/between_pose_rotations.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "estimation/solver_settings.h"
#include "methods/direction_noise.h"
#include "methods/gyro_initial_matrix.h"
#include "methods/gyro_rotations.h"
#include "util/so3.h"

namespace gravcal {

int AddBetweenPoseTurns(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                        std::vector<StaticObservation>* observations, double edge_seconds,
                        double max_turn_seconds) {
  if (observations->size() != intervals.size()) return 0;
  for (size_t k = 0; k < intervals.size(); ++k) {
    (*observations)[k].session_index = static_cast<int>(k);
  }
  if (!log.has_gyro()) return 0;
  // Samples of edge_seconds (at most a quarter of the interval).
  auto edge = [&](const StaticInterval& s) {
    if (s.end < s.begin + 2) return size_t{0};
    const double dt =
        (log.t[s.end - 1] - log.t[s.begin]) / static_cast<double>(s.end - 1 - s.begin);
    const double samples = dt > 0.0 ? std::max(0.0, edge_seconds) / dt : 0.0;
    return std::min<size_t>(static_cast<size_t>(std::lround(samples)), s.count() / 4);
  };
  int added = 0;
  for (size_t k = 1; k < intervals.size(); ++k) {
    const StaticInterval& before = intervals[k - 1];
    const StaticInterval& after = intervals[k];
    if (before.end < before.begin + 2 || before.end > after.begin || after.begin >= after.end ||
        after.end > log.size()) {
      continue;
    }
    const size_t first = before.end - 1 - edge(before);
    const size_t last = after.begin + edge(after);
    if (!(log.t[last] - log.t[first] <= max_turn_seconds)) continue;
    StaticObservation& o = (*observations)[k];
    o.has_turn = true;
    o.turn_t.assign(log.t.begin() + first, log.t.begin() + last + 1);
    o.turn_gyro.assign(log.gyro.begin() + first, log.gyro.begin() + last + 1);
    o.turn_accel.assign(log.accel.begin() + first, log.accel.begin() + last + 1);
    ++added;
  }
  return added;
}

namespace internal {
namespace {

Eigen::Matrix3d UpperMatrix(const double* u) {
  Eigen::Matrix3d m;
  m << u[0], u[1], u[2], 0.0, u[3], u[4], 0.0, 0.0, u[5];
  return m;
}

// The pose's mean raw vector in normalised units.
Eigen::Vector3d NormalizedRaw(const Normalization& norm, const Eigen::Vector3d& raw) {
  return (raw - norm.center) / norm.scale;
}

// The corrected accelerometer vector a of a pose (normalised raw v') at
// `accel`; false when the quadratic term has no root.
bool CorrectedForce(const AccelBlocks& accel, const Eigen::Vector3d& v, double temperature_offset,
                    double time_offset, Eigen::Vector3d* a) {
  const double* b = accel.blocks[0];
  Eigen::Vector3d m = UpperMatrix(accel.blocks[1]) * (v - Eigen::Vector3d(b[0], b[1], b[2]));
  const gravcal::AccelBlocks<double> effects(nullptr, nullptr, accel.blocks[2]);
  if (!RemoveAccelEffects<double>(effects.effect, temperature_offset, time_offset, m.data())) {
    return false;
  }
  *a = m;
  return true;
}

// Pooled per-sample covariance of the raw gyroscope over the poses.
bool PooledGyroCovariance(const std::vector<StaticObservation>& observations,
                          Eigen::Matrix3d* pooled) {
  pooled->setZero();
  double weight = 0.0;
  for (const StaticObservation& o : observations) {
    const double n = static_cast<double>(o.accel.sample_count);
    if (!o.has_gyro || n < 2.0) continue;
    *pooled += (n - 1.0) * n * o.gyro_mean_cov;
    weight += n - 1.0;
  }
  if (!(weight > 0.0)) return false;
  *pooled /= weight;
  return pooled->allFinite();
}

// The linear initial M_g (raw units) from the turns, with the calibrated
// force of the accelerometer at `accel` along each.
bool InitialGyroMatrix(const std::vector<StaticObservation>& observations,
                       const std::vector<std::pair<int, int>>& poses, const Normalization& norm,
                       const AccelBlocks& accel, const Eigen::Vector3d& center, Eigen::Matrix3d* m0,
                       std::string* error) {
  ImuLog log;
  std::vector<GyroSegment> segments;
  std::vector<std::vector<Eigen::Vector3d>> forces;
  const double* b = accel.blocks[0];
  const Eigen::Matrix3d u = UpperMatrix(accel.blocks[1]);
  for (const auto& pair : poses) {
    const StaticObservation& o = observations[pair.second];
    GyroSegment seg;
    seg.from = pair.first;
    seg.to = pair.second;
    seg.first = log.t.size();
    std::vector<Eigen::Vector3d> f;
    for (size_t i = 0; i < o.turn_t.size(); ++i) {
      log.t.push_back(o.turn_t[i]);
      log.gyro.push_back(o.turn_gyro[i]);
      log.accel.push_back(o.turn_accel[i]);
      f.push_back(u * (NormalizedRaw(norm, o.turn_accel[i]) - Eigen::Vector3d(b[0], b[1], b[2])));
    }
    seg.last = log.t.size() - 1;
    segments.push_back(seg);
    forces.push_back(f);
  }
  return GyroInitialMatrix(log, segments, forces, center, GyroParameterization::kFull, m0, error);
}

// Weighs every row at the current gyroscope (rows->gyro_*) and `accel`.
bool WeighRows(const std::vector<StaticObservation>& observations, const Normalization& norm,
               const AccelBlocks& accel, double extra_variance, double gyro_bias_variance,
               const Eigen::Matrix3d& sample_cov, RotationRows* rows, std::string* error) {
  const Eigen::Matrix3d m =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(rows->gyro_matrix);
  // Per-sample covariance of the rate, rad/s.
  const Eigen::Matrix3d rate_cov = m * sample_cov * rows->scale * rows->scale * m.transpose();
  const Eigen::Matrix3d upper = UpperMatrix(accel.blocks[1]);
  for (size_t j = 0; j < rows->data.size(); ++j) {
    AccelRotationData& d = rows->data[j];
    const StaticObservation& from = observations[rows->poses[j].first];
    const StaticObservation& to = observations[rows->poses[j].second];
    Eigen::Vector3d a_s, a_e;
    if (!CorrectedForce(accel, d.start_raw, d.start_temperature_offset, d.start_time_offset,
                        &a_s) ||
        !CorrectedForce(accel, d.end_raw, d.end_temperature_offset, d.end_time_offset, &a_e)) {
      *error = "the accelerometer model has no value at a pose";
      return false;
    }
    const Eigen::Vector3d d_s = a_s.normalized();
    const Eigen::Vector3d d_e = a_e.normalized();
    d.tangent = TangentBasis(d_e);

    const GyroRotationData& turn = d.turn;
    const size_t n = turn.t.size();
    std::vector<double> path(4 * n);
    double dq[4];
    double key[21];
    GyroTurnKey<double>(rows->gyro_bias, rows->gyro_matrix, nullptr, key);
    d.turn_cache->Evaluate(turn, key, false, dq, nullptr, path.data());
    const Eigen::Matrix3d rn = RotationOf(dq);
    Eigen::Matrix3d white = Eigen::Matrix3d::Zero();
    Eigen::Matrix3d shared = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < n; ++i) {
      const double before = i > 0 ? turn.t[i] - turn.t[i - 1] : 0.0;
      const double after = i + 1 < n ? turn.t[i + 1] - turn.t[i] : 0.0;
      const double c = 0.5 * (before + after);
      const Eigen::Matrix3d ri = rn.transpose() * RotationOf(&path[4 * i]);
      white += c * c * ri * rate_cov * ri.transpose();
      shared += c * ri;
    }
    // The local level's noise (the two static means, averaged) and the
    // bias's wander, both constant over the turn.
    const Eigen::Matrix3d level_cov = m * (0.25 * (from.gyro_mean_cov + to.gyro_mean_cov)) *
                                      rows->scale * rows->scale * m.transpose();
    const Eigen::Matrix3d angle_cov =
        white + shared * (level_cov + gyro_bias_variance * Eigen::Matrix3d::Identity()) *
                    shared.transpose();
    const Eigen::Matrix3d px = Skew(rn.transpose() * d_s);
    // The poses' direction noise: the mean's covariance and the extra
    // variance, both through the same projection.
    auto direction_cov = [&](const StaticObservation& o, const Eigen::Vector3d& a) {
      const Eigen::Vector3d u = a.normalized();
      const Eigen::Matrix3d p = (Eigen::Matrix3d::Identity() - u * u.transpose()) / a.norm();
      const Eigen::Matrix3d raw_cov = o.accel.raw_mean_cov / (norm.scale * norm.scale);
      return Eigen::Matrix3d(
          p * (upper * raw_cov * upper.transpose() + extra_variance * Eigen::Matrix3d::Identity()) *
          p.transpose());
    };
    const Eigen::Matrix3d cov = direction_cov(to, a_e) +
                                rn.transpose() * direction_cov(from, a_s) * rn +
                                px * angle_cov * px.transpose();
    const Eigen::Matrix2d cov2 = d.tangent * cov * d.tangent.transpose();
    if (!SqrtInformation<2>(cov2, &d.sqrt_information)) {
      std::ostringstream s;
      s << "the turn into pose " << rows->poses[j].second << " has no usable noise estimate";
      *error = s.str();
      return false;
    }
  }
  return true;
}

// Fits b_g' and M_g' to the rows with the accelerometer held.
void FitGyroAlone(const AccelBlocks& accel, const SolverTolerances& solver, RotationRows* rows) {
  double held[3][kAccelEffectParameters > 6 ? kAccelEffectParameters : 6];
  const int sizes[3] = {3, 6, kAccelEffectParameters};
  for (int b = 0; b < 3; ++b) std::copy(accel.blocks[b], accel.blocks[b] + sizes[b], held[b]);
  ceres::Problem problem;
  for (const AccelRotationData& d : rows->data) {
    problem.AddResidualBlock(AccelRotationResidual::Create(d), nullptr, held[0], held[1], held[2],
                             rows->gyro_bias, rows->gyro_matrix);
  }
  for (int b = 0; b < 3; ++b) problem.SetParameterBlockConstant(held[b]);
  ceres::Solver::Summary summary;
  ceres::Solve(SolverOptions(solver, ceres::DENSE_QR), &problem, &summary);
}

}  // namespace

std::vector<std::pair<int, int>> TurnPairs(const std::vector<StaticObservation>& observations) {
  std::vector<std::pair<int, int>> pairs;
  for (size_t k = 0; k < observations.size(); ++k) {
    const StaticObservation& o = observations[k];
    if (!o.has_turn || !o.has_gyro || o.session_index < 1 || o.turn_t.size() < 2 ||
        o.turn_gyro.size() != o.turn_t.size() || o.turn_accel.size() != o.turn_t.size()) {
      continue;
    }
    for (size_t j = 0; j < observations.size(); ++j) {
      if (observations[j].session_index == o.session_index - 1 && observations[j].has_gyro) {
        pairs.emplace_back(static_cast<int>(j), static_cast<int>(k));
        break;
      }
    }
  }
  return pairs;
}

bool PrepareRotationRows(const std::vector<StaticObservation>& observations,
                         const Normalization& norm, const EffectParameters& parameters,
                         const AccelBlocks& accel, double extra_variance, double gyro_bias_variance,
                         const SolverTolerances& solver, RotationRows* rows, std::string* error) {
  *rows = RotationRows();
  rows->poses = TurnPairs(observations);
  if (static_cast<int>(rows->poses.size()) < kMinRotations) {
    std::ostringstream s;
    s << "rotations between poses not used: " << rows->poses.size()
      << " turns between consecutive poses with a gyroscope, at least " << kMinRotations
      << " needed";
    *error = s.str();
    return false;
  }
  Eigen::Matrix3d sample_cov;
  if (!PooledGyroCovariance(observations, &sample_cov)) {
    *error = "rotations between poses not used: the poses give no gyroscope noise estimate";
    return false;
  }
  double count = 0.0;
  for (const StaticObservation& o : observations) {
    if (!o.has_gyro) continue;
    rows->center += o.gyro_mean;
    count += 1.0;
  }
  rows->center /= count;
  Eigen::Matrix3d m0;
  std::string why;
  if (!InitialGyroMatrix(observations, rows->poses, norm, accel, rows->center, &m0, &why)) {
    *error = "rotations between poses not used: " + why;
    return false;
  }
  rows->scale = std::cbrt(std::fabs(m0.determinant()));
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(rows->gyro_matrix) = m0 / rows->scale;
  for (const auto& pair : rows->poses) {
    const StaticObservation& from = observations[pair.first];
    const StaticObservation& to = observations[pair.second];
    AccelRotationData d;
    d.turn.t = to.turn_t;
    d.turn_cache = std::make_shared<GyroTurnCache>();
    // The turn's rate about the local level at rest, the mean of the two
    // poses' static means (rows->gyro_bias is a common correction to it).
    const Eigen::Vector3d level = 0.5 * (from.gyro_mean + to.gyro_mean);
    for (const Eigen::Vector3d& u : to.turn_gyro) {
      d.turn.gyro.push_back((u - level) * rows->scale);
    }
    d.start_raw = NormalizedRaw(norm, from.accel.raw_mean);
    d.end_raw = NormalizedRaw(norm, to.accel.raw_mean);
    d.start_temperature_offset = TemperatureOffset(parameters, from.temperature());
    d.end_temperature_offset = TemperatureOffset(parameters, to.temperature());
    d.start_time_offset = from.time() - parameters.reference_time;
    d.end_time_offset = to.time() - parameters.reference_time;
    rows->data.push_back(std::move(d));
  }
  // Weigh at the start, fit the gyroscope alone, weigh again there.
  if (!WeighRows(observations, norm, accel, extra_variance, gyro_bias_variance, sample_cov, rows,
                 error)) {
    return false;
  }
  FitGyroAlone(accel, solver, rows);
  return WeighRows(observations, norm, accel, extra_variance, gyro_bias_variance, sample_cov, rows,
                   error);
}

}  // namespace internal
}  // namespace gravcal
