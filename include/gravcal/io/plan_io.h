// gravcal/io/plan_io.h: plan.json, the recording plan on disk.
//
// plan.json (the contract):
//   {"poses": [{"up": [x, y, z], "hold_s": 12.5, "instruction": "x axis up ..."}, ...],
//    "rotations": [{"from": 0, "to": 1, "axis": [x, y, z], "angle_deg": 90,
//                   "instruction": "turn 90 degrees about ..."}, ...],
//    "predicted_std": {"bias_x": ..., ..., "u_zz": ...},
//    "predicted_std_readable": {"bias_x": {"value": 0.21, "unit": "mg"}, ...},
//    "targets": {"bias_x": {"value": 0.5, "unit": "mg", "stated": true}, ...},
//    "total_time_s": ..., "overhead_s": ..., "meets_targets": true,
//    "nominal_scale": s, "gravity": g, "criterion": "...", "pose_set": "faces+45",
//    "noise": "...",
//    "schemes": {"twelve": {"poses": 12, "hold_s": ..., "total_time_s": ...,
//                           "meets_targets": true, "predicted_std": {...}}, ...},
//    "message": "..."}
// `up` is the sensor-frame unit vector that points up (the accelerometer
// reads +g along it); predicted_std has the names and units of the
// calibration JSON's accel covariance (bias in raw units, U in m/s^2 per raw
// unit at nominal_scale); null = undetermined.
#ifndef GRAVCAL_IO_PLAN_IO_H_
#define GRAVCAL_IO_PLAN_IO_H_

#include <string>
#include <vector>

#include "gravcal/estimation/recording_plan.h"

namespace gravcal {

std::string PlanToJson(const RecordingPlan& plan);
bool WritePlanJson(const RecordingPlan& plan, const std::string& path, std::string* error);

// The poses of plan.json text (up normalised, hold_s > 0, instruction when
// present); false with *error (naming `name`) on anything else.
bool PlanPosesFromJson(const std::string& text, const std::string& name,
                       std::vector<PlannedPose>* poses, std::string* error);
bool ReadPlanPoses(const std::string& path, std::vector<PlannedPose>* poses, std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_IO_PLAN_IO_H_
