// gravcal/gravcal.h: the whole public API of gravcal in one include.
#ifndef GRAVCAL_GRAVCAL_H_
#define GRAVCAL_GRAVCAL_H_

#include "gravcal/accel_model.h"
#include "gravcal/calibration.h"
#include "gravcal/calibration_io.h"
#include "gravcal/coarse_fit.h"
#include "gravcal/config.h"
#include "gravcal/gravity.h"
#include "gravcal/gravity_magnitude_residual.h"
#include "gravcal/gyro_model.h"
#include "gravcal/housing_rotation.h"
#include "gravcal/imu_log.h"
#include "gravcal/log_reader.h"
#include "gravcal/newton_solver.h"
#include "gravcal/observability.h"
#include "gravcal/pipeline.h"
#include "gravcal/position.h"
#include "gravcal/refinement.h"
#include "gravcal/simulator.h"
#include "gravcal/static_detector.h"
// Issue 4: handheld Kalman calibration.
#include "gravcal/error_state_layout.h"
#include "gravcal/handheld_kalman.h"
#include "gravcal/handheld_simulator.h"
#include "gravcal/rate_table.h"
#include "gravcal/strapdown.h"

#endif  // GRAVCAL_GRAVCAL_H_
