// estimation/design_search.h (private): what the two files of the
// experiment design share. experiment_design.cc holds the information of a
// design (the model's rows, predicted standard deviations, evaluation);
// design_search.cc searches for poses and holds (DesignPoses, ShortestHold).
#ifndef GRAVCAL_SRC_ESTIMATION_DESIGN_SEARCH_H_
#define GRAVCAL_SRC_ESTIMATION_DESIGN_SEARCH_H_

#include <Eigen/Core>
#include <vector>

#include "gravcal/estimation/experiment_design.h"

namespace gravcal {
namespace internal {

// Unwhitened scale-free rows of the candidates (sigma 1), via the
// refinement's own Jacobian at the nominal sensor.
Eigen::MatrixXd UnitRows(const std::vector<Eigen::Vector3d>& ups, const DesignModel& model);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_DESIGN_SEARCH_H_
