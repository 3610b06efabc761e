// Private: the set-up shared by gravcal plan and gravcal check
// (workflows/plan.h): the request checked, the design model of the config,
// the targets per parameter, and a sensor's prediction from them.
#ifndef GRAVCAL_SRC_WORKFLOWS_PLAN_START_H_
#define GRAVCAL_SRC_WORKFLOWS_PLAN_START_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/workflows/plan.h"

namespace gravcal {
namespace internal {

// A pose whose up direction lies within this many degrees of a face counts
// as that face (the placement error of a hand; check and record).
constexpr double kFaceSnapDeg = 10.0;

struct PlanStart {
  DesignModel model;
  // MagnitudeParameterNames of the config's parameterisation.
  std::vector<std::string> names;
  // Scale-free targets: the stated ones, else the refinement's limit of a
  // determined parameter (max_bias_std, max_matrix_std); `targeted` marks
  // the stated ones.
  Eigen::VectorXd targets;
  std::vector<bool> targeted;
  // The refinement's limits per parameter (scale-free).
  Eigen::VectorXd limits;
  // The gyroscope: planned when the config calibrates one; its design model,
  // parameter names and targets (scale-free; the stated ones, else the
  // calibration's limits) as above.
  bool gyro_planned = false;
  GyroDesignModel gyro_model;
  std::vector<std::string> gyro_names;
  Eigen::VectorXd gyro_targets;
  std::vector<bool> gyro_targeted;
};

bool StartPlan(const Config& config, const PlanRequest& request, PlanStart* start,
               std::string* error);

// A sensor's prediction from its scale-free standard deviations (the raw
// units' ones at nominal_scale, StdInRawUnits) and its targets.
SensorPrediction Prediction(const std::vector<std::string>& names,
                            const Eigen::VectorXd& std_scale_free, const Eigen::VectorXd& targets,
                            const std::vector<bool>& targeted, double nominal_scale);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_PLAN_START_H_
