// Shared by the libFuzzer targets: a finite-output check that aborts with a
// message naming the output (libFuzzer then saves the input as a crash).
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <Eigen/Core>

namespace zwang::fuzz {

[[noreturn]] inline void failure(const char* what, const char* detail) {
  std::fprintf(stderr, "zwang fuzz failure: %s (%s)\n", what, detail);
  std::abort();
}

template <class Derived>
void requireFinite(const Eigen::DenseBase<Derived>& x, const char* what, const char* context) {
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    for (Eigen::Index j = 0; j < x.cols(); ++j)
      if (!std::isfinite(x(i, j))) {
        std::fprintf(stderr, "zwang fuzz failure: %s(%ld, %ld) = %g after %s\n", what, static_cast<long>(i),
                     static_cast<long>(j), x(i, j), context);
        std::abort();
      }
}

inline void requireFinite(double x, const char* what, const char* context) {
  if (!std::isfinite(x)) {
    std::fprintf(stderr, "zwang fuzz failure: %s = %g after %s\n", what, x, context);
    std::abort();
  }
}

}  // namespace zwang::fuzz
