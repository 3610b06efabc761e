// gravcal/io/plan_io.h: plan.json, the recording plan on disk.
//
// plan.json (the contract):
//   {"poses": [{"up": [x, y, z], "hold_s": 12.5, "instruction": "x axis up ..."}, ...],
//    "rotations": [{"from": 0, "to": 1, "axis": [x, y, z], "angle_deg": 90,
//                   "duration_s": 1.5 (when the gyroscope is planned),
//                   "instruction": "turn 90 degrees about ..."}, ...],
//    "predicted_std": {"bias_x": ..., ..., "u_zz": ...},
//    "predicted_std_readable": {"bias_x": {"value": 0.21, "unit": "mg"}, ...},
//    "targets": {"bias_x": {"value": 0.5, "unit": "mg", "stated": true}, ...},
//    "total_time_s": ..., "overhead_s": ..., "meets_targets": true,
//    "nominal_scale": s, "gravity": g, "criterion": "...", "pose_set": "faces+45",
//    "noise": "...",
//    "schemes": {"twelve": {"poses": 12, "hold_s": ..., "total_time_s": ...,
//                           "meets_targets": true, "predicted_std": {...}}, ...},
//    "gyro_predicted_std": {"bias_x": ..., "m_xx": ..., ..., "m_zz": ...},
//    "gyro_predicted_std_readable": {...}, "gyro_targets": {...},
//    "gyro_nominal_scale": k, "gyro_extra_poses": n   (when the gyroscope is planned),
//    "message": "..."}
// `up` is the sensor-frame unit vector that points up (the accelerometer
// reads +g along it); predicted_std has the names and units of the
// calibration JSON's accel covariance (bias in raw units, U in m/s^2 per raw
// unit at nominal_scale); null = undetermined. gyro_predicted_std has the
// names and units of the calibration JSON's gyro covariance (bias in raw
// units, M_g in rad/s per raw unit at gyro_nominal_scale).
#ifndef GRAVCAL_IO_PLAN_IO_H_
#define GRAVCAL_IO_PLAN_IO_H_

#include <string>
#include <vector>

#include "gravcal/estimation/recording_plan.h"

namespace gravcal {

std::string PlanToJson(const RecordingPlan& plan);

// What `gravcal check` says, as the "check" object of calibrate's
// calibration JSON (compact JSON text):
//   {"positions": n, "nominal_scale": s,
//    "predicted_std": {"bias_x": ..., ...} (calibration JSON units, null = undetermined),
//    "predicted_std_readable": {"bias_x": {"value": ..., "unit": "mg"}, ...},
//    "undetermined": [...], "short_of_target": [...],
//    "proposed": [{"up": [...], "hold_s": ..., "instruction": "..."}, ...],
//    "undetermined_with_proposed": [...], "message": "..."}
std::string CoverageToJson(const CoverageReport& report);
bool WritePlanJson(const RecordingPlan& plan, const std::string& path, std::string* error);

// The poses of plan.json text (up normalised, hold_s > 0, instruction when
// present); false with *error (naming `name`) on anything else.
bool PlanPosesFromJson(const std::string& text, const std::string& name,
                       std::vector<PlannedPose>* poses, std::string* error);
// The turns of plan.json text (from, to = from + 1 < pose_count, unit axis,
// angle_deg in [0, 180], duration_s when present); none when the key is
// absent; false with *error (naming `name`) on anything else.
bool PlanRotationsFromJson(const std::string& text, const std::string& name, size_t pose_count,
                           std::vector<PlannedRotation>* rotations, std::string* error);
// The poses of a plan.json file, and its turns when `rotations` is not null.
bool ReadPlanPoses(const std::string& path, std::vector<PlannedPose>* poses, std::string* error,
                   std::vector<PlannedRotation>* rotations = nullptr);

}  // namespace gravcal

#endif  // GRAVCAL_IO_PLAN_IO_H_
