// gravcal/methods/session.h: what one calibration runs on, in memory.
//
// A Session holds the raw log, the static detection of that log and the
// side data a method may need, all as values: the fixture's attitudes
// (known_attitude), the rate table's segments (rate_table) and the noise
// model (`gravcal noise`). Files are read by io and the command line
// (workflows/pipeline.h ReadSessionFiles), once; the names kept here are for
// messages only.
//
// The static poses are detected once (DetectSessionPoses): the method, the
// HTML report and the coverage check (workflows/plan.h) all read
// Session::detection, so they see the same intervals. A method given a
// session that was not detected detects itself, with its own options.
//
// Every method has the same entry point,
//   bool Calibrate<Method>(const Session&, const <Method>MethodOptions&, Calibration*);
// filling the Calibration (its message says what happened, or why not).
#ifndef GRAVCAL_METHODS_SESSION_H_
#define GRAVCAL_METHODS_SESSION_H_

#include <optional>
#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/noise_model.h"
#include "gravcal/core/rate_table_segment.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/io/attitude_fixture.h"

namespace gravcal {

struct Session {
  // The raw log (accelerometer, and gyroscope when the method uses it);
  // log.source names it in messages.
  ImuLog log;

  // The static detection of `log`, set by DetectSessionPoses: `detected`
  // says whether it ran, `detection_ok` whether it succeeded (otherwise
  // detection.message says why, naming log.source).
  bool detected = false;
  bool detection_ok = false;
  StaticDetection detection;

  // The fixture's attitude per static position (known_attitude), and the
  // name of the file they came from.
  std::vector<FixtureAttitude> attitudes;
  std::string attitudes_name;
  // The constant-rate segments, as sample ranges of `log` (rate_table).
  std::vector<RateTableSegment> segments;
  std::string segments_name;
  // The noise model (SI units), when one is given, and its file name.
  std::optional<ImuNoiseModel> noise;
  std::string noise_name;

  // The noise model or nullptr.
  const ImuNoiseModel* noise_model() const { return noise ? &*noise : nullptr; }
};

// Checks session->log and detects its static intervals with `detector`,
// once: a session already detected is left as it is. Returns
// session->detection_ok; on failure session->detection.message says why
// (naming log.source).
bool DetectSessionPoses(const StaticDetectorOptions& detector, Session* session);

}  // namespace gravcal

#endif  // GRAVCAL_METHODS_SESSION_H_
