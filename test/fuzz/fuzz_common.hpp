// Shared by the libFuzzer targets: a finite-output check that aborts with a
// message naming the output (libFuzzer then saves the input as a crash), and
// the statuses a solve may return.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <Eigen/Core>

#include "zwang/status.hpp"

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

// The codes docs/errors.md lists for a solve (NotComputed is a query's: no solve returns it).
inline bool documented(StatusCode code) {
  switch (code) {
    case StatusCode::Ok:
    case StatusCode::SizeMismatch:
    case StatusCode::NonFinite:
    case StatusCode::WorkspaceTooSmall:
    case StatusCode::ModelMismatch:
    case StatusCode::Degenerate:
    case StatusCode::BadOption:
    case StatusCode::Infeasible:
    case StatusCode::MimicMismatch:
    case StatusCode::BadConfiguration: return true;
    case StatusCode::NotComputed:
    case StatusCode::EventCascade: return false;
  }
  return false;
}

}  // namespace zwang::fuzz
