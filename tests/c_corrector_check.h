// The generated C corrector (export --to c) compiled by a real compiler and
// run over the rows of a log, for the tests that compare it with apply.
#ifndef GRAVCAL_TESTS_C_CORRECTOR_CHECK_H_
#define GRAVCAL_TESTS_C_CORRECTOR_CHECK_H_

#include <Eigen/Core>
#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "gravcal/core/imu_log.h"

namespace gravcal {
namespace testing_util {

// One row corrected by the C code: in double and in float.
struct CCorrectedRow {
  Eigen::Vector3d a, w, af, wf;
};

// Compiles dir/gravcal_correct.c (gcc -std=c99 -Wall -Wextra -Werror
// -pedantic -O2) with a main that reads rows "t,ax,ay,az,gx,gy,gz,temp"
// (`separator` between the values: "," or " ") from the standard output of
// the shell command `rows`, and corrects each in double and float: with
// `lag`, by gravcal_correct_sample and its lag state (as apply), else by
// the stateless gravcal_accel_correct and gravcal_gyro_correct. False with
// `error` (the compiler's messages) when it does not build or run.
inline bool RunCCorrector(const std::string& dir, const std::string& rows,
                          const std::string& separator, bool lag, std::vector<CCorrectedRow>* out,
                          std::string* error) {
  std::string format = "%lf";
  for (int k = 1; k < 8; ++k) format += separator + "%lf";
  const std::string correct =
      lag ? "    gravcal_correct_sample(&lag, v, u, temp, t, a, w);\n"
            "    for (i = 0; i < 3; ++i) { vf[i] = (float)v[i]; uf[i] = (float)u[i]; }\n"
            "    gravcal_correct_sample_f(&lag_f, vf, uf, (float)temp, (float)t, af, wf);\n"
          : "    gravcal_accel_correct(v, temp, t, a);\n"
            "    gravcal_gyro_correct(u, a, temp, t, w);\n"
            "    for (i = 0; i < 3; ++i) { vf[i] = (float)v[i]; uf[i] = (float)u[i]; }\n"
            "    gravcal_accel_correct_f(vf, (float)temp, (float)t, af);\n"
            "    gravcal_gyro_correct_f(uf, af, (float)temp, (float)t, wf);\n";
  std::ofstream(dir + "/main.c")
      << "#include <stdio.h>\n#include \"gravcal_correct.h\"\n"
      << "int main(void) {\n"
      << "  double t, v[3], u[3], temp, a[3], w[3];\n"
      << "  float vf[3], uf[3], af[3], wf[3];\n"
      << "  int i;\n"
      << (lag ? "  gravcal_lag_state lag;\n  gravcal_lag_state_f lag_f;\n"
                "  gravcal_lag_init(&lag);\n  gravcal_lag_init_f(&lag_f);\n"
              : "")
      << "  while (scanf(\"" << format
      << "\", &t, &v[0], &v[1], &v[2], &u[0], &u[1], &u[2], &temp) == 8) {\n"
      << correct
      << "    printf(\"%.17g %.17g %.17g %.17g %.17g %.17g %.9g %.9g %.9g %.9g %.9g %.9g\\n\", "
         "a[0], a[1], a[2], w[0], w[1], w[2], af[0], af[1], af[2], wf[0], wf[1], wf[2]);\n"
      << "  }\n  return 0;\n}\n";
  const std::string build = "gcc -std=c99 -Wall -Wextra -Werror -pedantic -O2 -o " + dir + "/run " +
                            dir + "/gravcal_correct.c " + dir + "/main.c -lm 2> " + dir +
                            "/gcc.txt";
  if (std::system(build.c_str()) != 0) {
    *error = Slurp(dir + "/gcc.txt");
    return false;
  }
  if (std::system((rows + " | " + dir + "/run > " + dir + "/c_out.txt").c_str()) != 0) {
    *error = "the C program failed";
    return false;
  }
  std::ifstream in(dir + "/c_out.txt");
  out->clear();
  for (CCorrectedRow r; in >> r.a(0) >> r.a(1) >> r.a(2) >> r.w(0) >> r.w(1) >> r.w(2) >> r.af(0) >>
                        r.af(1) >> r.af(2) >> r.wf(0) >> r.wf(1) >> r.wf(2);) {
    out->push_back(r);
  }
  return true;
}

// The largest |x - y| / |y| over the rows, of the double and of the float
// results against `expected` (accelerometer and gyroscope).
inline void WorstRelative(const std::vector<CCorrectedRow>& rows, const ImuLog& expected,
                          double* worst_double, double* worst_float) {
  const auto relative = [](const Eigen::Vector3d& x, const Eigen::Vector3d& y) {
    return (x - y).norm() / std::max(y.norm(), 1e-300);
  };
  *worst_double = *worst_float = 0.0;
  for (size_t n = 0; n < std::min(rows.size(), expected.size()); ++n) {
    const CCorrectedRow& r = rows[n];
    *worst_double = std::max(
        {*worst_double, relative(r.a, expected.accel[n]), relative(r.w, expected.gyro[n])});
    *worst_float = std::max(
        {*worst_float, relative(r.af, expected.accel[n]), relative(r.wf, expected.gyro[n])});
  }
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_C_CORRECTOR_CHECK_H_
