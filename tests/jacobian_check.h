// A cost function's Jacobian against central differences, block by block:
// the check every autodiff residual's test makes.
#ifndef GRAVCAL_TESTS_JACOBIAN_CHECK_H_
#define GRAVCAL_TESTS_JACOBIAN_CHECK_H_

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace gravcal {
namespace testing_util {

// params[b] has sizes[b] entries, perturbed by +-steps[b]; each entry of
// the analytic Jacobian must match within relative_tolerance (absolute
// below 1). *jacobians receives the analytic Jacobian, row-major per block.
inline void ExpectJacobianMatchesCentralDifferences(const ceres::CostFunction& cost,
                                                    const std::vector<double*>& params,
                                                    const std::vector<int>& sizes,
                                                    const std::vector<double>& steps,
                                                    double relative_tolerance,
                                                    std::vector<std::vector<double>>* jacobians) {
  const int rows = cost.num_residuals();
  std::vector<double> r(rows), rp(rows), rm(rows);
  jacobians->assign(params.size(), {});
  std::vector<double*> pointers;
  for (size_t b = 0; b < params.size(); ++b) {
    (*jacobians)[b].assign(rows * sizes[b], 0.0);
    pointers.push_back((*jacobians)[b].data());
  }
  ASSERT_TRUE(cost.Evaluate(params.data(), r.data(), pointers.data()));
  for (size_t b = 0; b < params.size(); ++b) {
    for (int i = 0; i < sizes[b]; ++i) {
      const double x = params[b][i];
      params[b][i] = x + steps[b];
      cost.Evaluate(params.data(), rp.data(), nullptr);
      params[b][i] = x - steps[b];
      cost.Evaluate(params.data(), rm.data(), nullptr);
      params[b][i] = x;
      for (int row = 0; row < rows; ++row) {
        const double numeric = (rp[row] - rm[row]) / (2.0 * steps[b]);
        const double analytic = (*jacobians)[b][row * sizes[b] + i];
        EXPECT_NEAR(analytic, numeric, relative_tolerance * std::max(1.0, std::fabs(analytic)))
            << "block " << b << " entry " << i << " row " << row;
      }
    }
  }
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_JACOBIAN_CHECK_H_
