#include "estimation/robust_loss.h"

namespace gravcal {
namespace internal {

ceres::LossFunction* MakeLoss(LossType type, double scale) {
  switch (type) {
    case LossType::kNone:
      return nullptr;
    case LossType::kHuber:
      return new ceres::HuberLoss(scale);
    case LossType::kCauchy:
      return new ceres::CauchyLoss(scale);
    case LossType::kSoftL1:
      return new ceres::SoftLOneLoss(scale);
    case LossType::kArctan:
      return new ceres::ArctanLoss(scale);
    case LossType::kTukey:
      return new ceres::TukeyLoss(scale);
  }
  return nullptr;
}

std::vector<double> GraduatedLossScales(LossType type, double loss_scale, double largest_whitened) {
  std::vector<double> scales = {loss_scale};
  if (type == LossType::kNone) return scales;
  while (scales.back() * 2.0 < largest_whitened) scales.push_back(scales.back() * 2.0);
  return scales;
}

}  // namespace internal
}  // namespace gravcal
