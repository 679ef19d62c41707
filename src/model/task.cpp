#include "zwang/task.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace zwang {

Task::Task(const Model& model) : dof_(model.dof()), frames_(static_cast<int>(model.frames().size())) {
  for (const Frame& f : model.frames()) {
    frame_names_.push_back(f.name);
    frame_bodies_.push_back(f.body);
  }
  reorder();
}

namespace {
int lookup(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) throw ModelError("task: the model has no frame '" + name + "'");
  return static_cast<int>(it - names.begin());
}
}  // namespace

int Task::addConstraint(int frame, const ConstraintMatrix& A, Expressed expressed) {
  if (frame < 0 || frame >= frames_) throw ModelError("task: frame index " + std::to_string(frame) + " out of range");
  if (A.cols() == 0) throw ModelError("task: a constraint needs at least one column");
  if (!A.allFinite())
    throw ModelError("task: constraint matrix on frame '" + frame_names_[static_cast<std::size_t>(frame)] +
                     "' is not finite");
  const int first = constraintRows();
  groups_.push_back(ConstraintGroup{frame, frame_bodies_[static_cast<std::size_t>(frame)], expressed, first,
                                    static_cast<int>(A.cols()), A});
  b_.conservativeResize(first + A.cols());
  b_.tail(A.cols()).setZero();
  reorder();
  return first;
}

int Task::addConstraint(const std::string& frame, const ConstraintMatrix& A, Expressed expressed) {
  return addConstraint(lookup(frame_names_, frame), A, expressed);
}

int Task::addWrench(int frame, Expressed expressed) {
  if (frame < 0 || frame >= frames_) throw ModelError("task: frame index " + std::to_string(frame) + " out of range");
  wrenches_.push_back(AppliedWrench{frame, expressed, Vec6::Zero()});
  return wrenchCount() - 1;
}

int Task::addWrench(const std::string& frame, Expressed expressed) {
  return addWrench(lookup(frame_names_, frame), expressed);
}

void Task::reorder() {
  // Farthest body first (stable: equal bodies keep the user's order), so the
  // constraints felt by body i — those on bodies i..N — are a leading block.
  std::stable_sort(groups_.begin(), groups_.end(),
                   [](const ConstraintGroup& a, const ConstraintGroup& b) { return a.body > b.body; });
  solver_row_.clear();
  for (const ConstraintGroup& g : groups_)
    for (int k = 0; k < g.rows; ++k) solver_row_.push_back(g.first_row + k);
  active_.assign(static_cast<std::size_t>(dof_ + 1), 0);
  for (int body = 0; body <= dof_; ++body) {
    int count = 0;
    for (const ConstraintGroup& g : groups_)
      if (g.body >= body) count += g.rows;
    active_[static_cast<std::size_t>(body)] = count;
  }
}

Status checkBalanceOptions(const BalanceOptions& o) {
  // The equilibrated eigenvalues lie in [0, m] with at least one ≥ 1, so a
  // threshold of 1 or more would call every task singular.
  if (!(o.singular_threshold > 0.0 && o.singular_threshold < 1.0))
    return Status::error(StatusCode::BadOption, "balance singular_threshold %g must be in (0, 1)",
                         o.singular_threshold);
  if (!(o.rank_tolerance >= 0.0 && o.rank_tolerance < o.singular_threshold))
    return Status::error(StatusCode::BadOption, "balance rank_tolerance %g must be in [0, singular_threshold = %g)",
                         o.rank_tolerance, o.singular_threshold);
  if (!(o.residual_tolerance > 0.0 && std::isfinite(o.residual_tolerance)))
    return Status::error(StatusCode::BadOption, "balance residual_tolerance %g must be finite and positive",
                         o.residual_tolerance);
  return {};
}

}  // namespace zwang
