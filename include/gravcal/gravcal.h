// gravcal/gravcal.h: the whole public API of gravcal in one include.
#ifndef GRAVCAL_GRAVCAL_H_
#define GRAVCAL_GRAVCAL_H_

#include "gravcal/accel_model.h"
#include "gravcal/batch.h"
#include "gravcal/batch_manifest.h"
#include "gravcal/attitude_fixture.h"
#include "gravcal/calibration.h"
#include "gravcal/calibration_io.h"
#include "gravcal/coarse_fit.h"
#include "gravcal/fleet_summary.h"
#include "gravcal/config.h"
#include "gravcal/gravity.h"
#include "gravcal/gravity_magnitude_residual.h"
#include "gravcal/gyro_calibration.h"
#include "gravcal/gyro_model.h"
#include "gravcal/gyro_rotation_residual.h"
#include "gravcal/gyro_static_residual.h"
#include "gravcal/housing_rotation.h"
#include "gravcal/imu_log.h"
#include "gravcal/known_attitude.h"
#include "gravcal/log_reader.h"
#include "gravcal/newton_solver.h"
#include "gravcal/observability.h"
#include "gravcal/pipeline.h"
#include "gravcal/position.h"
#include "gravcal/refinement.h"
#include "gravcal/simulator.h"
#include "gravcal/static_alignment.h"
#include "gravcal/static_detector.h"
#include "gravcal/ten_position.h"

#endif  // GRAVCAL_GRAVCAL_H_
