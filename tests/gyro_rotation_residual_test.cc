// The turn integrator's Jacobian (IntegrateGyroRotationJacobian), which the
// rotation residuals use for automatic differentiation, against dual numbers
// carried through every sample of IntegrateGyroRotation.
#include "gravcal/residuals/gyro_rotation_residual.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

namespace gravcal {
namespace {

using Dual = ceres::Jet<double, 21>;

// A turn of n samples at 100 Hz: a rate that sweeps its axis (so the coning
// term matters) up to about `peak` rad/s, raw gyroscope units of 1/0.01,
// and a specific force for G.
GyroRotationData Turn(size_t n, double peak, std::mt19937_64* rng) {
  std::normal_distribution<double> noise(0.0, 0.5);
  GyroRotationData d;
  for (size_t k = 0; k < n; ++k) {
    const double t = 0.01 * static_cast<double>(k);
    const double s = std::sin(M_PI * static_cast<double>(k) / static_cast<double>(n));
    d.t.push_back(t);
    d.gyro.push_back(Eigen::Vector3d(std::cos(3.0 * t), std::sin(2.0 * t), 0.5) * peak * s / 0.01 +
                     Eigen::Vector3d(noise(*rng), noise(*rng), noise(*rng)));
    d.force.push_back(Eigen::Vector3d(1.0 + t, -2.0, 9.5 - t));
  }
  return d;
}

// Ceres-style parameters near a calibrated gyroscope: b_g, M_g, G.
void Parameters(std::mt19937_64* rng, double* b, double* m, double* g) {
  std::normal_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 3; ++i) b[i] = 2.0 * unit(*rng);
  for (int i = 0; i < 9; ++i) m[i] = (i % 4 == 0 ? 0.01 : 0.0) + 2e-4 * unit(*rng);
  for (int i = 0; i < 9; ++i) g[i] = 1e-3 * unit(*rng);
}

TEST(GyroTurnJacobian, MatchesDualNumbersThroughEverySample) {
  std::mt19937_64 rng(7);
  for (size_t n : {2u, 3u, 4u, 5u, 9u, 300u}) {
    for (double peak : {0.0, 0.3, 3.0}) {
      for (bool with_g : {false, true}) {
        const GyroRotationData turn = Turn(n, peak, &rng);
        double b[3], m[9], g[9];
        Parameters(&rng, b, m, g);
        Dual db[3], dm[9], dg[9], dual[4];
        for (int i = 0; i < 3; ++i) db[i] = Dual(b[i], i);
        for (int i = 0; i < 9; ++i) dm[i] = Dual(m[i], 3 + i);
        for (int i = 0; i < 9; ++i) dg[i] = Dual(g[i], 12 + i);
        IntegrateGyroRotation<Dual>(turn, db, dm, with_g ? dg : nullptr, dual);
        double plain[4], q[4];
        IntegrateGyroRotation<double>(turn, b, m, with_g ? g : nullptr, plain);
        Eigen::Matrix<double, 4, 21> jacobian;
        IntegrateGyroRotationJacobian(turn, b, m, with_g ? g : nullptr, q, &jacobian);
        for (int k = 0; k < 4; ++k) {
          // The same operations in the same order: the same bits.
          EXPECT_EQ(q[k], plain[k]) << "n " << n << " peak " << peak;
          for (int j = 0; j < 21; ++j) {
            EXPECT_NEAR(jacobian(k, j), dual[k].v[j], 1e-11 * (1.0 + std::fabs(dual[k].v[j])))
                << "n " << n << " peak " << peak << " G " << with_g << " dq[" << k
                << "] / parameter " << j;
          }
        }
      }
    }
  }
}

// The residual's Jacobian (through IntegrateGyroTurn) equals the one of
// dual numbers through every sample, for the blocks (b_g, M_g, G).
TEST(GyroTurnJacobian, ResidualJacobianIsTheDualNumbersOne) {
  std::mt19937_64 rng(11);
  GyroRotationData turn = Turn(200, 2.0, &rng);
  turn.start_direction = Eigen::Vector3d(0.0, 0.6, 0.8);
  turn.end_direction = Eigen::Vector3d(0.8, 0.0, 0.6);
  turn.tangent << 0.6, 0.0, -0.8, 0.0, 1.0, 0.0;
  turn.sqrt_information << 300.0, 10.0, 0.0, 250.0;
  double b[3], m[9], g[9];
  Parameters(&rng, b, m, g);
  std::unique_ptr<ceres::CostFunction> cost(GyroRotationResidual::Create(turn, true, false));
  const double* blocks[3] = {b, m, g};
  double residual[2], jb[6], jm[18], jg[18];
  double* jacobians[3] = {jb, jm, jg};
  ASSERT_TRUE(cost->Evaluate(blocks, residual, jacobians));
  // The same residual with dual numbers through IntegrateGyroRotation.
  Dual db[3], dm[9], dg[9], dq[4];
  for (int i = 0; i < 3; ++i) db[i] = Dual(b[i], i);
  for (int i = 0; i < 9; ++i) dm[i] = Dual(m[i], 3 + i);
  for (int i = 0; i < 9; ++i) dg[i] = Dual(g[i], 12 + i);
  IntegrateGyroRotation<Dual>(turn, db, dm, dg, dq);
  Dual start[3], end[3], expected[2];
  for (int i = 0; i < 3; ++i) {
    start[i] = Dual(turn.start_direction(i));
    end[i] = Dual(turn.end_direction(i));
  }
  WhitenedTurnError<Dual>(dq, start, end, turn.tangent, turn.sqrt_information, expected);
  for (int r = 0; r < 2; ++r) {
    EXPECT_NEAR(residual[r], expected[r].a, 1e-12 * (1.0 + std::fabs(expected[r].a)));
    for (int j = 0; j < 21; ++j) {
      const double got = j < 3 ? jb[3 * r + j] : j < 12 ? jm[9 * r + j - 3] : jg[9 * r + j - 12];
      EXPECT_NEAR(got, expected[r].v[j], 1e-9 * (1.0 + std::fabs(expected[r].v[j])))
          << "r" << r << " parameter " << j;
    }
  }
}

// A turn's cache (what the residuals evaluate through) gives the bits of an
// evaluation from scratch in any order of requests: a plain evaluation, the
// Jacobian at the same parameters (the backward pass alone), the Jacobian at
// new parameters, the path, and a return to earlier parameters; for a turn
// whose forward pass the cache keeps and for one too long to keep.
TEST(GyroTurnCache, GivesTheBitsOfAnEvaluationFromScratch) {
  std::mt19937_64 rng(13);
  for (size_t n : {size_t{300}, GyroTurnCache::kMaxSamples + 1})
    for (bool with_g : {false, true}) {
      const GyroRotationData turn = Turn(n, 2.0, &rng);
      double key[2][21];
      for (double* k : key) Parameters(&rng, k, k + 3, k + 12);
      GyroTurnCache cache;
      // {parameters, Jacobian asked, path asked}.
      const int order[][3] = {{0, 0, 1}, {0, 1, 0}, {0, 1, 0}, {1, 1, 1},
                              {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 1, 1}};
      for (const auto& request : order) {
        const double* k = key[request[0]];
        const double* g = with_g ? k + 12 : nullptr;
        const bool jacobian = request[1] == 1;
        double q[4], expected_q[4];
        std::vector<double> path(4 * turn.t.size()), expected_path(path.size());
        Eigen::Matrix<double, 4, 21> j, expected_j;
        const bool with_path = request[2] == 1;
        cache.Evaluate(turn, k, with_g, q, jacobian ? &j : nullptr,
                       with_path ? path.data() : nullptr);
        IntegrateGyroRotation<double>(turn, k, k + 3, g, expected_q, expected_path.data());
        EXPECT_EQ(std::memcmp(q, expected_q, sizeof(q)), 0) << "n " << n << " G " << with_g;
        if (with_path) {
          EXPECT_EQ(std::memcmp(path.data(), expected_path.data(), path.size() * sizeof(double)),
                    0);
        }
        if (!jacobian) continue;
        IntegrateGyroRotationJacobian(turn, k, k + 3, g, expected_q, &expected_j);
        EXPECT_EQ(std::memcmp(j.data(), expected_j.data(), sizeof(double) * 84), 0)
            << "n " << n << " G " << with_g;
      }
    }
}

}  // namespace
}  // namespace gravcal
