#include "gravcal/estimation/error_state_layout.h"

namespace gravcal {

SensorErrorTerms SensorErrorTerms::ScaleOnly() { return SensorErrorTerms(); }

SensorErrorTerms SensorErrorTerms::ScaleAndCrossAxis() {
  SensorErrorTerms terms;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      if (r != c) terms.matrix_entries.emplace_back(r, c);
    }
  }
  return terms;
}

SensorErrorTerms SensorErrorTerms::ScaleAndUpperCrossAxis() {
  SensorErrorTerms terms;
  terms.matrix_entries.insert(terms.matrix_entries.end(), {{0, 1}, {0, 2}, {1, 2}});
  return terms;
}

bool SensorErrorTerms::IsValid(std::string* error) const {
  bool seen[3][3] = {};
  for (const auto& [r, c] : matrix_entries) {
    if (r < 0 || r > 2 || c < 0 || c > 2) {
      *error = "sensor error terms: matrix entries must have row and column in 0..2";
      return false;
    }
    if (seen[r][c]) {
      *error = "sensor error terms: an entry of E is listed twice";
      return false;
    }
    seen[r][c] = true;
  }
  return true;
}

ErrorStateLayout::ErrorStateLayout(const SensorErrorTerms& accel, const SensorErrorTerms& gyro,
                                   bool lever_arm)
    : accel_(accel), gyro_(gyro) {
  const int sizes[8] = {3,
                        3,
                        3,
                        3,
                        static_cast<int>(accel.matrix_entries.size()),
                        3,
                        static_cast<int>(gyro.matrix_entries.size()),
                        lever_arm ? 3 : 0};
  static const char* const kPrefix[8] = {"attitude", "velocity",  "position", "accel_bias",
                                         "accel",    "gyro_bias", "gyro",     "lever_arm"};
  const char* axes = "xyz";
  for (int b = 0; b < 8; ++b) {
    offset_[b] = size_;
    size_of_[b] = sizes[b];
    size_ += sizes[b];
    const bool matrix = b == static_cast<int>(StateBlock::kAccelMatrix) ||
                        b == static_cast<int>(StateBlock::kGyroMatrix);
    if (!matrix) {
      for (int i = 0; i < sizes[b]; ++i) names_.push_back(std::string(kPrefix[b]) + "_" + axes[i]);
      continue;
    }
    const SensorErrorTerms& terms = b == static_cast<int>(StateBlock::kAccelMatrix) ? accel : gyro;
    for (const auto& [r, c] : terms.matrix_entries) {
      names_.push_back(r == c ? std::string(kPrefix[b]) + "_scale_" + axes[r]
                              : std::string(kPrefix[b]) + "_cross_" + axes[r] + axes[c]);
    }
  }
}

}  // namespace gravcal
