// Input checks for the hot path: no allocation, no exception; a Status that
// names the input and the index at fault.
#pragma once

#include <Eigen/Core>

#include "zwang/status.hpp"

namespace zwang::internal {

using VectorRef = Eigen::Ref<const Eigen::VectorXd>;

inline Status checkVector(const char* name, const VectorRef& x, int expected) {
  if (x.size() != expected)
    return Status::error(StatusCode::SizeMismatch, "%s has %ld entries, the model has %d joints", name,
                         static_cast<long>(x.size()), expected);
  for (Eigen::Index k = 0; k < x.size(); ++k)
    if (!std::isfinite(x[k]))
      return Status::error(StatusCode::NonFinite, "%s[%ld] is %g (not finite)", name, static_cast<long>(k), x[k]);
  return {};
}

template <class Derived>
inline Status checkFinite(const char* name, const Eigen::MatrixBase<Derived>& x) {
  for (Eigen::Index k = 0; k < x.size(); ++k)
    if (!std::isfinite(x.derived().data()[k]))
      return Status::error(StatusCode::NonFinite, "%s holds a non-finite value (%g) at entry %ld", name,
                           x.derived().data()[k], static_cast<long>(k));
  return {};
}

}  // namespace zwang::internal
