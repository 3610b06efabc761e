// Private: how far a discovery model (discovery.h) is from the data, in the
// sample and predicted by leave-one-position-out cross-validation.
#ifndef GRAVCAL_SRC_WORKFLOWS_DISCOVERY_CROSS_VALIDATION_H_
#define GRAVCAL_SRC_WORKFLOWS_DISCOVERY_CROSS_VALIDATION_H_

#include <Eigen/Core>
#include <vector>

#include "workflows/discovery_context.h"

namespace gravcal {
namespace internal {

// rms of the residuals in physical units and in sigma, from a full fit.
Gap InSampleGap(const EffectFitResult& fit, bool has_gyro);

// Leave-one-position-out prediction of one sensor under `effects`, starting
// every fold from the full fit. Fills the cross-validated gap of that sensor
// and the left-out residuals (either may be null); false when a fold cannot
// be fitted.
bool CrossValidate(const DiscoveryContext& ctx, const std::vector<Effect>& effects,
                   const EffectFitResult& full, EffectSensor sensor, Gap* cv,
                   std::vector<double>* accel_residuals,
                   std::vector<Eigen::Vector3d>* gyro_residuals);

// Fits `effects` fully (both sensors, covariance) and cross-validates the
// sensors in `validate`; the other sensor's cross-validation is copied from
// `previous` (its model did not change).
bool Assess(const DiscoveryContext& ctx, const std::vector<Effect>& effects,
            const EffectFitResult& start, const std::vector<EffectSensor>& validate,
            const ModelAssessment* previous, ModelAssessment* out);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_DISCOVERY_CROSS_VALIDATION_H_
