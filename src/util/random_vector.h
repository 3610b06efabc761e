// util/random_vector.h (private): three random draws into a vector, in an
// order that does not depend on the compiler.
//
// Eigen::Vector3d(n(rng), n(rng), n(rng)) leaves the order of the three
// draws to the compiler (function arguments are unsequenced): g++ draws the
// z component first, clang the x component, so the same seed simulated a
// different session with each compiler (found by the clang sanitizer build:
// its simulated tables and detections differed from g++'s). The draws here
// are sequenced z, y, x: the order g++ gave the old expression, so every
// session simulated before keeps its numbers.
#ifndef GRAVCAL_SRC_UTIL_RANDOM_VECTOR_H_
#define GRAVCAL_SRC_UTIL_RANDOM_VECTOR_H_

#include <Eigen/Core>

namespace gravcal {
namespace internal {

// (draw(), draw(), draw()) with the z component drawn first, then y, then x.
template <typename Draw>
Eigen::Vector3d DrawVector3(Draw&& draw) {
  const double z = draw();
  const double y = draw();
  const double x = draw();
  return Eigen::Vector3d(x, y, z);
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_RANDOM_VECTOR_H_
