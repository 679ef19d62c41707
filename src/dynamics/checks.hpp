// Input checks for the hot path: no allocation, no exception; a Status that
// names the input and the index at fault.
#pragma once

#include <Eigen/Core>

#include "zwang/configuration.hpp"
#include "zwang/model.hpp"
#include "zwang/status.hpp"
#include "zwang/workspace.hpp"

#include "dynamics/workspace_scratch.hpp"

namespace zwang::internal {

using VectorRef = Eigen::Ref<const Eigen::VectorXd>;

inline Status checkVector(const char* name, const VectorRef& x, int expected) {
  if (x.size() == expected && x.allFinite()) return {};  // the usual case: one vectorised pass
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

// The state checks of every algorithm, for q (nq() entries) and the vectors of
// nv() entries (q̇, q̈, τ). A model without quaternions checks q inline: the
// hot path pays for no call; a quaternion's norm goes to checkConfiguration. The size messages
// name the base's share when there is one ("… the model has nv = 9 (3 base
// velocity coordinates + 6 joint DOFs)").
// "joints" when every joint below the root has one DOF, else "joint DOFs": what dof() counts.
const char* jointDofsWord(const Model& model);
Status velocitySizeMismatch(const Model& model, const char* name, Eigen::Index size);
inline Status checkStateConfiguration(const Model& model, const VectorRef& q) {
  return model.nq() == model.nv() && model.nv() == model.dof() ? checkVector("q", q, model.nq())
                                                               : checkConfiguration(model, q);
}
inline Status checkVelocityVector(const Model& model, const char* name, const VectorRef& x) {
  if (x.size() != model.nv()) return velocitySizeMismatch(model, name, x.size());
  return checkVector(name, x, model.nv());  // the size holds: only the finiteness message can come back
}

// A workspace made for a model with the same joints but another base (its H
// and τ are nv × nv and nv) must be refused before anything is written:
// Workspace::dof() alone cannot tell a fixed arm from the same arm floating.
inline bool workspaceFitsModel(const Model& model, const Workspace& ws) {
  const WorkspaceScratch& sw = scratchOf(ws);
  return ws.tau.size() == model.nv() && ws.H.rows() == model.nv() && ws.H.cols() == model.nv() &&
         static_cast<int>(sw.S.size()) == model.bodyCount();
}
// The ModelMismatch status for a workspace that does not fit (names both nv),
// or SizeMismatch for a workspace that fits whose H or τ a user resized.
Status workspaceMismatch(const Model& model, const Workspace& ws);

// The checks the queries of kinematics.hpp and center_of_mass.hpp share
// (src/dynamics/kinematics.cpp). The workspace made for this model:
Status checkKinematicsWorkspace(const Model& model, const Workspace& ws) noexcept;
// and holding the `needed` results for this model and this state
// (Workspace::kinematics), for the queries that read a workspace after the
// call that computed them; NotComputed naming what to call first otherwise.
// qd is zero-length for a pose query; `query` names the caller in messages.
Status checkKinematicsHeld(const Model& model, const Workspace& ws, const VectorRef& q, const VectorRef& qd,
                           KinematicsStage needed, const char* query) noexcept;
// True when the workspace holds poses of this model at exactly this q.
bool posesHeldAt(const Model& model, const Workspace& ws, const VectorRef& q);

}  // namespace zwang::internal
