// gravcal/workflows/noise_workflow.h: the noise model of a still log with
// the options a configuration gives, as `gravcal noise` computes it, and the
// files it writes. The command-line tool and the Python package both call
// these functions.
//
// The config's noise section supplies the Allan and fit settings; the raw
// units come from nominal_scale (accelerometer, m/s^2 per raw unit) and
// gyro_nominal_scale (gyroscope, rad/s per raw unit), and the still
// interval from the calibration's static detector section.
#ifndef GRAVCAL_WORKFLOWS_NOISE_WORKFLOW_H_
#define GRAVCAL_WORKFLOWS_NOISE_WORKFLOW_H_

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/estimation/noise_characterisation.h"
#include "gravcal/io/long_log.h"
#include "gravcal/workflows/config.h"

namespace gravcal {

// The options of `config`. False with a one-line *error when its reader
// options ("input: ...") or the noise options are invalid.
bool NoiseOptionsFromConfig(const Config& config, NoiseOptions* options, std::string* error);

// CharacteriseNoise, then a check of the accelerometer's unit: over the
// still interval |mean accelerometer - accel_offset| * accel_scale within
// 10 % of standard gravity is "checked" (noise->unit_check says so).
// Otherwise, with no offset stated (accel_offset zero), the mean is taken as
// a raw offset (unsigned counts, volts around 1.65; the Allan deviation
// removes it) and the unit reported as not checked; refused when an offset
// was stated, when the mean is 1 m/s^2 (data in g) or beyond 100 g (counts
// at scale 1). False with a one-line *error (naming log.source) on any
// failure.
bool CharacteriseLogNoise(const ImuLog& log, const NoiseOptions& options, ImuNoise* noise,
                          std::string* error);

// CharacteriseLogNoise on a log ReadImuLogBounded read (io/long_log.h).
// On block means (reading.samples_averaged > 1) the Allan deviation is the
// overlapping estimate on the means (taus from one block on), a nominal
// rate is divided by the block, and the results are restated per row of the
// recording (the rate, the still interval's rows, the curves' rates, sample
// counts and averaging factors; taus unchanged); noise->message and the
// timing's text (noise.json choices.timing.text) say what was done.
bool CharacteriseLongLogNoise(const ImuLog& log, const LongLogReading& reading,
                              const NoiseOptions& options, ImuNoise* noise, std::string* error);

// N against the datasheet's white-noise density (`noise
// --accel-noise-density/--gyro-noise-density`, SI units; 0 = none): one
// note per axis, and how far each axis's spectrum reaches toward Nyquist
// (the square root of its level at 0.8-0.97 of Nyquist over that at 0.2-0.4
// of it; NaN when the still interval is too short or the log was read as
// block means). An N more than 1.3 times the datasheet's over a spectrum flat
// to Nyquist (0.85 or more) is named as possible aliasing: a sensor whose
// bandwidth B reaches past Nyquist folds the noise above it in, reading
// sqrt(2 B / rate) times its own density (an MPU-6050's default 256 Hz
// filter read at 100 Hz: 2.3); the same spectrum is what a part that noisy
// shows, so the note says "possibly", and N stays the density the sampled
// data hold. A spectrum that falls toward Nyquist rules aliasing out.
struct NoiseDatasheetCheck {
  std::array<double, 3> accel_flatness{NAN, NAN, NAN};
  std::array<double, 3> gyro_flatness{NAN, NAN, NAN};
  std::vector<std::string> notes;
};
void CheckNoiseAgainstDatasheet(const ImuLog& log, const LongLogReading& reading,
                                const ImuNoise& noise, double accel_density, double gyro_density,
                                NoiseDatasheetCheck* check);

// The files of `gravcal noise`; an empty path is not written.
struct NoiseFiles {
  // noise.json (io/noise_io.h).
  std::string json;
  // Kalibr's imu.yaml (NoiseToKalibrYaml).
  std::string kalibr;
  // The handheld filter's hk_* keys (NoiseToHandheldYaml).
  std::string handheld;
  // The HTML report (workflows/report.h, NoiseToHtml), titled `source`.
  std::string report;
};

// Writes `files` for `noise`: every text first, then each file atomically,
// in the order above; on a failure the files already written are removed,
// so none is left. *written (may be null): the paths written, in order.
// False with a one-line *error (naming the file).
// With `datasheet` (may be null), noise.json also holds its flatness and
// notes (choices.spectrum).
bool WriteNoiseFiles(const ImuNoise& noise, const std::string& source, const NoiseFiles& files,
                     std::vector<std::string>* written, std::string* error,
                     const NoiseDatasheetCheck* datasheet = nullptr);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_NOISE_WORKFLOW_H_
