// libFuzzer target: bytes → a random tree (1–8 joints of every type: revolute,
// continuous, prismatic, and spherical, planar and free anywhere in the tree,
// their quaternions drawn as a free base's; masses 1e-6–1e4 kg, offsets 1e-3–10 m, rotor inertias 0–1e3, friction
// 0–1e4, limits), a state (speeds to 1e3, joints exactly stuck or on a limit),
// wrenches, constraints on up to three frames (random, repeated or on the base:
// singular tasks), mimic joints (laws to any other joint: chains, cycles the
// builder refuses, states on or off the law) and friction options; a base,
// fixed, free or planar (a random plane), with the base link's own inertia, a
// base state (a free base's quaternion unit, off unit by 1e-12–1e-2, or any,
// zero included), base velocities and generalized forces; contacts and joint
// rows among the task's rows; prescribed and locked DOFs. Calls solveHybridDynamics, both friction
// maximisers, RNEA, CRBA and a Jacobian, and two steps of a Simulation (either integrator, a drawn step).
//
// Fails (abort) when a call that returns Ok — or Infeasible, whose outputs
// docs/friction.md promises finite — leaves a NaN or Inf in its outputs, when a
// maximiser reports more iterations than its cap, when a status other than
// the documented ones comes back, or when a free base's quaternion is not
// judged as docs/conventions.md says: a finite one off unit length by more
// than kQuaternionNormTolerance must be BadConfiguration, one within it must
// not, and normalizeConfiguration must fix every non-zero one.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "fuzz_common.hpp"
#include "zwang/zwang.hpp"

#include "dynamics/task_solver_order.hpp"  // the task's groups, to mutate their matrices

#include "dynamics/workspace_scratch.hpp"  // the sweep's accelerations, checked finite too

namespace {

using namespace zwang;

// log-uniform in [lo, hi], or exactly 0 with probability p_zero.
double logUniform(FuzzedDataProvider& in, double lo, double hi, double p_zero = 0.0) {
  if (p_zero > 0.0 && in.ConsumeProbability<double>() < p_zero) return 0.0;
  return lo * std::pow(hi / lo, in.ConsumeProbability<double>());
}

double signedLog(FuzzedDataProvider& in, double lo, double hi) {
  const double x = logUniform(in, lo, hi, 0.1);
  return in.ConsumeBool() ? -x : x;
}

Vec3 direction(FuzzedDataProvider& in) {
  if (in.ConsumeBool()) {
    Vec3 e = Vec3::Zero();
    e[in.ConsumeIntegralInRange(0, 2)] = in.ConsumeBool() ? 1.0 : -1.0;
    return e;
  }
  Vec3 v(in.ConsumeFloatingPointInRange(-1.0, 1.0), in.ConsumeFloatingPointInRange(-1.0, 1.0),
         in.ConsumeFloatingPointInRange(-1.0, 1.0));
  return v.norm() > 1e-3 ? Vec3(v.normalized()) : Vec3(Vec3::UnitZ());
}

Mat3 rotation(FuzzedDataProvider& in) {
  if (in.ConsumeBool()) return Mat3::Identity();
  Eigen::Quaterniond quat(in.ConsumeFloatingPointInRange(-1.0, 1.0), in.ConsumeFloatingPointInRange(-1.0, 1.0),
                          in.ConsumeFloatingPointInRange(-1.0, 1.0), in.ConsumeFloatingPointInRange(-1.0, 1.0));
  if (quat.norm() < 1e-3) return Mat3::Identity();
  return quat.normalized().toRotationMatrix();
}

RigidInertia body(FuzzedDataProvider& in) {
  const double mass = logUniform(in, 1e-6, 1e4, 0.05);
  const double size = logUniform(in, 1e-3, 10.0);
  const Vec3 com = size * in.ConsumeProbability<double>() * direction(in);
  // Second moments s_k ≥ 0 of a real mass distribution: I = diag(s_y+s_z, …) is physical.
  Vec3 s;
  for (int k = 0; k < 3; ++k) s[k] = mass * size * size * logUniform(in, 1e-4, 1.0, 0.1);
  if (s.sum() <= 0.0) s.setConstant(mass * size * size * 1e-2);  // a point mass off its COM axis is not SPD
  const Mat3 R = rotation(in);
  Mat3 I = R * Vec3(s.y() + s.z(), s.x() + s.z(), s.x() + s.y()).asDiagonal() * R.transpose();
  I = 0.5 * (I + I.transpose());
  return RigidInertia::fromMassComInertia(mass, com, mass > 0.0 ? I : Mat3::Zero());
}

struct Chain {  // a chain or a tree, built depth first
  Model model;
  std::vector<std::string> frames;
};

bool buildChain(FuzzedDataProvider& in, Chain& out) {
  const int n = in.ConsumeIntegralInRange(1, 8);
  try {
    ModelBuilder builder("fuzz", "base");
    out.frames = {"base"};
    std::vector<std::string> path{"base"};  // the link frames back to the base: where a depth-first tree may grow
    std::vector<bool> multi_dof;            // per joint: more than one DOF (cannot mimic or be mimicked)
    for (int j = 0; j < n; ++j) {
      if (path.size() > 1 && in.ConsumeProbability<double>() < 0.3)  // a new branch off an earlier link
        path.resize(in.ConsumeIntegralInRange<std::size_t>(1, path.size() - 1));
      Joint joint;
      joint.name = "j" + std::to_string(j);
      // Every joint type, multi-DOF ones anywhere in the tree (a free joint mid-tree too).
      const int type = in.ConsumeIntegralInRange(0, 5);
      joint.type = type == 0   ? JointType::Revolute
                   : type == 1 ? JointType::Continuous
                   : type == 2 ? JointType::Prismatic
                   : type == 3 ? JointType::Spherical
                   : type == 4 ? JointType::Planar
                               : JointType::Free;
      multi_dof.push_back(joint.nv() > 1);
      joint.axis = direction(in);
      joint.placement = Transform::fromPose(rotation(in), logUniform(in, 1e-3, 10.0, 0.1) * direction(in));
      joint.rotor_inertia = logUniform(in, 1e-6, 1e3, 0.4);
      joint.breakaway_friction = logUniform(in, 1e-3, 1e4, 0.2);
      joint.kinetic_friction = in.ConsumeBool() ? joint.breakaway_friction : logUniform(in, 1e-3, 1e4, 0.3);
      joint.viscous_friction = logUniform(in, 1e-3, 1e3, 0.3);
      if (joint.type != JointType::Continuous && in.ConsumeBool() && joint.nv() == 1) {  // multi-DOF: no limits
        joint.lower = -logUniform(in, 1e-3, 3.0, 0.1);
        joint.upper = logUniform(in, 1e-3, 3.0, 0.1);
      }
      const std::string link = "link" + std::to_string(j + 1);
      builder.addJoint(joint, link, body(in), path.back());
      out.frames.push_back(link);
      path.push_back(link);
      if (in.ConsumeProbability<double>() < 0.2) {
        const std::string tool = "tool" + std::to_string(j + 1);
        builder.addFixedFrame(tool, link, Transform::fromPose(rotation(in), logUniform(in, 1e-3, 10.0) * direction(in)),
                              in.ConsumeBool() ? body(in) : RigidInertia{});
        out.frames.push_back(tool);
      }
    }
    for (int j = 0; j < n && n > 1; ++j)
      if (in.ConsumeProbability<double>() < 0.15) {
        int leader = in.ConsumeIntegralInRange(0, n - 2);
        leader += leader >= j ? 1 : 0;  // any other joint (a mimic joint too: a chain, or a cycle)
        const double multiplier = in.ConsumeBool() ? (in.ConsumeBool() ? 1.0 : -1.0) : signedLog(in, 1e-3, 1e2);
        // A mimic law is between one-DOF joints; the builder's refusal of the rest is test_mimic's.
        if (multi_dof[static_cast<std::size_t>(j)] || multi_dof[static_cast<std::size_t>(leader)]) continue;
        builder.setMimic("j" + std::to_string(j), "j" + std::to_string(leader), multiplier, signedLog(in, 1e-3, 1.0));
      }
    out.model = builder.build();
  } catch (const ModelError&) {
    return false;  // e.g. a massless last link or a mimic cycle: the builder refuses it, by design
  }
  return true;
}

ConstraintMatrix constraintColumns(FuzzedDataProvider& in, int rows, const ConstraintMatrix* previous) {
  ConstraintMatrix A(6, rows);
  for (int k = 0; k < rows; ++k) {
    const int kind = in.ConsumeIntegralInRange(0, 3);
    if (kind == 0 && previous && previous->cols() > 0) {
      A.col(k) = previous->col(in.ConsumeIntegralInRange<Eigen::Index>(0, previous->cols() - 1));  // repeated: singular
    } else if (kind <= 1) {
      A.col(k).setZero();
      A(in.ConsumeIntegralInRange(0, 5), k) = 1.0;
    } else {
      for (int r = 0; r < 6; ++r) A(r, k) = in.ConsumeFloatingPointInRange(-1.0, 1.0);
      if (A.col(k).norm() < 1e-6) A(0, k) = 1.0;
      A.col(k).normalize();
      if (kind == 3 && k > 0) A.col(k) = (A.col(k - 1) + 1e-9 * A.col(k)).normalized();  // near-singular
    }
  }
  return A;
}

void checkSolution(const Workspace& ws, const char* where) {
  fuzz::requireFinite(ws.solution.qdd, "qdd", where);
  fuzz::requireFinite(ws.solution.nu, "nu", where);
  fuzz::requireFinite(ws.solution.tau_constraint, "tau_constraint", where);
  fuzz::requireFinite(ws.solution.tau_control, "tau_control", where);
  fuzz::requireFinite(ws.solution.gauss, "gauss", where);
  fuzz::requireFinite(ws.solution.balance.residual, "balance residual", where);
  for (const Vec6& a : scratchOf(ws).a) fuzz::requireFinite(a, "body accelerations (the sweep's)", where);
}

void checkFriction(const Workspace& ws, const FrictionOptions& options, const char* where) {
  checkSolution(ws, where);
  fuzz::requireFinite(ws.friction.mu, "mu", where);
  fuzz::requireFinite(ws.friction.tau_friction, "tau_friction", where);
  fuzz::requireFinite(ws.friction.gauss_dual, "gauss_dual", where);
  fuzz::requireFinite(ws.friction.kkt_residual, "kkt_residual", where);
  if (ws.friction.iterations < 0 || ws.friction.iterations > options.max_iterations)
    fuzz::failure("maximiser iterations outside [0, max_iterations]", where);
}

// Every quaternion of the state (a spherical or free joint's, the root's
// included) against docs/conventions.md ("Joint types"): any one off unit
// length by more than kQuaternionNormTolerance ⇒ BadConfiguration; all within
// it ⇒ not; norms within rounding of the tolerance are not judged.
void checkQuaternionVerdict(const Model& model, const Eigen::VectorXd& q, StatusCode code, const char* where) {
  if (!q.allFinite()) return;
  const double margin = 1e-12;  // the norm's own rounding is ~1e-16; well clear of it
  bool beyond = false, near = false;
  for (const Joint& joint : model.allJoints()) {
    if (joint.type != JointType::Spherical && joint.type != JointType::Free) continue;
    const int w = joint.q_index + (joint.type == JointType::Free ? 3 : 0);
    const double off = std::abs(q.segment<4>(w).norm() - 1.0);
    beyond = beyond || off > kQuaternionNormTolerance + margin;
    near = near || off >= kQuaternionNormTolerance - margin;
  }
  if (beyond && code != StatusCode::BadConfiguration)
    fuzz::failure("a quaternion off unit length beyond the tolerance was not refused", where);
  if (!near && code == StatusCode::BadConfiguration)
    fuzz::failure("BadConfiguration for quaternions within the tolerance", where);
}

// The task as drawn, so that it can be made for the model it is solved on:
// the draws that choose the base come after the task's (see
// LLVMFuzzerTestOneInput). One entry per add call, in order.
struct RowGroup {
  enum class Kind { Frame, Relative, Contact, Joints } kind = Kind::Frame;
  int frame = 0, reference = -1;
  Expressed expressed = Expressed::Local;
  ConstraintMatrix A;
  std::vector<int> joints;  // Kind::Joints: one row each
};
struct WrenchDraw {
  int frame;
  Expressed expressed;
  Vec6 value;
};
struct TaskDraw {
  Vec3 gravity = Vec3::Zero();
  std::vector<WrenchDraw> wrenches;
  std::vector<RowGroup> groups;
  Eigen::VectorXd targets;  // one per row, in the order of the groups
  BalanceOptions balance;
};

void addGroup(const RowGroup& g, Task& task) {
  switch (g.kind) {
    case RowGroup::Kind::Frame: task.addConstraint(g.frame, g.A, g.expressed); break;
    case RowGroup::Kind::Relative: task.addRelativeConstraint(g.frame, g.reference, g.A, g.expressed); break;
    case RowGroup::Kind::Contact: task.addContact(g.frame, g.A, g.expressed); break;
    case RowGroup::Kind::Joints:
      for (const int j : g.joints) task.addJointConstraint(j);
      break;
  }
}

Task buildTask(const Model& model, const TaskDraw& draw) {
  Task task(model);
  task.gravity = draw.gravity;
  for (const WrenchDraw& w : draw.wrenches) task.wrench(task.addWrench(w.frame, w.expressed)) = w.value;
  for (const RowGroup& g : draw.groups) addGroup(g, task);
  task.targets() = draw.targets;
  task.balance = draw.balance;
  return task;
}

// Gravity, wrenches, up to 8 frame rows (absolute or relative) in up to three
// groups, set points, and the balance options anywhere in their valid ranges
// (0 < rank_tolerance < singular_threshold < 1). `chain` is the fixed-base
// model, whose task gives a repeated column its source.
TaskDraw drawTask(FuzzedDataProvider& in, const Model& chain, int frames) {
  TaskDraw draw;
  Task task(chain);
  draw.gravity = in.ConsumeBool() ? Vec3(0, 0, -9.81) : Vec3(9.81 * direction(in) * in.ConsumeProbability<double>());
  const int wrenches = in.ConsumeIntegralInRange(0, 3);
  for (int w = 0; w < wrenches; ++w) {
    WrenchDraw wrench{in.ConsumeIntegralInRange(0, frames - 1), in.ConsumeBool() ? Expressed::Local : Expressed::World,
                      Vec6::Zero()};
    for (int k = 0; k < 6; ++k) wrench.value[k] = signedLog(in, 1e-3, 1e4);
    draw.wrenches.push_back(wrench);
  }
  int rows = in.ConsumeIntegralInRange(0, 8);
  const ConstraintMatrix* previous = nullptr;
  for (int g = 0; g < 3 && rows > 0; ++g) {
    const int here = g == 2 ? rows : in.ConsumeIntegralInRange(1, rows);
    rows -= here;
    RowGroup group;
    group.A = constraintColumns(in, here, previous);
    group.frame = in.ConsumeIntegralInRange(0, frames - 1);  // 0: the base (fixed: singular)
    group.reference = in.ConsumeIntegralInRange(-1, frames - 1);
    const int axes = in.ConsumeIntegralInRange(0, 2);
    group.expressed = axes == 0 ? Expressed::Local : axes == 1 ? Expressed::World : Expressed::Reference;
    // relative to another frame, on any branch
    group.kind =
        group.reference >= 0 && group.reference != group.frame ? RowGroup::Kind::Relative : RowGroup::Kind::Frame;
    addGroup(group, task);
    draw.groups.push_back(group);
    previous = &solverOrder(task).groups().back().A;
  }
  draw.targets.resize(task.constraintRows());
  for (Eigen::Index r = 0; r < draw.targets.size(); ++r) draw.targets[r] = signedLog(in, 1e-3, 1e3);
  draw.balance.singular_threshold = in.ConsumeBool() ? 1e-6 : logUniform(in, 1e-16, 1e-1);
  draw.balance.rank_tolerance = in.ConsumeBool() ? std::min(1e-11, 0.5 * draw.balance.singular_threshold)
                                                 : draw.balance.singular_threshold * logUniform(in, 1e-8, 0.99);
  draw.balance.residual_tolerance = in.ConsumeBool() ? 1e-9 : logUniform(in, 1e-14, 1e-3);
  return draw;
}

// The joints' state: each on a limit or anywhere, exactly stuck or moving;
// whether mimic joints are put on their law (90 %); occasionally one
// non-finite entry (applied by applyJointState once the base is known).
struct JointStateDraw {
  Eigen::VectorXd q, qd, tau;
  bool follow_leaders = true;
  int poison = -1;          // the joint whose entry is not finite, −1: none
  int poisoned_vector = 0;  // 0 q, 1 qd, 2 tau
  double poison_value = 0.0;
};

// A quaternion (w x y z): unit (half the draws), off unit by a relative 1e-12–1e-2 either way (across
// kQuaternionNormTolerance), zero, or as drawn (any norm up to 2).
Eigen::Vector4d drawQuaternion(FuzzedDataProvider& in) {
  Eigen::Vector4d quat;
  for (int k = 0; k < 4; ++k) quat[k] = in.ConsumeFloatingPointInRange(-1.0, 1.0);
  const int pick = in.ConsumeIntegralInRange(0, 3);
  if (pick <= 1 && quat.norm() > 0.0) quat.normalize();
  if (pick == 1) quat *= 1.0 + (in.ConsumeBool() ? 1.0 : -1.0) * logUniform(in, 1e-12, 1e-2);
  if (pick == 2) quat.setZero();
  return quat;
}

JointStateDraw drawJointState(FuzzedDataProvider& in, const Model& chain) {
  // `chain` has a fixed base: its q and v are the joints' alone.
  JointStateDraw d;
  d.q.resize(chain.nq());
  d.qd.resize(chain.nv());
  d.tau.resize(chain.nv());
  for (const Joint& joint : chain.joints()) {
    double* q = d.q.data() + joint.q_index;
    switch (joint.type) {
      case JointType::Spherical: d.q.segment<4>(joint.q_index) = drawQuaternion(in); break;
      case JointType::Free:
        for (int k = 0; k < 3; ++k) q[k] = in.ConsumeFloatingPointInRange(-10.0, 10.0);
        d.q.segment<4>(joint.q_index + 3) = drawQuaternion(in);
        break;
      case JointType::Planar:
        for (int k = 0; k < 3; ++k) q[k] = in.ConsumeFloatingPointInRange(-10.0, 10.0);
        break;
      default: {
        const int pick = in.ConsumeIntegralInRange(0, 3);
        if (pick == 0 && std::isfinite(joint.lower))
          q[0] = joint.lower;
        else if (pick == 1 && std::isfinite(joint.upper))
          q[0] = joint.upper;
        else
          q[0] = in.ConsumeFloatingPointInRange(-10.0, 10.0);
      }
    }
    for (int k = joint.v_index; k < joint.v_index + joint.nv(); ++k) {
      d.qd[k] = in.ConsumeBool() ? 0.0 : signedLog(in, 1e-9, 1e3);
      d.tau[k] = signedLog(in, 1e-3, 1e4);
    }
  }
  d.follow_leaders = in.ConsumeProbability<double>() < 0.9;  // else most likely MimicMismatch
  // Occasionally a non-finite input: must come back as NonFinite, not as a crash.
  const int poison = in.ConsumeIntegralInRange(0, 40);
  d.poisoned_vector = in.ConsumeIntegralInRange(0, 2);
  if (poison < (d.poisoned_vector == 0 ? d.q.size() : d.qd.size())) {
    d.poison = poison;
    d.poison_value =
        in.ConsumeBool() ? std::numeric_limits<double>::quiet_NaN() : std::numeric_limits<double>::infinity();
  }
  return d;
}

FrictionOptions drawFrictionOptions(FuzzedDataProvider& in, int n) {
  FrictionOptions options;
  options.velocity_tolerance = in.ConsumeBool() ? 1e-6 : logUniform(in, 1e-12, 1.0, 0.2);
  options.limit_tolerance = in.ConsumeBool() ? 1e-9 : logUniform(in, 1e-12, 1e-3, 0.2);
  options.joint_limits = in.ConsumeBool();
  options.margin = in.ConsumeBool() ? 1.0 : in.ConsumeProbability<double>();
  options.max_iterations = in.ConsumeBool() ? 500 : in.ConsumeIntegralInRange(1, 50);
  options.kkt_tolerance = in.ConsumeBool() ? 1e-12 : logUniform(in, 1e-16, 1e-2);
  if (in.ConsumeProbability<double>() < 0.2) {
    options.breakaway.resize(n);
    for (int j = 0; j < n; ++j) options.breakaway[j] = logUniform(in, 1e-3, 1e4, 0.3);
  }
  return options;
}

// A base for the chain: fixed (the chain as built), or free or planar (a
// random plane) with the base link's own inertia. False when the builder
// refuses it.
bool drawBase(FuzzedDataProvider& in, Chain& chain) {
  const int pick = in.ConsumeIntegralInRange(0, 2);
  if (pick == 0) return true;
  try {
    ModelBuilder builder(chain.model);
    builder.addBaseLinkInertia(body(in));
    if (pick == 1)
      builder.setBase(BaseType::Free);
    else
      builder.setBase(BaseType::Planar,
                      Transform::fromPose(rotation(in), logUniform(in, 1e-3, 10.0, 0.5) * direction(in)));
    chain.model = builder.build();
  } catch (const ModelError&) {
    return false;
  }
  return true;
}

// One more group of rows, none (a third of the inputs), a contact or joint
// rows (one per row, on any joint: repeated ones are singular), with its set
// points appended.
void drawContactOrJointRows(FuzzedDataProvider& in, const Model& model, int frames, TaskDraw& draw) {
  const int kind = in.ConsumeIntegralInRange(0, 2);
  if (kind == 0) return;
  const int rows = in.ConsumeIntegralInRange(1, 6);
  RowGroup group;
  if (kind == 1) {
    group.kind = RowGroup::Kind::Contact;
    group.A = constraintColumns(in, rows, nullptr);
    group.frame = in.ConsumeIntegralInRange(0, frames - 1);
    group.expressed = in.ConsumeBool() ? Expressed::Local : Expressed::World;
  } else {
    group.kind = RowGroup::Kind::Joints;
    // Joint indices (a multi-DOF joint adds one row per DOF).
    for (int r = 0; r < rows; ++r)
      group.joints.push_back(in.ConsumeIntegralInRange(0, static_cast<int>(model.joints().size()) - 1));
  }
  draw.groups.push_back(group);
  const Eigen::Index first = draw.targets.size();
  draw.targets.conservativeResize(first + rows);
  for (int r = 0; r < rows; ++r) draw.targets[first + r] = signedLog(in, 1e-3, 1e3);
}

// The base's coordinates, velocities and generalized forces (the first
// entries of q, qd, tau). A free base's quaternion as drawQuaternion draws it.
void drawBaseState(FuzzedDataProvider& in, const Model& model, Eigen::VectorXd& q, Eigen::VectorXd& qd,
                   Eigen::VectorXd& tau) {
  for (int k = 0; k < model.baseConfigurationSize(); ++k) q[k] = signedLog(in, 1e-3, 1e2);
  if (model.baseType() == BaseType::Free) q.segment<4>(3) = drawQuaternion(in);
  const bool pushed = in.ConsumeProbability<double>() < 0.3;  // usually 0: no motor at the base
  for (int k = 0; k < model.baseVelocitySize(); ++k) {
    qd[k] = signedLog(in, 1e-9, 1e3);
    tau[k] = pushed ? signedLog(in, 1e-3, 1e4) : 0.0;
  }
  // A non-finite base coordinate now and then (0, as when the bytes ran out: none).
  const int poison = in.ConsumeIntegralInRange(0, 12);
  if (poison >= 1 && poison <= model.baseConfigurationSize()) q[poison - 1] = std::numeric_limits<double>::infinity();
}

// q (nq), qd and tau (nv): the base's entries, then the joints' as drawn.
void assembleState(FuzzedDataProvider& in, const Model& model, const JointStateDraw& joints, Eigen::VectorXd& q,
                   Eigen::VectorXd& qd, Eigen::VectorXd& tau) {
  q.setZero(model.nq());
  qd.setZero(model.nv());
  tau.setZero(model.nv());
  const int base_configuration_size = model.baseConfigurationSize(), base_velocity_size = model.baseVelocitySize();
  q.tail(joints.q.size()) = joints.q;
  qd.tail(joints.qd.size()) = joints.qd;
  tau.tail(joints.tau.size()) = joints.tau;
  drawBaseState(in, model, q, qd, tau);
  if (joints.follow_leaders) model.followLeaders(q, qd);
  if (joints.poison >= 0) {
    Eigen::VectorXd* v[] = {&q, &qd, &tau};
    (*v[joints.poisoned_vector])[(joints.poisoned_vector == 0 ? base_configuration_size : base_velocity_size) +
                                 joints.poison] = joints.poison_value;
  }
}

// After a solve at (q, qd): the frame queries at that state read finite values; at another q they are NotComputed.
void checkHeldState(const Model& model, const Workspace& ws, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  const int frame = static_cast<int>(model.frames().size()) - 1;
  Eigen::Isometry3d pose;
  Vec6 velocity, acceleration;
  if (!framePose(model, ws, q, frame, pose).ok() ||
      !frameVelocity(model, ws, q, qd, frame, Expressed::World, velocity).ok() ||
      !frameAcceleration(model, ws, q, qd, frame, Expressed::Local, acceleration).ok())
    fuzz::failure("a query at the solve's state", "not Ok");
  fuzz::requireFinite(pose.matrix(), "pose", "framePose");
  fuzz::requireFinite(acceleration, "acceleration", "frameAcceleration");
  Eigen::VectorXd other = q;
  other[0] = q[0] == 0.0 ? 1.0 : -q[0];  // differs from q[0] whatever its size
  if (framePose(model, ws, other, frame, pose).code != StatusCode::NotComputed)
    fuzz::failure("a query at another q", "not NotComputed");
}

// The solves, each status documented, every output of a successful one finite.
// Prescribed DOFs (Task::setDofMode), drawn last so that older corpus entries keep their meaning: each entry of
// v, the base's too, prescribed one time in four (a mimic joint's never: it follows its leader), its q̈ anywhere
// in ±1e4 or zero (locked).
void drawModes(FuzzedDataProvider& in, const Model& model, Task& task) {
  std::vector<char> mimic(static_cast<std::size_t>(model.nv()), 0);
  for (const int m : model.mimicJoints()) mimic[static_cast<std::size_t>(model.joint(m).v_index)] = 1;
  for (int v = 0; v < model.nv() && in.remaining_bytes() > 0; ++v) {
    if (mimic[static_cast<std::size_t>(v)] || in.ConsumeIntegralInRange(0, 3) != 0) continue;
    task.setDofMode(v, DofMode::Prescribed);
    task.prescribedAccelerations()[v] = in.ConsumeBool() ? 0.0 : signedLog(in, 1e-3, 1e4);
  }
}

void runSolves(const Model& model, const Task& task, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
               const Eigen::VectorXd& tau, FrictionOptions& options, Workspace& ws) {
  const bool finite_inputs = q.allFinite() && qd.allFinite() && tau.allFinite();
  Status status = solveHybridDynamics(model, ws, q, qd, tau, task);
  if (!fuzz::documented(status.code)) fuzz::failure("undocumented status", "solveHybridDynamics");
  if (finite_inputs && status.code == StatusCode::NonFinite)
    fuzz::failure("NonFinite for finite inputs", status.message);
  if (!finite_inputs && status.ok()) fuzz::failure("Ok for a non-finite input", "solveHybridDynamics");
  checkQuaternionVerdict(model, q, status.code, "solveHybridDynamics");
  if (status.ok()) checkSolution(ws, "solveHybridDynamics");
  if (status.ok()) checkHeldState(model, ws, q, qd);

  // forwardDynamics: the task's rows refused, the rest as the plain solve.
  status = forwardDynamics(model, ws, q, qd, tau, task);
  if ((task.constraintRows() > 0) != (status.code == StatusCode::BadOption))
    fuzz::failure("forwardDynamics: BadOption exactly for a task with rows", status.message);
  status = forwardDynamics(model, ws, q, qd, tau);
  if (!fuzz::documented(status.code)) fuzz::failure("undocumented status", "forwardDynamics");
  if (!finite_inputs && status.ok()) fuzz::failure("Ok for a non-finite input", "forwardDynamics");
  if (status.ok()) checkSolution(ws, "forwardDynamics");

  for (const FrictionMethod method :
       {FrictionMethod::ActiveSet, FrictionMethod::ProjectedGradient, FrictionMethod::StickPatterns}) {
    options.method = method;
    const char* where = toString(method);
    status = solveWithFriction(model, ws, q, qd, tau, task, options);
    if (!fuzz::documented(status.code)) fuzz::failure("undocumented status", where);
    if (!finite_inputs && status.ok()) fuzz::failure("Ok for a non-finite input", where);
    checkQuaternionVerdict(model, q, status.code, where);
    if (status.ok() || status.code == StatusCode::Infeasible) checkFriction(ws, options, where);
  }
  // Warm start: the call again from the pattern the last one kept (the search's first pass when it holds).
  options.warm_start = true;
  for (int call = 0; call < 2; ++call) {
    status = solveWithFriction(model, ws, q, qd, tau, task, options);
    if (!fuzz::documented(status.code)) fuzz::failure("undocumented status", "solveWithFriction (warm start)");
    if (!finite_inputs && status.ok()) fuzz::failure("Ok for a non-finite input", "solveWithFriction (warm start)");
    if (status.ok() || status.code == StatusCode::Infeasible)
      checkFriction(ws, options, "solveWithFriction (warm start)");
  }
  options.warm_start = false;

  if (finite_inputs) {
    status = inverseDynamics(model, ws, q, qd, tau, task);
    if (status.ok())
      fuzz::requireFinite(ws.tau, "tau (RNEA)", "inverseDynamics");
    else if (!fuzz::documented(status.code))
      fuzz::failure("undocumented status", "inverseDynamics");
    status = jointSpaceInertia(model, ws, q);
    if (status.ok()) fuzz::requireFinite(ws.H, "H", "jointSpaceInertia");
    Eigen::MatrixXd J(6, model.nv());
    status = frameJacobian(model, ws, q, static_cast<int>(model.frames().size()) - 1, Expressed::World, J);
    if (status.ok()) fuzz::requireFinite(J, "J", "frameJacobian");
  }
}

// A few steps of a Simulation from the state (issue #29): both integrators, a drawn step, the drawn friction options;
// the statuses documented ones (or EventCascade, the simulation's own), the state finite with unit quaternions, the
// events inside the time simulated and in time order, the energy finite.
void runSimulation(FuzzedDataProvider& in, const Model& model, const Task& task, const Eigen::VectorXd& q,
                   const Eigen::VectorXd& qd, const Eigen::VectorXd& tau, const FrictionOptions& friction) {
  SimulationOptions options;
  options.friction = friction;
  options.friction.method = FrictionMethod::Automatic;  // the loop's own choice (runSolves left the last one forced)
  options.friction.warm_start = in.ConsumeBool();
  options.dt = logUniform(in, 1e-5, 1e-2);
  options.integrator = in.ConsumeBool() ? Integrator::RungeKutta4 : Integrator::SemiImplicitEuler;
  options.max_events_per_step = 4;  // an input stays well inside the fuzzer's 1 s
  Simulation sim(model, task, options);
  Status status = sim.reset(q, qd);
  const char* where = "Simulation";
  for (int k = 0; k < 2 && status.ok(); ++k) status = sim.step(tau);
  if (!fuzz::documented(status.code) && status.code != StatusCode::EventCascade)
    fuzz::failure("undocumented status", where);
  if (!status.ok()) return;
  fuzz::requireFinite(sim.q(), "q", where);
  fuzz::requireFinite(sim.qd(), "qd", where);
  if (!checkConfiguration(model, sim.q())) fuzz::failure("a quaternion off unit length after a step", where);
  double last = 0.0;
  for (const SimulationEvent& e : sim.events()) {
    if (!(e.t >= last && e.t <= sim.time()))
      fuzz::failure("an event out of order or outside the time simulated", where);
    last = e.t;
  }
  const EnergyLedger& energy = sim.energy();
  fuzz::requireFinite(energy.kinetic + energy.potential + energy.motor_effort + energy.friction_dissipation, "energy",
                      where);
}

// Quaternions refused: normalizeConfiguration must fix any finite non-zero
// ones, every joint's (docs/conventions.md), and the solve then take them.
void checkNormalisation(const Model& model, const Task& task, Eigen::VectorXd q, const Eigen::VectorXd& qd,
                        const Eigen::VectorXd& tau, Workspace& ws) {
  if (model.nq() == model.nv() || !q.allFinite()) return;  // no quaternion
  bool zero = false;
  for (const Joint& joint : model.allJoints())
    if (joint.type == JointType::Spherical || joint.type == JointType::Free)
      zero = zero || q.segment<4>(joint.q_index + (joint.type == JointType::Free ? 3 : 0)).squaredNorm() == 0.0;
  const Status normalised = normalizeConfiguration(model, q);
  if (normalised.ok() == zero)
    fuzz::failure("normalizeConfiguration: Ok exactly when the quaternion is non-zero", normalised.message);
  if (!normalised.ok()) return;
  const Status status = solveHybridDynamics(model, ws, q, qd, tau, task);
  if (status.code == StatusCode::BadConfiguration)
    fuzz::failure("BadConfiguration after normalizeConfiguration", status.message);
  if (status.ok()) checkSolution(ws, "solveHybridDynamics (normalised q)");
}

}  // namespace

// The draws of the fixed-base chain, its task, state and options come first,
// in the order they always had: an input whose bytes run out there, or right
// after, is a fixed base with nothing more (every later draw is 0). (A joint's
// type byte reads among six types since issue #25, so older corpus entries
// now draw other types.) Then the base, a contact or joint rows, and the
// base's state.
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  Chain chain;
  if (!buildChain(in, chain)) return 0;
  const int frames = static_cast<int>(chain.frames.size());
  TaskDraw task_draw = drawTask(in, chain.model, frames);
  const JointStateDraw joints = drawJointState(in, chain.model);
  FrictionOptions options = drawFrictionOptions(in, chain.model.dof());
  if (!drawBase(in, chain)) return 0;
  const Model& model = chain.model;
  drawContactOrJointRows(in, model, frames, task_draw);
  Task task = buildTask(model, task_draw);
  Eigen::VectorXd q, qd, tau;
  assembleState(in, model, joints, q, qd, tau);
  drawModes(in, model, task);
  Workspace ws(model, task);
  runSolves(model, task, q, qd, tau, options, ws);
  checkNormalisation(model, task, q, qd, tau, ws);
  runSimulation(in, model, task, q, qd, tau, options);
  return 0;
}
