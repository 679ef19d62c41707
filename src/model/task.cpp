#include "zwang/task.hpp"

#include "task_layout.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace zwang {

Task::Task(const Model& model)
    : dof_(model.dof()),
      frames_(static_cast<int>(model.frames().size())),
      fixed_base_mass_(model.inertia(0).mass) {  // the world's: zero under a floating base
  for (const Frame& f : model.frames()) {
    frame_names_.push_back(f.name);
    frame_bodies_.push_back(f.body);
  }
  for (int b = 0; b < model.bodyCount(); ++b) {
    layout_->subtree_end.push_back(model.subtreeEnd(b));
    body_frames_.push_back(model.bodyFrame(b));
  }
  for (const Joint& joint : model.joints()) {
    joint_dofs_.emplace_back(joint.v_index, joint.nv());
    joint_names_.push_back(joint.name);
  }
  for (int v = 0; v < model.nv(); ++v) dof_parent_bodies_.push_back(model.parent(v + 1));
  dof_modes_.assign(static_cast<std::size_t>(model.nv()), DofMode::Torque);
  mimic_dof_.assign(static_cast<std::size_t>(model.nv()), 0);
  for (const int m : model.mimicJoints()) mimic_dof_[static_cast<std::size_t>(model.joint(m).v_index)] = 1;
  prescribed_qdd_ = Eigen::VectorXd::Zero(model.nv());
  addMimicRows(model);
  reorder();
}

Task::LayoutPointer::LayoutPointer() : layout_(std::make_unique<Layout>()) {}
Task::LayoutPointer::LayoutPointer(const LayoutPointer& other) : layout_(std::make_unique<Layout>(*other)) {}
Task::LayoutPointer& Task::LayoutPointer::operator=(const LayoutPointer& other) {
  if (this != &other) *layout_ = *other;  // reuses this layout's storage
  return *this;
}
Task::LayoutPointer::~LayoutPointer() = default;

void Task::addMimicRows(const Model& model) {
  // Row r: q̈_m − a·q̈_l = 0, four pieces: each joint's body and the body it
  // hangs from (where the coupling torque reacts), scaled 1 and −a.
  for (const int m : model.mimicJoints()) {
    const Mimic& law = model.joint(m).mimic;
    const struct {
      int dof;
      double coefficient;
    } pieces[] = {{model.joint(m).v_index, 1.0}, {model.joint(law.leader).v_index, -law.multiplier}};
    for (const auto& piece : pieces) {
      if (piece.coefficient == 0.0) continue;  // a = 0: the mimic joint is held at its offset
      for (const bool parent_side : {false, true}) {
        const int body = parent_side ? model.parent(piece.dof + 1) : piece.dof + 1;
        Layout::ConstraintGroup g{model.bodyFrame(body), body, Expressed::World, mimic_rows_, 1, ConstraintMatrix()};
        g.reference_side = parent_side;
        g.dof = piece.dof;
        g.coefficient = piece.coefficient;
        g.mimic_row = true;
        layout_->groups.push_back(g);
      }
    }
    mimic_laws_.push_back(law);
    mimic_joint_of_row_.push_back(m);
    ++mimic_rows_;
  }
}

bool Task::mimicLawsMatch(const Model& model) const {
  const std::vector<int>& joints = model.mimicJoints();
  if (joints.size() != mimic_joint_of_row_.size()) return false;
  for (std::size_t r = 0; r < joints.size(); ++r) {
    const Mimic& law = model.joint(joints[r]).mimic;
    const Mimic& mine = mimic_laws_[r];
    // Exact comparison: the rows were built from these very numbers.
    if (joints[r] != mimic_joint_of_row_[r] || law.leader != mine.leader || law.multiplier != mine.multiplier)
      return false;
  }
  return true;
}

namespace {
// An unknown name is reported with the candidates, as Model::frameIndex does.
int lookup(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) {
    std::string known;
    for (const std::string& n : names) known += (known.empty() ? "'" : ", '") + n + "'";
    throw ModelError("task: the model has no frame '" + name + "' (frames: " + known + ")");
  }
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
  growTargets(static_cast<int>(A.cols()));  // first: it may refuse, and the task stays as it was
  layout_->groups.push_back(Layout::ConstraintGroup{frame, frame_bodies_[static_cast<std::size_t>(frame)], expressed,
                                                    first, static_cast<int>(A.cols()), A});
  reorder();
  return first;
}

void Task::growTargets(int rows) {
  // A b whose size the user changed would leave rows without a defined set
  // point (or shift them): refuse it here as the solve does.
  if (b_.size() != rows_)
    throw ModelError("task: constraint targets b has " + std::to_string(b_.size()) + " entries, the task has " +
                     std::to_string(rows_) + " constraint rows (Task::targets() must keep its size)");
  b_.conservativeResize(rows_ + rows);
  b_.tail(rows).setZero();
  rows_ += rows;
}

int Task::addConstraint(const std::string& frame, const ConstraintMatrix& A, Expressed expressed) {
  return addConstraint(lookup(frame_names_, frame), A, expressed);
}

int Task::addRelativeConstraint(int frame, int reference, const ConstraintMatrix& A, Expressed expressed) {
  if (reference < 0 || reference >= frames_)
    throw ModelError("task: reference frame index " + std::to_string(reference) + " out of range");
  if (reference == frame)
    throw ModelError("task: a relative constraint on frame '" + frame_names_[static_cast<std::size_t>(frame)] +
                     "' needs another frame to refer to, not itself");
  const int first = addConstraint(frame, A, expressed);  // checks frame and A, sorts
  const auto user_group = [first](const Layout::ConstraintGroup& g) { return !g.mimic_row && g.first_row == first; };
  for (Layout::ConstraintGroup& g : layout_->groups)
    if (user_group(g)) g.reference = reference;
  Layout::ConstraintGroup side = *std::find_if(layout_->groups.begin(), layout_->groups.end(), user_group);
  side.body = frame_bodies_[static_cast<std::size_t>(reference)];
  side.reference_side = true;
  layout_->groups.push_back(side);
  reorder();
  return first;
}

int Task::addRelativeConstraint(const std::string& frame, const std::string& reference, const ConstraintMatrix& A,
                                Expressed expressed) {
  return addRelativeConstraint(lookup(frame_names_, frame), lookup(frame_names_, reference), A, expressed);
}

std::pair<int, int> Task::jointDofs(int joint) const {
  const auto joints = static_cast<int>(joint_dofs_.size());
  if (joint < 0 || joint >= joints)
    throw ModelError("task: joint index " + std::to_string(joint) + " out of range (the model has " +
                     std::to_string(joints) + " joints)");
  return joint_dofs_[static_cast<std::size_t>(joint)];
}

int Task::jointIndex(const std::string& joint) const {
  const auto it = std::find(joint_names_.begin(), joint_names_.end(), joint);
  if (it == joint_names_.end()) throw ModelError("task: the model has no moving joint '" + joint + "'");
  return static_cast<int>(it - joint_names_.begin());
}

int Task::addJointConstraint(int joint) {
  const auto [v_index, nv] = jointDofs(joint);
  const int first_row = constraintRows();
  growTargets(nv);                // first: it may refuse, and the task stays as it was
  for (int k = 0; k < nv; ++k) {  // one row per DOF, in order
    const int dof = v_index + k;
    for (const bool parent_side : {false, true}) {
      const int body = parent_side ? dof_parent_bodies_[static_cast<std::size_t>(dof)] : dof + 1;
      Layout::ConstraintGroup g{
          body_frames_[static_cast<std::size_t>(body)], body, Expressed::World, first_row + k, 1, ConstraintMatrix()};
      g.reference_side = parent_side;
      g.dof = dof;
      g.coefficient = 1.0;
      layout_->groups.push_back(g);
    }
  }
  reorder();
  return first_row;
}

int Task::addJointConstraint(const std::string& joint) { return addJointConstraint(jointIndex(joint)); }

void Task::setDofMode(int dof, DofMode mode) {
  const auto nv = static_cast<int>(dof_modes_.size());
  if (dof < 0 || dof >= nv)
    throw ModelError("task: DOF index " + std::to_string(dof) + " out of range (the model has " + std::to_string(nv) +
                     " entries of v)");
  const auto d = static_cast<std::size_t>(dof);
  // A mimic joint moves as its leader's law says: prescribing it would prescribe the leader through the coupling.
  if (mode == DofMode::Prescribed && mimic_dof_[d]) {
    std::size_t j = 0;  // a mimic joint has one DOF: the joint whose v_index it is
    while (joint_dofs_[j].first != dof) ++j;
    throw ModelError("task: joint '" + joint_names_[j] +
                     "' is a mimic joint, which follows its leader: prescribe the leader instead");
  }
  if (dof_modes_[d] == mode) return;
  prescribed_count_ += mode == DofMode::Prescribed ? 1 : -1;
  dof_modes_[d] = mode;
}

void Task::prescribe(int joint) {
  const auto [v_index, nv] = jointDofs(joint);
  for (int k = 0; k < nv; ++k) setDofMode(v_index + k, DofMode::Prescribed);
}

void Task::prescribe(const std::string& joint) { prescribe(jointIndex(joint)); }

void Task::lock(int joint) {
  prescribe(joint);
  const auto [v_index, nv] = jointDofs(joint);
  prescribed_qdd_.segment(v_index, nv).setZero();
}

void Task::lock(const std::string& joint) { lock(jointIndex(joint)); }

void Task::release(int joint) {
  const auto [v_index, nv] = jointDofs(joint);
  for (int k = 0; k < nv; ++k) setDofMode(v_index + k, DofMode::Torque);
}

void Task::release(const std::string& joint) { release(jointIndex(joint)); }

namespace {
// A contact on a bolted-down base with mass: the humanoid or the quadruped
// loaded without its floating base. The world then holds the robot up, and the
// contacts carry next to nothing: a silent wrong answer if it was meant to stand.
ModelWarning fixedBaseContact(const std::string& frame, const std::string& base_link, double mass) {
  char figures[40];
  std::snprintf(figures, sizeof figures, "%g kg", mass);
  return {WarningCode::FixedBaseContact,
          "contact on frame '" + frame + "' of a fixed-base model whose base carries " + figures + " (link '" +
              base_link +
              "' and the links welded to it): the base is bolted to the world, which then holds the robot up in "
              "place of the contacts. A robot that stands or leans on its contacts needs a floating base: "
              "UrdfOptions::base = BaseType::Free or ModelBuilder::setBase (CLI \"base\": {\"type\": \"free\"}, "
              "Python base=\"free\")"};
}
}  // namespace

int Task::addContact(int frame, const ConstraintMatrix& A, Expressed expressed) {
  const int first = addConstraint(frame, A, expressed);
  for (Layout::ConstraintGroup& g : layout_->groups)
    if (!g.mimic_row && g.dof < 0 && g.first_row == first) g.contact = true;
  reorder();
  const bool warned = std::any_of(warnings_.begin(), warnings_.end(),
                                  [](const ModelWarning& w) { return w.code == WarningCode::FixedBaseContact; });
  if (fixed_base_mass_ > 0.0 && !warned)
    warnings_.push_back(fixedBaseContact(frame_names_[static_cast<std::size_t>(frame)],
                                         frame_names_[static_cast<std::size_t>(body_frames_[0])], fixed_base_mass_));
  return first;
}

int Task::addContact(const std::string& frame, const ConstraintMatrix& A, Expressed expressed) {
  return addContact(lookup(frame_names_, frame), A, expressed);
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
  using Group = Layout::ConstraintGroup;
  Layout& layout = *layout_;
  // Last body first (stable: equal bodies keep the user's order). The bodies
  // are in depth-first order, so body b's subtree [b, end) owns the columns
  // between those on bodies ≥ end and those on bodies ≥ b: a contiguous block.
  std::stable_sort(layout.groups.begin(), layout.groups.end(),
                   [](const Group& a, const Group& b) { return a.body > b.body; });
  layout.balance_on_rows =
      std::any_of(layout.groups.begin(), layout.groups.end(), [](const Group& g) { return g.reference_side; });
  layout.solver_row.clear();
  layout.balance_row.clear();
  layout.contact_column.clear();
  for (const Group& g : layout.groups)
    for (int k = 0; k < g.rows; ++k) {
      // A mimic piece's row follows the user's rows, however many there are.
      const int row = g.mimic_row ? constraintRows() + g.first_row : g.first_row + k;
      // With relative constraints the balance works on the rows (each the sum
      // of its sides); otherwise on the solver columns themselves.
      layout.balance_row.push_back(layout.balance_on_rows ? row : static_cast<int>(layout.solver_row.size()));
      layout.solver_row.push_back(row);
      layout.contact_column.push_back(g.contact ? 1 : 0);
    }
  solver_columns_ = static_cast<int>(layout.solver_row.size());
  has_contacts_ = std::any_of(layout.groups.begin(), layout.groups.end(), [](const Group& g) { return g.contact; });
  const std::size_t bodies = layout.subtree_end.size();
  layout.columns_end.assign(bodies + 1, 0);  // columns_end[N + 1] = 0: no body beyond the last
  for (std::size_t body = 0; body <= bodies; ++body)
    for (const Group& g : layout.groups)
      if (static_cast<std::size_t>(g.body) >= body) layout.columns_end[body] += g.rows;
  layout.first_column.assign(bodies, 0);
  for (std::size_t body = 0; body < bodies; ++body)
    layout.first_column[body] = layout.columns_end[static_cast<std::size_t>(layout.subtree_end[body])];
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
