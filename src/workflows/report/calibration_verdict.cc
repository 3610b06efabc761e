// The verdict of a calibration report (calibration_verdict.h).
#include "workflows/report/calibration_verdict.h"

#include <cmath>

#include "core/conditional_sigmas.h"
#include "gravcal/workflows/report.h"
#include "util/join.h"
#include "util/statistics.h"
#include "workflows/report/svg_plot.h"

namespace gravcal {
namespace internal {

double AfterSigma(const PositionReport& p) {
  return p.sigma > 0 ? p.residual_after / p.sigma : NAN;
}

double OutlierThreshold(size_t n) {
  return internal::NormalQuantile(1.0 - 0.005 / std::max<size_t>(n, 1));
}

std::string PoseName(const Calibration& c, size_t k) {
  const PositionReport& p = c.positions[k];
  return "pose " + std::to_string(k + 1) + " (" + NominalAxisName(p.nominal_up) + " up, " +
         FormatNumber(p.position.t_begin, "%.1f") + " to " +
         FormatNumber(p.position.t_end, "%.1f") + " s)";
}

Verdict Judge(const Calibration& c) {
  Verdict v;
  if (!c.success) {
    v.Raise(VerdictLevel::kAgain, "the calibration failed: " + c.message);
    return v;
  }
  const VarianceComponent& vc = c.accel.pose_variance;
  if (vc.absorbed) {
    v.notes.push_back("the poses scatter by s = " + FormatNumber(std::sqrt(vc.variance), "%.3g") +
                      " m/s^2 beyond what their samples show: expected for poses placed by "
                      "hand (the white-noise model is optimistic there); every standard "
                      "deviation includes it");
  }
  const double threshold = OutlierThreshold(c.positions.size());
  std::vector<size_t> disturbed;
  for (size_t k = 0; k < c.positions.size(); ++k) {
    if (std::fabs(AfterSigma(c.positions[k])) > threshold) disturbed.push_back(k);
  }
  const bool many = disturbed.size() > std::max<size_t>(2, c.positions.size() / 4);
  for (size_t k : disturbed) {
    v.Raise(VerdictLevel::kLook,
            PoseName(c, k) + " lies " +
                FormatNumber(std::fabs(AfterSigma(c.positions[k])), "%.1f") +
                " sigma from the fit (more than " + FormatNumber(threshold, "%.2f") +
                ", the outlier limit for " + std::to_string(c.positions.size()) +
                " poses): it was disturbed or not settled; cut it from the log and calibrate "
                "again, or record that pose again");
  }
  if (many) {
    v.Raise(VerdictLevel::kAgain, std::to_string(disturbed.size()) + " of " +
                                      std::to_string(c.positions.size()) +
                                      " poses are disturbed, too many to trust the fit: record the "
                                      "session again, holding each pose still");
  }
  const RefinementResult& r = c.refinement;
  if (r.dof > 0 && internal::ChiSquareUpperTail(r.chi2, r.dof) < 1e-3) {
    std::ostringstream s;
    s << "chi2 / dof = " << FormatNumber(r.chi2 / r.dof, "%.3g")
      << ": the residuals are larger than the noise of the poses predicts (p < 0.001)"
      << (vc.absorbed ? ""
                      : " and were not absorbed as pose scatter: the model misses a term (see "
                        "the warnings, or run `gravcal discover`)");
    v.Raise(VerdictLevel::kLook, s.str());
  }
  if (!r.observability.undetermined.empty()) {
    std::string names;
    for (const std::string& n : r.observability.undetermined)
      names += (names.empty() ? "" : ", ") + n;
    const std::string held = internal::Join(internal::ConditionalOn(r));
    v.Raise(VerdictLevel::kLook,
            "this session cannot determine " + names +
                ": they are reported without a number; the other parameters can be used" +
                (held.empty() ? std::string()
                              : " (their standard deviations are conditional on holding " + held +
                                    " at the coarse fit's value)") +
                ", or add poses (`gravcal check` names them)");
  }
  // Warnings that only say what the method cannot do or where a number
  // comes from do not call for a look.
  size_t to_look = 0;
  for (size_t i = 0; i < c.warnings.size(); ++i) {
    const WarningCode code =
        i < c.warning_codes.size() ? c.warning_codes[i] : WarningCode::kUnclassified;
    to_look += code != WarningCode::kMethodScope && code != WarningCode::kParameterSource;
  }
  if (to_look > 0) {
    v.Raise(VerdictLevel::kLook, std::to_string(to_look) + " warning" + (to_look > 1 ? "s" : "") +
                                     " to look at (explained below)");
  }
  if (v.reasons.empty()) {
    v.reasons.push_back(std::string(c.positions.empty() ? "" : "no pose disturbed, ") +
                        "the residuals match the noise, every parameter determined and no "
                        "warning to look at");
  }
  return v;
}

}  // namespace internal
}  // namespace gravcal
