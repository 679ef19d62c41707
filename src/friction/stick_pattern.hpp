// Warm start (FrictionOptions::warm_start; docs/friction.md, "Warm start"): the last solve's stick/slip pattern
// tried before the full solve. src/friction/stick_pattern.cpp.
#pragma once

#include "friction/friction_scratch.hpp"

namespace zwang::internal {

// The pattern kept from the last solve, for this solve's stuck set Θ₀ (fr.stuck, fs.lo, fs.hi and
// fs.tau_effective set): on success q̈* in ws.solution.qdd, ν in the sweep's ν columns, the bodies' accelerations
// in the sweep, μ* in fs.mu and the acceleration tolerance the states are told by; false when there is none to
// try or it does not hold (the sweep's results are then scratch for the full solve).
bool solveLastPattern(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& qd, const FrictionResult& fr, Workspace& ws,
                      FrictionScratch& fs, double& acc_tolerance);

// Keep the pattern of the solve just finished (the states on Θ₀) for the next call, or (keep false) forget it.
void rememberPattern(const Model& model, const Task& task, const FrictionResult& fr, bool keep, FrictionScratch& fs);

}  // namespace zwang::internal
