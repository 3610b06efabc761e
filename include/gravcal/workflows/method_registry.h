// gravcal/workflows/method_registry.h: the one list of calibration methods a
// config's `method:` can name.
//
// Each entry gives the method's name, a one-line help, the config sections
// and single keys it reads (beyond the general and input sections every
// method reads), the side input it needs, and its run function. The help of
// the `method` key, Config::IsValid and RunCalibration all come from this
// list, so a new method is its own file(s) in src/methods, its options
// section in src/workflows/config/, and one entry in method_registry.cc.
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
  // Config sections (config.h, ConfigSectionUse::kSomeMethods) whose every
  // key the method reads, and single keys of other sections it reads.
  std::vector<std::string> sections;
  std::vector<std::string> keys;
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
// Whether `method` reads `key`: every kAllMethods key, the keys of its
// sections and its single keys; never a kCommand key.
bool MethodReadsKey(const CalibrationMethod& method, const ConfigKey& key);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_METHOD_REGISTRY_H_
