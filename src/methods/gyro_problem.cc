#include "methods/gyro_problem.h"

#include <ceres/manifold.h>

#include <algorithm>

#include "estimation/robust_loss.h"
#include "gravcal/residuals/gravity_magnitude_residual.h"
#include "gravcal/residuals/gyro_static_residual.h"

namespace gravcal {
namespace internal {
namespace {

// M = s I, the only free direction of the common-scale model.
class IsotropicScaleManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 9; }
  int TangentSize() const override { return 1; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    for (int i = 0; i < 9; ++i) x_plus_delta[i] = x[i] + (i % 4 == 0 ? delta[0] : 0.0);
    return true;
  }
  bool PlusJacobian(const double* /*x*/, double* jacobian) const override {
    for (int i = 0; i < 9; ++i) jacobian[i] = i % 4 == 0 ? 1.0 : 0.0;
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    y_minus_x[0] = (y[0] - x[0] + y[4] - x[4] + y[8] - x[8]) / 3.0;
    return true;
  }
  bool MinusJacobian(const double* /*x*/, double* jacobian) const override {
    for (int i = 0; i < 9; ++i) jacobian[i] = i % 4 == 0 ? 1.0 / 3.0 : 0.0;
    return true;
  }
};

}  // namespace

GyroLayout::GyroLayout(bool with_g, bool joint) {
  for (int i = 0; i < 3; ++i) names.push_back(std::string("bias_") + kGyroAxisNames[i]);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      names.push_back(std::string("m_") + kGyroAxisNames[r] + kGyroAxisNames[c]);
    }
  }
  if (with_g) {
    g = size;
    size += 9;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        names.push_back(std::string("g_") + kGyroAxisNames[r] + kGyroAxisNames[c]);
      }
    }
  }
  if (joint) {
    accel_bias = size;
    accel_upper = size + 3;
    size += 9;
    for (const std::string& n : MagnitudeParameterNames(AccelParameterization::kAffine)) {
      names.push_back("accel_" + n);
    }
  }
}

GyroFreeColumns MakeGyroFreeColumns(const GyroLayout& layout, GyroParameterization gp,
                                    AccelParameterization ap, const std::vector<bool>& held) {
  std::vector<std::pair<std::string, std::vector<int>>> columns;
  for (int i = 0; i < 3; ++i) columns.push_back({layout.names[i], {i}});
  if (gp == GyroParameterization::kBias) {
    columns.push_back({"scale", {layout.matrix, layout.matrix + 4, layout.matrix + 8}});
  } else {
    for (int i = 0; i < 9; ++i) {
      const int a = layout.matrix + i;
      if ((gp == GyroParameterization::kFull || i % 4 == 0) && !held[a]) {
        columns.push_back({layout.names[a], {a}});
      }
    }
  }
  if (layout.g >= 0) {
    for (int i = 0; i < 9; ++i) {
      if (!held[layout.g + i]) columns.push_back({layout.names[layout.g + i], {layout.g + i}});
    }
  }
  if (layout.accel_bias >= 0) {
    for (int i = 0; i < 3; ++i) {
      columns.push_back({layout.names[layout.accel_bias + i], {layout.accel_bias + i}});
    }
    for (int i : FreeUpperIndices(ap)) {
      columns.push_back({layout.names[layout.accel_upper + i], {layout.accel_upper + i}});
    }
  }
  GyroFreeColumns out;
  out.basis = Eigen::MatrixXd::Zero(layout.size, columns.size());
  for (size_t j = 0; j < columns.size(); ++j) {
    out.names.push_back(columns[j].first);
    for (int a : columns[j].second) out.basis(a, j) = 1.0;
  }
  return out;
}

// The accelerometer at x (joint) or the fixed one.
AccelModel GyroAccelAt(const std::vector<double>& x, const GyroLayout& layout,
                       const AccelModel& accel, const Normalization& norm) {
  if (layout.accel_bias < 0) return accel;
  AccelModel n = norm.Apply(accel);
  n.bias =
      Eigen::Vector3d(x[layout.accel_bias], x[layout.accel_bias + 1], x[layout.accel_bias + 2]);
  n.SetUpper(&x[layout.accel_upper]);
  return norm.Undo(n);
}

void BuildGyroProblem(const GyroPrepared& prep, const GyroLayout& layout,
                      const GyroCalibrationOptions& options, AccelParameterization ap,
                      const std::vector<bool>& held, const GyroWeights& weights,
                      const std::vector<double>& magnitude_sigmas, double gravity,
                      std::vector<double>* x, GyroProblem* built) {
  built->problem = std::make_unique<ceres::Problem>();
  built->blocks.clear();
  built->rows = 0;
  ceres::Problem& problem = *built->problem;
  double* base = x->data();
  const bool with_g = layout.g >= 0;
  const bool joint = layout.accel_bias >= 0;
  std::vector<int> gyro_offsets = {layout.bias, layout.matrix};
  if (with_g) gyro_offsets.push_back(layout.g);
  auto add = [&](ceres::CostFunction* cost, const std::vector<int>& offsets, bool robust) {
    std::vector<double*> blocks;
    for (int o : offsets) blocks.push_back(base + o);
    problem.AddResidualBlock(cost, robust ? MakeLoss(options.loss, options.loss_scale) : nullptr,
                             blocks);
    built->blocks.push_back({cost, offsets});
    built->rows += cost->num_residuals();
  };
  for (size_t k = 0; k < prep.static_gyro.size(); ++k) {
    add(GyroStaticResidual::Create(prep.static_gyro[k], prep.static_force[k],
                                   weights.static_information[k], with_g),
        gyro_offsets, true);
  }
  std::vector<int> rotation_offsets = gyro_offsets;
  if (joint) {
    rotation_offsets.push_back(layout.accel_bias);
    rotation_offsets.push_back(layout.accel_upper);
  }
  for (const GyroRotationData& d : weights.rotations) {
    add(GyroRotationResidual::Create(d, with_g, joint), rotation_offsets, true);
  }
  if (joint) {
    for (size_t k = 0; k < prep.normalized_positions.size(); ++k) {
      add(GravityMagnitudeResidual::Create(prep.normalized_positions[k].raw_mean, gravity,
                                           magnitude_sigmas[k]),
          {layout.accel_bias, layout.accel_upper}, false);
    }
  }

  // Held entries: fixed by the parameterization, or not determined.
  auto hold = [&](int offset, int size, std::vector<int> fixed, ceres::Manifold* manifold) {
    double* block = base + offset;
    for (int i = 0; i < size; ++i) {
      if (held[offset + i] && std::find(fixed.begin(), fixed.end(), i) == fixed.end()) {
        fixed.push_back(i);
      }
    }
    if (static_cast<int>(fixed.size()) == size) {
      problem.SetParameterBlockConstant(block);
      delete manifold;
      return;
    }
    built->free_blocks.push_back(block);
    if (manifold != nullptr) {
      problem.SetManifold(block, manifold);
    } else if (!fixed.empty()) {
      problem.SetManifold(block, new ceres::SubsetManifold(size, fixed));
    }
  };
  built->free_blocks.clear();
  hold(layout.bias, 3, {}, nullptr);
  const GyroParameterization gp = options.parameterization;
  if (gp == GyroParameterization::kBias) {
    hold(layout.matrix, 9, {}, new IsotropicScaleManifold);
  } else if (gp == GyroParameterization::kScale) {
    hold(layout.matrix, 9, {1, 2, 3, 5, 6, 7}, nullptr);
  } else {
    hold(layout.matrix, 9, {}, nullptr);
  }
  if (with_g) hold(layout.g, 9, {}, nullptr);
  if (joint) {
    hold(layout.accel_bias, 3, {}, nullptr);
    if (ap == AccelParameterization::kScale) {
      hold(layout.accel_upper, kUpperSize, {1, 2, 4}, nullptr);
    } else {
      hold(layout.accel_upper, kUpperSize, {}, nullptr);
    }
  }
}

// The whitened Jacobian of all residuals (no loss) with respect to the
// ambient parameters at x.
Eigen::MatrixXd GyroAmbientJacobian(const GyroProblem& built, const GyroLayout& layout,
                                    std::vector<double>* x) {
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(built.rows, layout.size);
  int row = 0;
  for (const GyroProblem::Block& b : built.blocks) {
    const int rows = b.cost->num_residuals();
    const std::vector<int32_t>& sizes = b.cost->parameter_block_sizes();
    std::vector<const double*> parameters;
    std::vector<std::vector<double>> storage(sizes.size());
    std::vector<double*> jacobians;
    for (size_t i = 0; i < sizes.size(); ++i) {
      parameters.push_back(x->data() + b.offsets[i]);
      storage[i].resize(rows * sizes[i]);
      jacobians.push_back(storage[i].data());
    }
    std::vector<double> residuals(rows);
    b.cost->Evaluate(parameters.data(), residuals.data(), jacobians.data());
    for (size_t i = 0; i < sizes.size(); ++i) {
      for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < sizes[i]; ++c) {
          j(row + r, b.offsets[i] + c) = storage[i][r * sizes[i] + c];
        }
      }
    }
    row += rows;
  }
  return j;
}

}  // namespace internal
}  // namespace gravcal
