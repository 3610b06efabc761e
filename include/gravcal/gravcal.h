// gravcal/gravcal.h: the whole public API of gravcal in one include, wing by
// wing from the bottom (shared types) to the top (workflows); see
// docs/architecture.md.
#ifndef GRAVCAL_GRAVCAL_H_
#define GRAVCAL_GRAVCAL_H_

// core
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
#include "gravcal/core/types.h"

// detection
#include "gravcal/detection/static_detector.h"

// residuals
#include "gravcal/residuals/accel_rotation_residual.h"
#include "gravcal/residuals/accel_trend_residual.h"
#include "gravcal/residuals/gravity_magnitude_residual.h"
#include "gravcal/residuals/gyro_rotation_residual.h"
#include "gravcal/residuals/gyro_static_residual.h"

// estimation
#include "gravcal/estimation/allan_deviation.h"
#include "gravcal/estimation/coarse_fit.h"
#include "gravcal/estimation/error_state_layout.h"
#include "gravcal/estimation/experiment_design.h"
#include "gravcal/estimation/housing_rotation.h"
#include "gravcal/estimation/newton_solver.h"
#include "gravcal/estimation/noise_characterisation.h"
#include "gravcal/estimation/observability.h"
#include "gravcal/estimation/pose_mean_covariance.h"
#include "gravcal/estimation/recording_plan.h"
#include "gravcal/estimation/refinement.h"
#include "gravcal/estimation/solver_tolerances.h"
#include "gravcal/estimation/static_alignment.h"
#include "gravcal/estimation/strapdown.h"

// io
#include "gravcal/io/attitude_fixture.h"
#include "gravcal/io/calibration_export.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/calibration_models.h"
#include "gravcal/io/files.h"
#include "gravcal/io/imu_stream.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/io/noise_io.h"
#include "gravcal/io/plan_io.h"
#include "gravcal/io/recording.h"

// simulation
#include "gravcal/simulation/handheld_simulator.h"
#include "gravcal/simulation/noise_process.h"
#include "gravcal/simulation/simulated_attitudes.h"
#include "gravcal/simulation/simulator.h"

// methods
#include "gravcal/methods/effect_fit.h"
#include "gravcal/methods/gyro_calibration.h"
#include "gravcal/methods/handheld_kalman.h"
#include "gravcal/methods/known_attitude.h"
#include "gravcal/methods/rate_table.h"
#include "gravcal/methods/ten_position.h"
#include "gravcal/methods/twelve_position.h"

// workflows
#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/batch_manifest.h"
#include "gravcal/workflows/batch_scheduler_shard.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/discovery.h"
#include "gravcal/workflows/discovery_report.h"
#include "gravcal/workflows/fleet_summary.h"
#include "gravcal/workflows/method_registry.h"
#include "gravcal/workflows/noise_workflow.h"
#include "gravcal/workflows/pipeline.h"
#include "gravcal/workflows/plan.h"
#include "gravcal/workflows/rate_table_segments.h"
#include "gravcal/workflows/report.h"
#include "gravcal/workflows/simulation_workflow.h"
#endif  // GRAVCAL_GRAVCAL_H_
