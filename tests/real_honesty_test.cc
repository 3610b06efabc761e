// Issue 33, part 1: are the shipped defaults honest on real hand-placed
// sessions? Every real recording of ../shared/data/real with poses (skipped
// when the folder is absent) is calibrated with the shipped default
// uncertainty pipeline (the recording's config says only its input layout,
// gravity and model) and judged three ways:
//
// - split-half: the even-numbered poses and the odd-numbered ones are
//   fitted apart, with the full fit's options; the halves are independent,
//   so z = (p_even - p_odd) / sqrt(s_even^2 + s_odd^2) is N(0, 1) per
//   parameter when the sigmas are honest;
// - leave-one-pose-out: each pose predicted from the others (real_sessions.h);
// - the three AHRS repeats (one unit, three sessions) compared pairwise.
//
// The rms of z must lie in [0.7, 1.4] where the statistic rests on enough
// differences to tell (a band that fails both ways: sigmas too small and
// sigmas inflated). GRAVCAL_HONEST_SET="key=value;..." overrides config
// keys of every session (for tuning by hand; the assertions then still
// apply).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "gravcal/detection/static_detector.h"
#include "gravcal/estimation/pose_mean_covariance.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/report.h"
#include "real_sessions.h"

namespace gravcal {
namespace {

using testing_util::RealFit;
using testing_util::RmsOf;

const std::vector<testing_util::RealPoseSession>& kSessions = testing_util::RealPoseSessions();

// Applies GRAVCAL_HONEST_SET to `config`.
bool ApplyOverrides(Config* config, std::string* error) {
  const char* env = std::getenv("GRAVCAL_HONEST_SET");
  if (env == nullptr) return true;
  std::stringstream list(env);
  std::string item;
  while (std::getline(list, item, ';')) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos) continue;
    if (!SetConfigValue(item.substr(0, eq), item.substr(eq + 1), config, error)) return false;
  }
  return true;
}

bool LoadSession(const std::string& config_name, const std::string& file, Config* config,
                 ImuLog* log) {
  std::string error;
  const bool ok = testing_util::LoadRealSession(config_name, file, config, log, &error) &&
                  ApplyOverrides(config, &error);
  EXPECT_TRUE(ok) << config_name << ": " << error;
  return ok;
}

bool FitSession(const std::string& config_name, const std::string& file, RealFit* fit) {
  Config config;
  ImuLog log;
  if (!LoadSession(config_name, file, &config, &log)) return false;
  const bool ok = testing_util::CalibrateRealSession(config, log, file, fit);
  EXPECT_TRUE(ok) << file << ": " << fit->calibration.message;
  return ok;
}

// ck_explorer_poses: 160 blocks of 100 samples published with the
// transitions cut out. Each block is one pose (the detector's splitting of
// such blocks is tested elsewhere); here only the sigmas are judged.
bool FitCkExplorer(RealFit* fit) {
  Config config;
  std::string error;
  // The shipped twelve_position.yaml with this file's input layout.
  const std::string text =
      "format: csv\nsample_rate: 100\nnominal_scale: 9.80665\ngravity: 9.80665\n";
  ImuLog log;
  if (!LoadConfigFile(testing_util::SourceDir() + "/configs/twelve_position.yaml", &config,
                      &error) ||
      !LoadConfigText(text, "ck_explorer", &config, &error) || !ApplyOverrides(&config, &error) ||
      !ReadImuLog(testing_util::RealDataDir() + "/ck_explorer_poses/acc_log.csv", config.input,
                  &log, &error)) {
    ADD_FAILURE() << error;
    return false;
  }
  std::vector<StaticInterval> intervals;
  for (size_t b = 0; b + 100 <= log.size(); b += 100)
    intervals.push_back(MakeInterval(log, b, b + 100));
  fit->positions = PositionsFromIntervals(intervals);
  std::vector<std::string> notes;
  if (!SetPoseMeanCovariance(log, intervals, config.calibration.pose_noise, &fit->positions, &notes,
                             &error)) {
    ADD_FAILURE() << error;
    return false;
  }
  fit->refit = config.calibration;
  const bool ok = CalibrateFromPositions(fit->positions, fit->refit, &fit->calibration);
  EXPECT_TRUE(ok) << fit->calibration.message;
  if (ok && fit->calibration.accel.pose_variance.prior_set_aside) {
    fit->refit.refinement.pose_disturbance_prior_dof = 0.0;
  }
  return ok;
}

void Describe(const std::string& name, const RealFit& fit, double split, size_t split_n,
              double lopo) {
  const Calibration& c = fit.calibration;
  const VarianceComponent& vc = c.accel.pose_variance;
  std::printf(
      "%-22s poses %3zu  chi2/dof %7.2f on %3d  s %.2e%s%s  split-half rms z %.2f (%zu)  "
      "lopo rms z %.2f\n",
      name.c_str(), fit.positions.size(), c.refinement.chi2 / std::max(c.refinement.dof, 1),
      c.refinement.dof, std::sqrt(vc.variance), vc.absorbed ? " absorbed" : "",
      vc.prior_set_aside ? " prior-aside" : "", split, split_n, lopo);
}

double LopoRms(const RealFit& fit) {
  std::vector<double> z;
  for (double v : testing_util::LeaveOnePoseOutZ(fit)) {
    if (std::isfinite(v)) z.push_back(v);
  }
  return RmsOf(z);
}

TEST(RealHonesty, SplitHalvesAgreeWithinTheirSigmas) {
  if (testing_util::RealDataDir().empty()) GTEST_SKIP() << "../shared/data/real is not there";
  RealFit ck;
  ASSERT_TRUE(FitCkExplorer(&ck));
  const std::vector<double> z = testing_util::SplitHalfZ(ck);
  const double rms = RmsOf(z);
  Describe("ck_explorer_poses", ck, rms, z.size(), NAN);
  ASSERT_EQ(z.size(), 9u);
  // Consecutive poses are about 10 degrees apart, so the odd and the even
  // halves see the same directions and a misfit that depends on the
  // direction is common to both and cancels in their difference: the lower
  // bound is 0.6, not 0.7, for that reason (measured 0.69; white-noise
  // sigmas give 5.7, the earlier hand-placed prior 0.68).
  EXPECT_GT(rms, 0.6);
  EXPECT_LT(rms, 1.4);
}

TEST(RealHonesty, PosesAndRepeatsWithinTheirSigmas) {
  if (testing_util::RealDataDir().empty()) GTEST_SKIP() << "../shared/data/real is not there";
  std::vector<RealFit> fits(kSessions.size());
  std::vector<double> lopo(fits.size());
  for (size_t i = 0; i < fits.size(); ++i) {
    ASSERT_TRUE(FitSession(kSessions[i].config, kSessions[i].file, &fits[i]));
    const std::vector<double> split = testing_util::SplitHalfZ(fits[i]);
    lopo[i] = LopoRms(fits[i]);
    Describe(kSessions[i].file, fits[i], RmsOf(split), split.size(), lopo[i]);
  }
  // The three AHRS repeats pairwise, each within its sigmas, neither too
  // far apart nor too close. good2 and good3 (14 and 15 poses) determine
  // every parameter. good1's nine poses determine u_xy and u_xz only to
  // second order: they are held at the coarse fit's value (reported without
  // a number, left out of z) and good1's other sigmas are conditional on
  // them, labelled so. Before they were held, the free fit's linearised
  // sigmas were inflated by those near-flat directions: good1's pairs gave
  // rms z 0.45 and 0.52, all three 0.62 over 23 (too small).
  std::vector<double> all;
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) {
      testing_util::ParameterEstimate a, b;
      const AccelParameterization p = fits[i].refit.refinement.parameterization;
      ASSERT_TRUE(testing_util::EstimateOf(fits[i].calibration, p, &a));
      ASSERT_TRUE(testing_util::EstimateOf(fits[j].calibration, p, &b));
      std::vector<double> z;
      testing_util::AppendZ(a, b, &z);
      std::printf("AHRS good%d-good%d rms z %.2f over %zu:", i + 1, j + 1, RmsOf(z), z.size());
      for (double v : z) std::printf(" %.2f", v);
      std::printf("\n");
      for (double v : z) EXPECT_LT(std::fabs(v), 3.5) << "good" << i + 1 << "-good" << j + 1;
      EXPECT_LT(RmsOf(z), 1.4) << "good" << i + 1 << "-good" << j + 1;
      EXPECT_GT(RmsOf(z), 0.7) << "good" << i + 1 << "-good" << j + 1;
      EXPECT_EQ(z.size(), i == 0 ? 7u : 9u);
      all.insert(all.end(), z.begin(), z.end());
    }
  }
  std::printf("AHRS repeats: rms z %.2f over %zu differences\n", RmsOf(all), all.size());
  EXPECT_GT(RmsOf(all), 0.7);
  EXPECT_LT(RmsOf(all), 1.4);
  // good1's held terms are named wherever its sigmas are shown.
  const std::vector<std::string> held = {"u_xy", "u_xz"};
  EXPECT_EQ(fits[0].calibration.refinement.observability.undetermined, held);
  const std::string json = CalibrationToJson(fits[0].calibration, false);
  EXPECT_NE(json.find("\"conditional_on\""), std::string::npos);
  Config good1;
  ImuLog good1_log;
  ASSERT_TRUE(LoadSession(kSessions[0].config, kSessions[0].file, &good1, &good1_log));
  const std::string html = CalibrationToHtml(fits[0].calibration, good1_log, "good1");
  EXPECT_NE(html.find("sigma conditional on holding u_xy, u_xz"), std::string::npos);
  // The recordings with residual degrees of freedom: leave-one-pose-out
  // predictions within their sigmas (the MPU-6050's one residual and
  // good1's none cannot show it: real_sessions.h).
  for (size_t i : {1, 2, 4}) {
    EXPECT_GT(lopo[i], 0.7) << kSessions[i].file;
    EXPECT_LT(lopo[i], 1.4) << kSessions[i].file;
  }
}

// What a session shows: the residuals' chi2 / dof with the samples' white
// noise alone, the per-pose scatter s the shipped pipeline estimates, and
// the accelerometer's white noise per sample (median over the poses of the
// samples' standard deviation, m/s^2).
struct SessionStatistics {
  double white_chi2_dof = NAN;
  double s = NAN;
  double noise = NAN;
};

bool StatisticsOf(const Config& config, const ImuLog& log, SessionStatistics* out) {
  PipelineInput input;
  input.log = log;
  Config white = config;
  // As flags after the file (--pose_variance false --pose_noise white),
  // which override the file's pose-variance keys.
  std::string switch_error;
  EXPECT_TRUE(SetConfigValue("pose_variance", "false", &white, &switch_error)) << switch_error;
  EXPECT_TRUE(SetConfigValue("pose_noise", "white", &white, &switch_error)) << switch_error;
  Calibration w, c;
  if (!RunCalibration(white, input, &w) || !RunCalibration(config, input, &c)) return false;
  out->white_chi2_dof = w.refinement.chi2 / std::max(w.refinement.dof, 1);
  out->s = std::sqrt(c.accel.pose_variance.variance);
  const double scale = c.accel.model.matrix().diagonal().cwiseAbs().mean();
  std::vector<double> noise;
  for (const PositionReport& p : c.positions) noise.push_back(p.raw_std.mean() * scale);
  std::nth_element(noise.begin(), noise.begin() + noise.size() / 2, noise.end());
  out->noise = noise[noise.size() / 2];
  return true;
}

// The simulator's hand-placed profile (configs/hand_placed.yaml's sim_*
// keys) against the real hand-placed recordings that have residual degrees
// of freedom to show it: its chi2 / dof with white sigmas, its scatter s and
// its white noise must lie within a factor of two of the real recordings'
// range, so that what the simulator-based tests show about honesty carries
// to real sessions. A simulation without pose scatter (s = 0) fails it.
TEST(RealHonesty, HandPlacedSimulationLooksLikeTheRealSessions) {
  if (testing_util::RealDataDir().empty()) GTEST_SKIP() << "../shared/data/real is not there";
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {0.0, 0.0, 0.0};
  auto extend = [&](const SessionStatistics& st) {
    const double v[3] = {st.white_chi2_dof, st.s, st.noise};
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], v[i]);
      hi[i] = std::max(hi[i], v[i]);
    }
  };
  for (size_t i : {1, 2, 4}) {
    Config config;
    ImuLog log;
    ASSERT_TRUE(LoadSession(kSessions[i].config, kSessions[i].file, &config, &log));
    SessionStatistics st;
    ASSERT_TRUE(StatisticsOf(config, log, &st)) << kSessions[i].file;
    std::printf("%-34s white chi2/dof %6.2f  s %.2e  noise %.2e m/s^2\n", kSessions[i].file,
                st.white_chi2_dof, st.s, st.noise);
    extend(st);
  }
  Config sim;
  std::string error;
  ASSERT_TRUE(LoadConfigFile(testing_util::SourceDir() + "/configs/hand_placed.yaml", &sim, &error))
      << error;
  // The shipped uncertainty pipeline (configs/twelve_position.yaml), not
  // the profile's own prior.
  Config shipped;
  ASSERT_TRUE(
      LoadConfigFile(testing_util::SourceDir() + "/configs/twelve_position.yaml", &shipped, &error))
      << error;
  sim.calibration = shipped.calibration;
  // The accelerometer alone, as --gyro_model none after the file would.
  ASSERT_TRUE(SetConfigValue("gyro_model", "none", &sim, &error)) << error;
  for (uint64_t seed = 1; seed <= 2; ++seed) {
    SimulatedSession session;
    ASSERT_TRUE(Simulate(sim.simulation, seed, &session, &error)) << error;
    SessionStatistics st;
    ASSERT_TRUE(StatisticsOf(sim, session.log, &st)) << "seed " << seed;
    std::printf(
        "simulated hand_placed seed %d     white chi2/dof %6.2f  s %.2e  noise %.2e m/s^2\n",
        static_cast<int>(seed), st.white_chi2_dof, st.s, st.noise);
    const double v[3] = {st.white_chi2_dof, st.s, st.noise};
    const char* names[3] = {"white chi2/dof", "pose scatter s", "white noise"};
    for (int i = 0; i < 3; ++i) {
      EXPECT_GT(v[i], lo[i] / 2) << names[i] << ", seed " << seed;
      EXPECT_LT(v[i], hi[i] * 2) << names[i] << ", seed " << seed;
    }
  }
}

// The report's verdict keeps three situations apart (issue 33): on a
// simulated hand-placed session (pose scatter, calibrated with the shipped
// config) the scatter is a note, not a reason to look or to record again;
// one pose disturbed on top of it is named, with what to do, and still no
// "record again"; a session whose calibration fails says record again.
TEST(RealHonesty, VerdictSeparatesScatterDisturbedPoseAndFailure) {
  Config config;
  std::string error;
  ASSERT_TRUE(
      LoadConfigFile(testing_util::SourceDir() + "/configs/twelve_position.yaml", &config, &error))
      << error;
  ASSERT_TRUE(SetConfigValue("sim_pose_disturbance", "0.002", &config, &error)) << error;
  ASSERT_TRUE(SetConfigValue("sim_scheme", "random:30", &config, &error)) << error;
  ASSERT_TRUE(SetConfigValue("sim_hold", "4", &config, &error)) << error;
  SimulatedSession session;
  ASSERT_TRUE(Simulate(config.simulation, 4, &session, &error)) << error;
  PipelineInput input;
  input.log = session.log;
  Calibration c;
  ASSERT_TRUE(RunCalibration(config, input, &c)) << c.message;
  std::string html = CalibrationToHtml(c, input.log, "scatter");
  EXPECT_NE(html.find("expected for poses placed by hand"), std::string::npos);
  EXPECT_EQ(html.find("disturbed or not settled"), std::string::npos);
  EXPECT_EQ(html.find("Record the session again"), std::string::npos);

  // Pose 5 bumped by 0.1 m/s^2 along its up axis for its whole hold (the
  // variance component absorbs part of it: one pose among few cannot be
  // told from scatter, hence 30 poses here).
  const SimulatedPose& p = session.poses[4];
  const Eigen::Vector3d up = input.log.accel[(p.begin + p.end) / 2].normalized();
  for (size_t i = p.begin; i < p.end; ++i) {
    input.log.accel[i] += 0.1 * session.accel_units_per_si * up;
  }
  Calibration d;
  ASSERT_TRUE(RunCalibration(config, input, &d)) << d.message;
  html = CalibrationToHtml(d, input.log, "disturbed");
  EXPECT_NE(html.find("pose 5 ("), std::string::npos);
  EXPECT_NE(html.find("disturbed or not settled"), std::string::npos);
  EXPECT_NE(html.find("record that pose again"), std::string::npos);
  EXPECT_EQ(html.find("Record the session again"), std::string::npos);

  // Three poses cannot calibrate nine parameters: record again.
  Calibration f;
  input.log = session.log;
  input.log.t.resize(session.poses[2].end);
  input.log.accel.resize(session.poses[2].end);
  input.log.gyro.resize(std::min(input.log.gyro.size(), input.log.t.size()));
  if (input.log.temperature.size() > input.log.t.size()) {
    input.log.temperature.resize(input.log.t.size());
  }
  EXPECT_FALSE(RunCalibration(config, input, &f));
  html = CalibrationToHtml(f, input.log, "failed");
  EXPECT_NE(html.find("Record the session again"), std::string::npos);
}

// A simulated session shaped like good1: its nine pose directions (x up and
// down, the rest in the y-z plane), nine poses for the nine parameters.
// u_xy and u_xz enter the magnitude only to second order there: the
// weakest is held (and the other too when still weak), named, and the other
// parameters' sigmas (conditional on them) agree with the truth, rms z over
// 60 sessions in [0.7, 1.4] (measured 0.90; 0.72 with a 0.2 % truth
// non-orthogonality instead of 1 %). They include the held terms' spread
// up to max_matrix_std (refinement.cc, AddHeldSpread): without it, the
// sigmas conditional on u_xy = u_xz = 0 gave rms z 1.84, and held at the
// coarse fit's value (which these poses leave far off) 20.
TEST(RealHonesty, WeakTermsHeldAndTheOtherSigmasConditionalOnThem) {
  std::vector<Eigen::Vector3d> directions = {
      {0.010, -0.005, -1.000}, {-1.000, -0.001, 0.031}, {0.000, -0.760, 0.650},
      {-0.020, 0.770, 0.637},  {0.999, 0.007, 0.036},   {0.003, -0.073, 0.997},
      {-0.007, 0.773, 0.635},  {0.007, 0.976, -0.218},  {0.004, -0.978, -0.208}};
  for (Eigen::Vector3d& d : directions) d.normalize();
  CalibrationOptions options;
  options.gravity.gravity = 9.80665;
  options.allow_undetermined = true;
  std::vector<double> z;
  int both = 0, sessions_held = 0, stalled = 0;
  std::mt19937_64 rng(33);
  for (int session = 0; session < 60; ++session) {
    const AccelModel truth = AccelModel::Random(AccelParameterization::kScaleMisalignment,
                                                9.80665 / 16384, 0.02, 0.01, 400, &rng);
    const std::vector<Position> positions =
        testing_util::MakePositions(truth, directions, 9.80665, 0.005, 0.02, 600, false, &rng);
    Calibration fit;
    // An exact fit on near-singular poses can stall; it says so (false).
    if (!CalibrateFromPositions(positions, options, &fit)) {
      EXPECT_NE(fit.message.find("did not converge"), std::string::npos) << fit.message;
      ++stalled;
      continue;
    }
    testing_util::ParameterEstimate e, t;
    ASSERT_TRUE(testing_util::EstimateOf(fit, options.refinement.parameterization, &e));
    t.value = testing_util::FreeParameters(truth, options.refinement.parameterization);
    t.sigma = Eigen::VectorXd::Zero(t.value.size());
    testing_util::AppendZ(e, t, &z);
    // One or both of the flat terms held (or none, when this session's
    // noise happens to determine them), nothing else; named in a warning.
    const std::vector<std::string>& undetermined = fit.refinement.observability.undetermined;
    if (undetermined.empty()) continue;
    ++sessions_held;
    for (const std::string& name : undetermined) {
      EXPECT_TRUE(name == "u_xy" || name == "u_xz") << session << ": " << name;
    }
    bool named = false;
    for (const std::string& w : fit.warnings) named |= w.find("conditional on holding") != w.npos;
    EXPECT_TRUE(named) << session;
    both += undetermined.size() == 2;
  }
  std::printf(
      "good1-shaped simulations: rms z %.2f over %zu (held in %d of 60, both in %d, stalled %d)\n",
      RmsOf(z), z.size(), sessions_held, both, stalled);
  EXPECT_LE(stalled, 3);
  EXPECT_GT(sessions_held, 30);
  EXPECT_GT(RmsOf(z), 0.7);
  EXPECT_LT(RmsOf(z), 1.4);
}

}  // namespace
}  // namespace gravcal
