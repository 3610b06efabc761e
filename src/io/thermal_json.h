// io/thermal_json.h (private): the calibration JSON's "thermal" section
// (docs/data_contract.md, "Calibration JSON: thermal"), written and read.
#ifndef GRAVCAL_IO_THERMAL_JSON_H_
#define GRAVCAL_IO_THERMAL_JSON_H_

#include <nlohmann/json.hpp>
#include <string>

#include "gravcal/core/thermal_model.h"

namespace gravcal {
namespace internal {

// The section; undetermined coefficients and missing standard deviations
// are null.
nlohmann::json ThermalJson(const ThermalModel& model);

// Reads the section `j` (the value of key "thermal"); `error` is one line
// "<name>: key 'thermal.<...>': <what>". Null coefficients read as 0 and
// undetermined.
bool ThermalFromJson(const nlohmann::json& j, const std::string& name, ThermalModel* model,
                     std::string* error);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_IO_THERMAL_JSON_H_
