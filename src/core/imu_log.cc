#include "gravcal/core/imu_log.h"

#include <cmath>
#include <sstream>

namespace gravcal {

bool ImuLog::Validate(std::string* error) const {
  const std::string name = source.empty() ? std::string("log") : source;
  auto fail = [&](const std::string& what) {
    if (error) *error = name + ": " + what;
    return false;
  };
  if (t.empty()) return fail("no samples");
  if (accel.size() != t.size()) return fail("accelerometer and time have different lengths");
  if (!gyro.empty() && gyro.size() != t.size())
    return fail("gyroscope and time have different lengths");
  if (!temperature.empty() && temperature.size() != t.size())
    return fail("temperature and time have different lengths");
  for (size_t i = 0; i < t.size(); ++i) {
    const bool ok = std::isfinite(t[i]) && (i == 0 || t[i] > t[i - 1]) && accel[i].allFinite() &&
                    (gyro.empty() || gyro[i].allFinite()) &&
                    (temperature.empty() || std::isfinite(temperature[i]));
    if (ok) continue;  // The message is built only for the bad sample.
    std::ostringstream where;
    where << "sample " << i << ": ";
    if (!std::isfinite(t[i])) return fail(where.str() + "time is not finite");
    if (i > 0 && !(t[i] > t[i - 1])) return fail(where.str() + "time does not increase");
    if (!accel[i].allFinite()) return fail(where.str() + "accelerometer is not finite");
    if (!gyro.empty() && !gyro[i].allFinite()) return fail(where.str() + "gyroscope is not finite");
    if (!temperature.empty() && !std::isfinite(temperature[i]))
      return fail(where.str() + "temperature is not finite");
  }
  return true;
}

}  // namespace gravcal
