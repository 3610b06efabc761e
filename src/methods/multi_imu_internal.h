// Private: the pieces of the multi-IMU calibration (methods/multi_imu.h)
// shared by its fit (multi_imu.cc) and its timing and checks
// (multi_imu_checks.cc).
#ifndef GRAVCAL_SRC_METHODS_MULTI_IMU_INTERNAL_H_
#define GRAVCAL_SRC_METHODS_MULTI_IMU_INTERNAL_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/methods/multi_imu.h"
#include "gravcal/residuals/gyro_rotation_residual.h"

namespace gravcal {
namespace internal {

// One IMU's view of one shared pose.
struct PlatePoseData {
  size_t begin = 0, end = 0;                             // samples of its log
  Eigen::Vector3d accel_mean = Eigen::Vector3d::Zero();  // raw
  double accel_sigma = 0.0;                              // of the mean, m/s^2
  Eigen::Vector3d gyro_mean = Eigen::Vector3d::Zero();   // raw
  double gyro_sigma = 0.0;                               // of the mean, raw
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
