// gravcal/gravcal.h: the core of gravcal's public API in one include: the IMU
// log, the sensor model and the calibration result, the calibration methods'
// entry points and options, and reading and writing logs and calibrations.
// It includes no Ceres or glog header, so a program built against the core
// needs Eigen and gravcal only (a test checks it: HeaderCheck.CoreWithoutCeres).
//
// Elsewhere in the public API, included one by one where needed:
// - gravcal/ceres.h: the Ceres residuals, for estimators that build their own
//   ceres::Problem (link gravcal::ceres, which adds Ceres);
// - gravcal/estimation/*.h: the estimation steps the methods are made of;
// - gravcal/simulation/*.h: simulators with known truth;
// - gravcal/workflows/*.h: configs, RunCalibration by method name, batch,
//   discovery, plans and reports (what the command-line tool runs).
// See docs/architecture.md.
#ifndef GRAVCAL_GRAVCAL_H_
#define GRAVCAL_GRAVCAL_H_

// The log, the model, the result and the shared vocabulary.
#include "gravcal/core/accel_model.h"
#include "gravcal/core/calibration.h"
#include "gravcal/core/gravity.h"
#include "gravcal/core/gyro_model.h"
#include "gravcal/core/imu_corrector.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/core/imu_model.h"
#include "gravcal/core/model_effects.h"
#include "gravcal/core/noise_model.h"
#include "gravcal/core/position.h"
#include "gravcal/core/rate_table_segment.h"
#include "gravcal/core/solver_result.h"
#include "gravcal/core/thermal_model.h"
#include "gravcal/core/thermal_rate.h"
#include "gravcal/core/types.h"

// Static poses of a log, the input of the static methods.
#include "gravcal/detection/static_detector.h"

// The methods: entry points and options.
#include "gravcal/methods/effect_fit.h"
#include "gravcal/methods/gyro_calibration.h"
#include "gravcal/methods/handheld_kalman.h"
#include "gravcal/methods/known_attitude.h"
#include "gravcal/methods/rate_table.h"
#include "gravcal/methods/session.h"
#include "gravcal/methods/ten_position.h"
#include "gravcal/methods/thermal_calibration.h"
#include "gravcal/methods/twelve_position.h"
#include "gravcal/methods/twelve_position_method.h"

// Read and write: logs, fixture attitudes, calibrations and their exports.
#include "gravcal/io/attitude_fixture.h"
#include "gravcal/io/calibration_export.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/calibration_models.h"
#include "gravcal/io/log_reader.h"

#endif  // GRAVCAL_GRAVCAL_H_
