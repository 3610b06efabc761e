// Private: the pieces of the multi-IMU calibration (methods/multi_imu.h):
// the session's poses and starting values (multi_imu_poses.cc), the joint
// Ceres problem (multi_imu_fit.cc), the results (multi_imu_output.cc), the
// timing and checks (multi_imu_checks.cc), and their order
// (multi_imu.cc).
#ifndef GRAVCAL_SRC_METHODS_MULTI_IMU_INTERNAL_H_
#define GRAVCAL_SRC_METHODS_MULTI_IMU_INTERNAL_H_

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "gravcal/detection/static_detector.h"
#include "gravcal/methods/multi_imu.h"
#include "gravcal/residuals/gyro_rotation_residual.h"

namespace gravcal {
namespace internal {

// One IMU's view of one shared pose.
struct PlatePoseData {
  size_t begin = 0, end = 0;                                // samples of its log
  Eigen::Vector3d accel_mean = Eigen::Vector3d::Zero();     // raw
  double accel_sigma = 0.0;                                 // of the mean, m/s^2
  Eigen::Vector3d accel_raw_std = Eigen::Vector3d::Zero();  // per sample, raw
  Eigen::Vector3d gyro_mean = Eigen::Vector3d::Zero();      // raw
  double gyro_sigma = 0.0;                                  // of the mean, raw
};

// One IMU's data: its poses (one per shared pose), its turns (turn k joins
// pose k and k + 1; empty t when unusable), its noise per sample.
struct PlateImuData {
  const PlateImu* imu = nullptr;
  bool has_gyro = false;
  std::vector<PlatePoseData> poses;
  std::vector<GyroRotationData> turns;
  double accel_noise = 0.0;  // m/s^2 per sample
  double gyro_noise = 0.0;   // rad/s per sample (nominal scale)
};

// The parameters of one IMU: b, U, b_g, M_g, and C = c0 Exp(delta); when
// split >= 0 the poses from `split` on use c0_after Exp(delta_after).
struct PlateImuParameters {
  double bias[3] = {0, 0, 0};
  double upper[6] = {1, 0, 0, 1, 0, 1};
  double gyro_bias[3] = {0, 0, 0};
  double gyro_matrix[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  double delta[3] = {0, 0, 0};
  double delta_after[3] = {0, 0, 0};
  Eigen::Matrix3d c0 = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d c0_after = Eigen::Matrix3d::Identity();
  int split = -1;

  Eigen::Matrix3d Rotation() const;
  Eigen::Matrix3d RotationAfter() const;
  Eigen::Matrix3d UpperMatrix() const;
  Eigen::Matrix3d GyroMatrix() const;
  // The calibrated, normalised direction of its pose k.
  Eigen::Vector3d Direction(const PlatePoseData& pose) const;
};

// The tangent basis E (2 x 3, rows orthonormal and orthogonal to d) of a
// turn's end direction d.
Eigen::Matrix<double, 2, 3> TangentBasis(const Eigen::Vector3d& d);

// Variance factors of the three row groups.
struct GroupFactors {
  double accel = 1.0, gyro = 1.0, turn = 1.0;
};

// One solve: the IMUs `members` (indices into data/params), `held` the one
// whose rotation is held (C = c0), poses `dirs` (plate frame, unit).
struct FitOutput {
  bool ok = false;
  std::string message;
  // chi2 (unit weights) and rows per member and group (accel poses, gyro
  // poses, turns).
  std::vector<std::array<double, 3>> chi2;
  std::vector<std::array<int, 3>> rows;
  int parameters = 0;
  // Per member: covariance of [b U b_g M_g delta] (21 or 24; NaN rows and
  // columns where undetermined), and the rms of its pose rows (m/s^2) and
  // turn rows (deg).
  std::vector<Eigen::MatrixXd> covariance;
  std::vector<double> accel_rms, turn_rms_deg;
};

// One solve of `members` with the group factors of each (empty: all 1);
// the covariance (and the null space) when `covariance`.
bool Fit(const std::vector<PlateImuData>& data, const std::vector<int>& members, int held,
         double gravity, const std::vector<GroupFactors>& member_factors, bool covariance,
         int max_iterations, std::vector<PlateImuParameters>* params,
         std::vector<Eigen::Vector3d>* dirs, FitOutput* out);

// The group factors of each member of a solve: chi2 / dof per member and
// group, at least 1 (and the dof of each when group_dofs is not null). Per
// IMU: one unit's misfit (or noisier sensor) does not inflate the others'
// sigmas.
std::vector<GroupFactors> FactorsOf(const FitOutput& out,
                                    std::vector<std::array<double, 3>>* group_dofs);

// Solve, reweigh the groups, solve again with the covariance. With `prior`
// (one per member: each IMU's factors from its separate fit) a member
// keeps its prior factor unless this fit's rows of it show a misfit beyond
// 2 standard deviations of chi2 / dof above it (the poses not shared as
// modelled): its own data measure its noise, and the joint fit's sigmas
// are then never larger than the separate fit's by a noisier estimate of
// the same factor.
bool FitWithFactors(const std::vector<PlateImuData>& data, const std::vector<int>& members,
                    int held, double gravity, int max_iterations,
                    const std::vector<GroupFactors>& prior, std::vector<PlateImuParameters>* params,
                    std::vector<Eigen::Vector3d>* dirs, std::vector<GroupFactors>* factors,
                    FitOutput* out);

// Starting intrinsics of one IMU from its poses (an ellipsoid through them).
void StartIntrinsics(const PlateImuData& imu, double gravity, PlateImuParameters* p);

// Starting gyroscope (bias the still mean, the scale stated or from the
// turns, said in *notes).
void StartGyro(const PlateImuData& imu, const std::vector<Eigen::Vector3d>& dirs,
               PlateImuParameters* p, std::vector<std::string>* notes);

// The poses held still by every IMU: time windows in the reference's
// detection intersected with every other IMU's (notes name those left out).
bool SharedPoses(const std::vector<PlateImu>& imus, const std::vector<StaticDetection>& detections,
                 int reference, std::vector<std::pair<double, double>>* windows,
                 std::vector<std::string>* notes);

// One IMU's view of the window [begin, end] of its log.
PlatePoseData PoseOf(const ImuLog& log, double begin, double end);

// The per-IMU Calibration in the existing schema.
void FillCalibration(const PlateImuData& imu, const PlateImuParameters& p,
                     const Eigen::MatrixXd& cov, double gravity, Calibration* c);

// The standard deviations of [b U b_g M_g] (21; gyro NaN when absent).
std::vector<double> StdsOf(const Eigen::MatrixXd& cov, bool gyro);

// Expands a member covariance without gyro (9 + 3) to the 24 layout.
Eigen::MatrixXd FullLayout(const Eigen::MatrixXd& cov, bool gyro);

// The single shared pose: each unit's offset along gravity only.
void SinglePose(const std::vector<PlateImuData>& data, const MultiImuOptions& options,
                MultiImuResult* result);

// R minimising sum |x_k - R y_k|^2 (Wahba, by SVD).
Eigen::Matrix3d Wahba(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y);

// Time offsets of every IMU's gyroscope to the reference (methods/
// multi_imu.h), into result->imus[i] and result->time_offset_covariance.
void EstimateTimeOffsets(const std::vector<PlateImuData>& data,
                         const std::vector<PlateImuParameters>& params, int reference,
                         const MultiImuOptions& options, MultiImuResult* result);

// The permutation check: warnings into result.
void CheckMountings(const std::vector<PlateImuData>& data,
                    const std::vector<PlateImuParameters>& params, int reference,
                    const MultiImuOptions& options, MultiImuResult* result);

// The slip check: the unit that moved and the first pose after its move
// (-1 when none or not attributable), warnings into result.
int FindMovedUnit(const std::vector<PlateImuData>& data,
                  const std::vector<PlateImuParameters>& params, const MultiImuOptions& options,
                  int* split, MultiImuResult* result);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_MULTI_IMU_INTERNAL_H_
