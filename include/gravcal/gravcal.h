// gravcal/gravcal.h: the whole public API of gravcal in one include.
#ifndef GRAVCAL_GRAVCAL_H_
#define GRAVCAL_GRAVCAL_H_

#include "gravcal/accel_model.h"
#include "gravcal/calibration.h"
#include "gravcal/calibration_io.h"
#include "gravcal/coarse_fit.h"
#include "gravcal/config.h"
#include "gravcal/discovery.h"
#include "gravcal/discovery_report.h"
#include "gravcal/effect_fit.h"
#include "gravcal/gravity.h"
#include "gravcal/gravity_magnitude_residual.h"
#include "gravcal/gyro_model.h"
#include "gravcal/housing_rotation.h"
#include "gravcal/imu_log.h"
#include "gravcal/log_reader.h"
#include "gravcal/model_effects.h"
#include "gravcal/newton_solver.h"
#include "gravcal/observability.h"
#include "gravcal/pipeline.h"
#include "gravcal/position.h"
#include "gravcal/refinement.h"
#include "gravcal/simulator.h"
#include "gravcal/static_detector.h"

#endif  // GRAVCAL_GRAVCAL_H_
