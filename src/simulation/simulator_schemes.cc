// The schemes of the multi-position simulator: named pose sets and planned
// poses as nominal attitudes (simulator_schemes.h, SchemeAttitudes).
#include "simulation/simulator_schemes.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "util/so3.h"
#include "util/units.h"

namespace gravcal {
namespace internal {
namespace {

// Limit that keeps a typo from asking for gigabytes of poses.
constexpr long kMaxRandomPoses = 100000;

// Body-to-navigation attitude from roll (about x) then pitch (about y), zero
// heading: C_bn = R_y(pitch) R_x(roll), so gravity in the body frame reads
// g (-sin(pitch), sin(roll) cos(pitch), cos(roll) cos(pitch)).
Eigen::Quaterniond RollPitch(double roll_deg, double pitch_deg) {
  const double d = kDegToRad;
  return AxisAngle(pitch_deg * d, Eigen::Vector3d::UnitY()) *
         AxisAngle(roll_deg * d, Eigen::Vector3d::UnitX());
}

// A uniformly distributed rotation (Shoemake's method).
Eigen::Quaterniond UniformRotation(std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double u1 = u01(*rng);
  const double u2 = u01(*rng);
  const double u3 = u01(*rng);
  const double a = std::sqrt(1.0 - u1);
  const double b = std::sqrt(u1);
  return Eigen::Quaterniond(b * std::cos(2.0 * M_PI * u3), a * std::sin(2.0 * M_PI * u2),
                            a * std::cos(2.0 * M_PI * u2), b * std::sin(2.0 * M_PI * u3))
      .normalized();
}

}  // namespace

Eigen::Quaterniond UpToZenith(const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  const Eigen::Vector3d axis = u.cross(Eigen::Vector3d::UnitZ());
  if (axis.norm() < 1e-12) {
    return u.z() > 0.0 ? Eigen::Quaterniond::Identity() : AxisAngle(M_PI, Eigen::Vector3d::UnitX());
  }
  return AxisAngle(std::atan2(axis.norm(), u.z()), axis.normalized());
}

int UpAxis(const Eigen::Quaterniond& attitude) {
  const Eigen::Vector3d up = attitude.conjugate() * Eigen::Vector3d::UnitZ();
  for (int axis = 0; axis < 3; ++axis) {
    if (up(axis) > 1.0 - 1e-9) return 2 * axis;
    if (up(axis) < -1.0 + 1e-9) return 2 * axis + 1;
  }
  return -1;
}

bool PlannedTurns(const SimulatorOptions& options) {
  return options.planned_poses.size() > 1 &&
         std::all_of(options.planned_poses.begin() + 1, options.planned_poses.end(),
                     [](const PlannedHold& p) { return p.turn_axis.norm() > 0.5; });
}

bool MakeNominalPoses(const SimulatorOptions& options, uint64_t seed, NominalPoses* poses,
                      std::string* error) {
  NominalPoses& n = *poses;
  if (options.planned_poses.empty()) {
    if (!SchemeAttitudes(options.scheme, seed, &n.attitudes, &n.nominal_up, error)) return false;
  }
  n.hold_seconds.assign(n.attitudes.size(), options.hold_seconds);
  const bool chained = PlannedTurns(options);
  for (const PlannedHold& p : options.planned_poses) {
    // A turn about the body axis a by t: q' = q exp(t a).
    n.attitudes.push_back(chained && !n.attitudes.empty()
                              ? (n.attitudes.back() * AxisAngle(p.turn_angle_deg * M_PI / 180.0,
                                                                p.turn_axis.normalized()))
                                    .normalized()
                              : UpToZenith(p.up));
    n.nominal_up.push_back(UpAxis(n.attitudes.back()));
    n.hold_seconds.push_back(p.hold_seconds);
  }
  return true;
}

}  // namespace internal

using internal::AxisAngle;

bool SimulatorScheme::PoseCount(long* count, std::string* error) const {
  constexpr long kFixed[] = {6, 12, 10};
  switch (kind) {
    case PoseScheme::kSix:
    case PoseScheme::kTwelve:
    case PoseScheme::kTen:
      *count = kFixed[static_cast<int>(kind)];
      return true;
    case PoseScheme::kRandom:
      if (random_poses < 1 || random_poses > internal::kMaxRandomPoses) {
        if (error) {
          *error = "random:" + std::to_string(random_poses) +
                   ": N in random:N must be an integer from 1 to " +
                   std::to_string(internal::kMaxRandomPoses);
        }
        return false;
      }
      *count = random_poses;
      return true;
  }
  if (error) *error = "not one of " + AcceptedNames(PoseScheme());
  return false;
}

std::string ToString(const SimulatorScheme& scheme) {
  const std::string name = ToString(scheme.kind);
  return scheme.kind == PoseScheme::kRandom ? name + ":" + std::to_string(scheme.random_poses)
                                            : name;
}

bool ParseSimulatorScheme(const std::string& text, SimulatorScheme* scheme, std::string* error) {
  const size_t colon = text.find(':');
  SimulatorScheme parsed;
  if (!FromString(text.substr(0, colon), &parsed.kind) ||
      (colon != std::string::npos) != (parsed.kind == PoseScheme::kRandom)) {
    if (error) *error = "'" + text + "' is not one of " + AcceptedNames(PoseScheme());
    return false;
  }
  if (parsed.kind == PoseScheme::kRandom) {
    const std::string digits = text.substr(colon + 1);
    bool ok = !digits.empty() && digits.size() <= 9;
    for (char c : digits) ok = ok && c >= '0' && c <= '9';
    parsed.random_poses = ok ? std::stol(digits) : 0;
  }
  long count = 0;
  if (!parsed.PoseCount(&count, nullptr)) {
    if (error) {
      *error = "'" + text + "': N in random:N must be an integer from 1 to " +
               std::to_string(internal::kMaxRandomPoses);
    }
    return false;
  }
  *scheme = parsed;
  return true;
}

bool SchemeAttitudes(const SimulatorScheme& scheme, uint64_t seed,
                     std::vector<Eigen::Quaterniond>* attitudes, std::vector<int>* nominal_up,
                     std::string* error) {
  if (attitudes == nullptr || nominal_up == nullptr) {
    if (error) *error = "SchemeAttitudes: null output";
    return false;
  }
  long count = 0;
  if (!scheme.PoseCount(&count, error)) return false;
  const PoseScheme kind = scheme.kind;
  attitudes->clear();
  nominal_up->clear();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  const double h = M_PI / 2.0;
  switch (kind) {
    case PoseScheme::kTwelve:
    case PoseScheme::kSix:
      // +x, -x, +y, -y, +z, -z up (the body axis that points up).
      attitudes->push_back(AxisAngle(-h, y));
      attitudes->push_back(AxisAngle(h, y));
      attitudes->push_back(AxisAngle(h, x));
      attitudes->push_back(AxisAngle(-h, x));
      attitudes->push_back(Eigen::Quaterniond::Identity());
      attitudes->push_back(AxisAngle(M_PI, x));
      if (kind == PoseScheme::kTwelve) {
        // Chen 2012: the YZ, XZ and XY planes tilted to about 45 and 135
        // degrees. Up directions (body frame) are six of the twelve cube edge
        // midpoints, one from each opposite pair.
        const Eigen::Vector3d ups[6] = {{0, 1, 1},   {0, 1, -1}, {-1, 0, 1},
                                        {-1, 0, -1}, {1, 1, 0},  {1, -1, 0}};
        for (const Eigen::Vector3d& up : ups) {
          attitudes->push_back(internal::UpToZenith(up));
        }
      }
      break;
    case PoseScheme::kTen: {
      // CN101907638B: ten poses of differing roll and pitch (degrees).
      const double roll_pitch[10][2] = {{0, 0},   {180, 0}, {90, 0},   {-90, 0},  {0, 90},
                                        {0, -90}, {45, 45}, {-45, 45}, {45, -45}, {135, -45}};
      for (const auto& rp : roll_pitch) attitudes->push_back(internal::RollPitch(rp[0], rp[1]));
      break;
    }
    case PoseScheme::kRandom: {
      // A stream of its own, so the poses do not share numbers with the
      // simulator's other draws from the same seed.
      std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
      for (long k = 0; k < count; ++k) attitudes->push_back(internal::UniformRotation(&rng));
      break;
    }
  }
  for (const Eigen::Quaterniond& q : *attitudes) nominal_up->push_back(internal::UpAxis(q));
  return true;
}

}  // namespace gravcal
