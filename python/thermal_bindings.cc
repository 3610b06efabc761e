// The thermal model of a calibration (issue 35, core/thermal_model.h) for
// Python: its numbers as a dict, and each term evaluated with its standard
// deviation at given temperatures, exactly as the corrector evaluates it
// (the clamp to the valid range included).
#include "bindings.h"
#include "gravcal/core/thermal_model.h"

namespace gravcal {
namespace python {
namespace {

// An enum from its name (its one table); the error names the argument and
// the accepted names.
template <typename E>
E Named(const char* argument, const std::string& name) {
  E value{};
  std::string error;
  Check(ParseName(argument, name, &value, &error), error);
  return value;
}

ThermalSensor SensorNamed(const std::string& name) { return Named<ThermalSensor>("sensor", name); }

ThermalQuantity QuantityNamed(const std::string& name) {
  return Named<ThermalQuantity>("quantity", name);
}

py::dict TermDict(const ThermalPolynomial& p, ThermalSensor s, ThermalQuantity q) {
  py::dict d;
  d["order"] = p.order;
  d["max_order"] = p.max_order;
  d["selection"] = p.selection;
  d["components"] = ThermalComponentNames(s, q);
  // components x order, NaN where the session does not determine one.
  Eigen::MatrixXd c =
      p.active() ? Eigen::MatrixXd(p.coefficients) : Eigen::MatrixXd(ThermalComponents(s, q), 0);
  for (Eigen::Index i = 0; i < c.rows(); ++i) {
    for (Eigen::Index k = 0; k < c.cols(); ++k) {
      if (!p.Determined(static_cast<int>(i), static_cast<int>(k) + 1)) c(i, k) = NAN;
    }
  }
  d["coefficients"] = c;
  py::list units;
  for (int k = 1; k <= p.order; ++k) units.append(ThermalUnit(q, k));
  d["units"] = units;
  return d;
}

// The calibration's thermal model; "active" False when it has none.
py::dict ThermalDict(const PyCalibration& c) {
  const ThermalModel& m = c.Models().corrector.thermal;
  py::dict d;
  d["active"] = m.active();
  d["reference_temperature"] = m.reference_temperature;
  d["min_temperature"] = m.min_temperature;
  d["max_temperature"] = m.max_temperature;
  d["lag_time_constant"] = m.lag_time_constant;
  d["lag_time_constant_std"] = m.lag_time_constant_std;
  d["notes"] = m.notes;
  for (ThermalSensor s : {ThermalSensor::kAccel, ThermalSensor::kGyro}) {
    py::dict sensor;
    for (ThermalQuantity q :
         {ThermalQuantity::kBias, ThermalQuantity::kScale, ThermalQuantity::kMisalignment}) {
      sensor[ToString(q)] = TermDict(m.Sensor(s).Term(q), s, q);
    }
    d[ToString(s)] = sensor;
  }
  return d;
}

// (values, std): (N, components) arrays of the term's change from T_ref at
// each temperature (clamped to the valid range as the correction does), and
// its standard deviation (NaN where it is not known).
py::tuple ThermalEvaluate(const PyCalibration& c, const std::string& sensor,
                          const std::string& quantity, const py::object& temperatures) {
  const ThermalModel& m = c.Models().corrector.thermal;
  const ThermalSensor s = SensorNamed(sensor);
  const ThermalQuantity q = QuantityNamed(quantity);
  const std::vector<double> t = ToScalars(temperatures, "temperatures", -1, "temperatures");
  const ThermalPolynomial& p = m.Sensor(s).Term(q);
  const int n = ThermalComponents(s, q);
  Eigen::MatrixXd values(t.size(), n), stds(t.size(), n);
  for (size_t r = 0; r < t.size(); ++r) {
    const double x = m.Offset(t[r], NAN, nullptr);
    for (int i = 0; i < n; ++i) {
      values(r, i) = p.Value(i, x);
      stds(r, i) = p.active() ? p.Std(i, x, false) : 0.0;
    }
  }
  return py::make_tuple(values, stds);
}

}  // namespace

void BindThermal(py::module_& m) {
  m.def("thermal_model", &ThermalDict, py::arg("calibration"));
  m.def("thermal_evaluate", &ThermalEvaluate, py::arg("calibration"), py::arg("sensor"),
        py::arg("quantity"), py::arg("temperatures"));
}

}  // namespace python
}  // namespace gravcal
