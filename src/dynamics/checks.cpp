#include "dynamics/checks.hpp"

namespace zwang::internal {

const char* jointDofsWord(const Model& model) {
  return model.dof() == static_cast<int>(model.joints().size()) ? "joints" : "joint DOFs";
}

Status velocitySizeMismatch(const Model& model, const char* name, Eigen::Index size) {
  if (model.baseVelocitySize() == 0 && model.nv() == static_cast<int>(model.joints().size()))  // one-DOF joints
    return Status::error(StatusCode::SizeMismatch, "%s has %ld entries, the model has %d joints", name,
                         static_cast<long>(size), model.nv());
  return Status::error(
      StatusCode::SizeMismatch, "%s has %ld entries, the model has nv = %d (%d base velocity coordinates + %d %s)",
      name, static_cast<long>(size), model.nv(), model.baseVelocitySize(), model.dof(), jointDofsWord(model));
}

Status workspaceMismatch(const Model& model, const Workspace& ws) {
  const WorkspaceScratch& sw = scratchOf(ws);
  const bool bodies_fit = static_cast<int>(sw.S.size()) == model.bodyCount();
  // One of the two of the right size: the workspace fits, the other was resized since.
  if (bodies_fit && ws.tau.size() == model.nv())
    return Status::error(StatusCode::SizeMismatch,
                         "workspace result H is %ldx%ld, expected %dx%d (a workspace's results must keep their sizes)",
                         static_cast<long>(ws.H.rows()), static_cast<long>(ws.H.cols()), model.nv(), model.nv());
  if (bodies_fit && ws.H.rows() == model.nv() && ws.H.cols() == model.nv())
    return Status::error(StatusCode::SizeMismatch,
                         "workspace result tau has %ld entries, expected nv = %d (a workspace's results must keep "
                         "their sizes)",
                         static_cast<long>(ws.tau.size()), model.nv());
  return Status::error(StatusCode::ModelMismatch,
                       "workspace was made for a model with nv = %ld, this one has nv = %d (a %s base and %d joints)",
                       static_cast<long>(ws.tau.size()), model.nv(), toString(model.baseType()), model.dof());
}

}  // namespace zwang::internal
