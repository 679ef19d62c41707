/// \file
/// Status of a hot-path call: no exception, no allocation; the message is held
/// in a fixed buffer inside the Status itself.
#pragma once

#include <cstdio>

namespace zwang {

/// What went wrong in a hot-path call (docs/errors.md, "Solve statuses").
enum class StatusCode {
  Ok = 0,             ///< success
  SizeMismatch,       ///< an input vector has the wrong length
  NonFinite,          ///< an input holds NaN or Inf
  WorkspaceTooSmall,  ///< no room for the task's rows: out of memory, or a workspace of a model with fewer mimic joints
  ModelMismatch,      ///< task or workspace built for another model
  Degenerate,         ///< a joint has no inertia to move (D_j ≤ 0) in this configuration
  BadOption,          ///< an option or per-solve override is out of range
  Infeasible,         ///< the task drives a joint into its position limit (outputs finite, not physical)
  MimicMismatch,      ///< a mimic joint's q or q̇ does not follow its leader's (Model::followLeaders)
  BadConfiguration,   ///< q is no pose: a free base's quaternion off unit length
  NotComputed,        ///< a query for results the workspace does not hold (kinematics.hpp): compute them first
  EventCascade,       ///< a simulation step met more events than SimulationOptions::max_events_per_step (Zeno)
};

/// The result of a hot-path call: a code and, on error, a message naming the input at fault.
struct Status {
  StatusCode code = StatusCode::Ok;  ///< Ok, or what went wrong
  char message[240];                 ///< one line naming the input at fault; empty when ok

  /// Ok with an empty message. Only the message's first byte is written: the
  /// hot path makes a Status at every check, and zeroing all 240 bytes each time
  /// cost a solve more than the checks themselves.
  Status() noexcept { message[0] = '\0'; }

  /// True when the call succeeded.
  bool ok() const { return code == StatusCode::Ok; }
  /// The same as ok(): `if (!status) …`.
  explicit operator bool() const { return ok(); }

  /// An error status whose message is printf-formatted into the fixed buffer (truncated if longer).
  template <class... Args>
  static Status error(StatusCode code, const char* format, Args... args) {
    Status s;
    s.code = code;
    if constexpr (sizeof...(Args) == 0)
      std::snprintf(s.message, sizeof s.message, "%s", format);  // a fixed message: no format to interpret
    else
      std::snprintf(s.message, sizeof s.message, format, args...);
    return s;
  }
};

}  // namespace zwang
