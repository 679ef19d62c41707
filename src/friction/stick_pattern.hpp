// The pattern search (FrictionMethod::StickPatterns, the automatic choice and FrictionOptions::warm_start;
// docs/friction.md, "The pattern search"): μ* found by one pass of the sweeps per stick/slip pattern, no K formed.
// src/friction/stick_pattern.cpp.
#pragma once

#include "friction/friction_scratch.hpp"
#include "zwang/friction.hpp"

namespace zwang::internal {

// A pattern kept by the last solve for this model and this task object (another stuck set is mapped onto it).
bool keptPatternApplies(const Model& model, const Task& task, const FrictionScratch& fs);

// The search for this solve's stuck set Θ₀ (fr.stuck, fs.lo, fs.hi and fs.tau_effective set, the kinematics done by
// outwardSweep), at most max_passes passes of the sweeps, from the kept pattern (from_kept: it applies) mapped onto
// Θ₀ or from every stuck DOF sticking; options' margin and max_iterations serve the least-effort choice. On success: q̈* in ws.solution.qdd, ν in
// the sweep's ν columns, the bodies' accelerations in the sweep, μ* in fs.mu, the acceleration tolerance the states
// are told by, and true. False when no pattern holds within the passes or μ* may not be unique: the full solve
// then runs on the same kinematics. `passes` counts the passes made.
bool searchPatterns(const Model& model, const Task& task, const FrictionResult& fr, bool from_kept, int max_passes,
                    const FrictionOptions& options, Workspace& ws, FrictionScratch& fs, double& acc_tolerance,
                    int& passes);

// Keep the pattern of the solve just finished (the states on Θ₀) for the next call, or (keep false) forget it.
void rememberPattern(const Model& model, const Task& task, const FrictionResult& fr, bool keep, FrictionScratch& fs);

}  // namespace zwang::internal
