// gravcal/io/noise_io.h: the noise model on disk.
//
// noise.json (the contract):
//   {"rate_hz": 100.0,
//    "still": {"begin": 0, "end": 360000, "t_begin": 0.0, "t_end": 3599.99},
//    "accel": {"x": {"white_noise":      {"value": v, "std": s, "tau": t, "tau_range": [lo, hi]},
//                    "bias_instability": {...}, "random_walk": {...}, "quantisation": {...},
//                    "lines": [{"frequency_hz": f, "amplitude": a, "prominence": p}, ...],
//                    "allan": {"tau": [...], "adev": [...], "lo": [...], "hi": [...]}},
//              "y": ..., "z": ...},
//    "gyro": {same; absent when the log has none},
//    "temperature": {"allan": {...}} (when the log has one),
//    "confidence": 0.683,
//    "choices": {"timing": {"rate_source": "...", "median_step": s, "largest_step": s,
//                           "largest_departure": s, "unbiased_tau": s, "text": "..."},
//                "units": {"accel_scale": k, "gyro_scale": k, "accel_offset": [x, y, z],
//                          "mean_removed": true, "unit_check": "..."},
//                "fit": {"readings": "..."}}}
// ("lines" and "choices" are optional on reading: older files lack them.)
// in SI (accelerometer m/s^2, gyroscope rad/s; units of each term in
// core/noise_model.h). A term the log cannot show has "value": null and a
// "reason".
//
// Kalibr imu.yaml: the continuous-time densities of Kalibr's IMU noise model
// (its wiki page "IMU Noise Model"): *_noise_density in units/sqrt(Hz)
// (white noise N) and *_random_walk in units/s/sqrt(Hz) (rate random walk
// K), update_rate in Hz. Kalibr takes one value per sensor; the largest of
// the three axes is written (conservative: no axis is weighted more than its
// noise allows).
//
// Handheld filter keys (methods/handheld_kalman.h, config keys hk_*):
// hk_accel_noise_density (m/s^2/sqrt(Hz)) and hk_gyro_noise_density
// (rad/s/sqrt(Hz)) = N, hk_accel_bias_walk (m/s^2/sqrt(s)) and
// hk_gyro_bias_walk (rad/s/sqrt(s)) = K (the same unit), axis maxima.
#ifndef GRAVCAL_IO_NOISE_IO_H_
#define GRAVCAL_IO_NOISE_IO_H_

#include <array>
#include <string>

#include "gravcal/core/noise_model.h"
#include "gravcal/estimation/noise_characterisation.h"

namespace gravcal {

// noise.json text of the result (model and curves).
std::string NoiseToJson(const ImuNoise& noise);
// Parses noise.json text; `name` is used in messages. On failure returns
// false, leaves *noise unchanged and sets *error to one line.
bool NoiseFromJson(const std::string& text, const std::string& name, ImuNoise* noise,
                   std::string* error);

// Atomic file versions of the two above.
bool WriteNoiseJson(const ImuNoise& noise, const std::string& path, std::string* error);
bool ReadNoiseJson(const std::string& path, ImuNoise* noise, std::string* error);

// Kalibr imu.yaml text. False (with *error) when white noise or random walk
// is not shown by any axis of a sensor: Kalibr needs all four.
bool NoiseToKalibrYaml(const ImuNoiseModel& model, std::string* yaml, std::string* error);
bool WriteKalibrImuYaml(const ImuNoiseModel& model, const std::string& path, std::string* error);

// The handheld filter's hk_* keys as YAML; a term no axis shows is left out
// (the filter keeps its default) with a comment saying why.
std::string NoiseToHandheldYaml(const ImuNoiseModel& model);

// The largest value of a term over three axes; NaN when no axis shows it.
double AxisMaximum(const std::array<AxisNoiseModel, 3>& axes, NoiseTerm AxisNoiseModel::*term);

}  // namespace gravcal

#endif  // GRAVCAL_IO_NOISE_IO_H_
