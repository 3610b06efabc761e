// gravcal/workflows/method_registry.h: the one list of calibration methods a
// config's `method:` can name.
//
// Each entry gives the method's name, a one-line help, the side input it
// needs, and where each part of its options struct is copied from in the
// Config. That one list fills the options the method runs with and says
// which keys it reads (beyond the general and input sections every method
// reads): a key is read when a field it sets is copied into the options, so
// a key the method's options do not embed is refused, and no list of key
// names is kept by hand. The help of the `method` key, Config::IsValid and
// RunCalibration all come from this list, so a new method is its own
// file(s) in src/methods, its options section in src/workflows/config/, and
// one entry in method_registry.cc.
//
// Run functions take data already read and parsed (Session), never a path:
// the pipeline (pipeline.h) reads the files.
#ifndef GRAVCAL_WORKFLOWS_METHOD_REGISTRY_H_
#define GRAVCAL_WORKFLOWS_METHOD_REGISTRY_H_

#include <functional>
#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/methods/session.h"
#include "gravcal/workflows/config.h"

namespace gravcal {

// A file a method needs besides the log (a command-line flag, a batch
// manifest column).
enum class MethodSideInput {
  kNone,
  // The fixture's attitude per static position (--attitudes, attitude_fixture.h).
  kAttitudes,
  // The constant-rate segments of a rate table (--segments, rate_table_segments.h).
  kSegments,
};

struct CalibrationMethod {
  Method id = Method::kTwelvePosition;
  // ToString(id): the value of `method:`.
  std::string name;
  std::string help;
  // Whether the method's options are filled from the field at `field` of
  // `config` (derived from the parts of the config its options are copied
  // from); MethodReadsKey asks it of the fields a key sets.
  std::function<bool(const Config& config, const void* field)> reads;
  MethodSideInput side_input = MethodSideInput::kNone;
  // Checks the options the method reads (beyond the shared ones);
  // nullptr = nothing more to check.
  std::function<bool(const Config&, std::string*)> validate;
  // Gives the method (src/methods/) the sections of the config it reads and
  // runs it on the session. Fills calibration (calibration->method
  // included). Returns false with a one-line message.
  std::function<bool(const Config&, const Session&, Calibration*)> run;
  // What the method does with a noise model (--noise), for help and notes;
  // empty = it uses none, and giving one is an error.
  std::string noise_model;
  // Whether the method keeps an estimate history (Calibration::history,
  // calibrate --history): checked before the method runs.
  bool keeps_history = false;
};

// Every method, in the order help lists them.
const std::vector<CalibrationMethod>& CalibrationMethods();
// nullptr when there is no method of that name.
const CalibrationMethod* FindCalibrationMethod(const std::string& name);
// The entry of `method`.
const CalibrationMethod* FindCalibrationMethod(Method method);
// "twelve_position, ten_position, ..." for messages.
std::string CalibrationMethodNames();
// "twelve_position (one-line help), ten_position (...), ..." for help text.
std::string CalibrationMethodsHelp();
// Whether `method` reads `key`: every kAllMethods key, and a kSomeMethods
// key when a field the key sets is copied into the method's options; never
// a kCommand key.
bool MethodReadsKey(const CalibrationMethod& method, const ConfigKey& key);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_METHOD_REGISTRY_H_
