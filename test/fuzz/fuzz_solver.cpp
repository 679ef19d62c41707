// libFuzzer target: bytes → a random serial chain (1–8 joints of every type,
// masses 1e-6–1e4 kg, offsets 1e-3–10 m, rotor inertias 0–1e3, friction
// 0–1e4, limits), a state (speeds to 1e3, joints exactly stuck or on a limit),
// wrenches, constraints on up to three frames (random, repeated or on the base:
// singular tasks), mimic joints (laws to any other joint: chains, cycles the
// builder refuses, states on or off the law) and friction options. Calls solveHybridDynamics, both
// friction maximisers, RNEA, CRBA and a Jacobian.
//
// Fails (abort) when a call that returns Ok — or Infeasible, whose outputs
// docs/friction.md promises finite — leaves a NaN or Inf in its outputs, when a
// maximiser reports more iterations than its cap, or when a status other than
// the documented ones comes back.
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
    for (int j = 0; j < n; ++j) {
      if (path.size() > 1 && in.ConsumeProbability<double>() < 0.3)  // a new branch off an earlier link
        path.resize(in.ConsumeIntegralInRange<std::size_t>(1, path.size() - 1));
      Joint joint;
      joint.name = "j" + std::to_string(j);
      const int type = in.ConsumeIntegralInRange(0, 2);
      joint.type = type == 0 ? JointType::Revolute : type == 1 ? JointType::Continuous : JointType::Prismatic;
      joint.axis = direction(in);
      joint.placement = Transform::fromPose(rotation(in), logUniform(in, 1e-3, 10.0, 0.1) * direction(in));
      joint.rotor_inertia = logUniform(in, 1e-6, 1e3, 0.4);
      joint.breakaway_friction = logUniform(in, 1e-3, 1e4, 0.2);
      joint.kinetic_friction = in.ConsumeBool() ? joint.breakaway_friction : logUniform(in, 1e-3, 1e4, 0.3);
      joint.viscous_friction = logUniform(in, 1e-3, 1e3, 0.3);
      if (joint.type != JointType::Continuous && in.ConsumeBool()) {
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
  for (const Vec6& a : ws.a) fuzz::requireFinite(a, "body accelerations (ws.a)", where);
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

bool documented(StatusCode code) {
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
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  Chain chain;
  if (!buildChain(in, chain)) return 0;
  const Model& model = chain.model;
  const int n = model.dof();
  const int frames = static_cast<int>(chain.frames.size());

  Task task(model);
  task.gravity = in.ConsumeBool() ? Vec3(0, 0, -9.81) : Vec3(9.81 * direction(in) * in.ConsumeProbability<double>());
  const int wrenches = in.ConsumeIntegralInRange(0, 3);
  for (int w = 0; w < wrenches; ++w) {
    const int index = task.addWrench(in.ConsumeIntegralInRange(0, frames - 1),
                                     in.ConsumeBool() ? Expressed::Local : Expressed::World);
    for (int k = 0; k < 6; ++k) task.wrench(index)[k] = signedLog(in, 1e-3, 1e4);
  }
  int rows = in.ConsumeIntegralInRange(0, 8);
  const ConstraintMatrix* previous = nullptr;
  for (int g = 0; g < 3 && rows > 0; ++g) {
    const int here = g == 2 ? rows : in.ConsumeIntegralInRange(1, rows);
    rows -= here;
    const ConstraintMatrix A = constraintColumns(in, here, previous);
    const int frame = in.ConsumeIntegralInRange(0, frames - 1);  // 0: the fixed base (singular)
    const int reference = in.ConsumeIntegralInRange(-1, frames - 1);
    const int axes = in.ConsumeIntegralInRange(0, 2);
    const Expressed expressed = axes == 0 ? Expressed::Local : axes == 1 ? Expressed::World : Expressed::Reference;
    if (reference >= 0 && reference != frame)  // relative to another frame, on any branch
      task.addRelativeConstraint(frame, reference, A, expressed);
    else
      task.addConstraint(frame, A, expressed);
    previous = &task.groups().back().A;
  }
  for (Eigen::Index r = 0; r < task.targets().size(); ++r) task.targets()[r] = signedLog(in, 1e-3, 1e3);
  // The balance options anywhere in their valid ranges (0 < rank_tolerance < singular_threshold < 1).
  task.balance.singular_threshold = in.ConsumeBool() ? 1e-6 : logUniform(in, 1e-16, 1e-1);
  task.balance.rank_tolerance = in.ConsumeBool() ? std::min(1e-11, 0.5 * task.balance.singular_threshold)
                                                 : task.balance.singular_threshold * logUniform(in, 1e-8, 0.99);
  task.balance.residual_tolerance = in.ConsumeBool() ? 1e-9 : logUniform(in, 1e-14, 1e-3);

  Eigen::VectorXd q(n), qd(n), tau(n);
  for (int j = 0; j < n; ++j) {
    const Joint& joint = model.joint(j);
    const int pick = in.ConsumeIntegralInRange(0, 3);
    if (pick == 0 && std::isfinite(joint.lower))
      q[j] = joint.lower;
    else if (pick == 1 && std::isfinite(joint.upper))
      q[j] = joint.upper;
    else
      q[j] = in.ConsumeFloatingPointInRange(-10.0, 10.0);
    qd[j] = in.ConsumeBool() ? 0.0 : signedLog(in, 1e-9, 1e3);
    tau[j] = signedLog(in, 1e-3, 1e4);
  }
  if (in.ConsumeProbability<double>() < 0.9) model.followLeaders(q, qd);  // else most likely MimicMismatch
  // Occasionally a non-finite input: must come back as NonFinite, not as a crash.
  const int poison = in.ConsumeIntegralInRange(0, 40);
  if (poison < n) {
    Eigen::VectorXd* v[] = {&q, &qd, &tau};
    (*v[in.ConsumeIntegralInRange(0, 2)])[poison] =
        in.ConsumeBool() ? std::numeric_limits<double>::quiet_NaN() : std::numeric_limits<double>::infinity();
  }

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

  Workspace ws(model, task);
  const bool finite_inputs = q.allFinite() && qd.allFinite() && tau.allFinite();

  Status status = solveHybridDynamics(model, task, q, qd, tau, ws);
  if (!documented(status.code)) fuzz::failure("undocumented status", "solveHybridDynamics");
  if (finite_inputs && status.code == StatusCode::NonFinite)
    fuzz::failure("NonFinite for finite inputs", status.message);
  if (!finite_inputs && status.ok()) fuzz::failure("Ok for a non-finite input", "solveHybridDynamics");
  if (status.ok()) checkSolution(ws, "solveHybridDynamics");

  for (const FrictionMethod method : {FrictionMethod::ActiveSet, FrictionMethod::ProjectedGradient}) {
    options.method = method;
    const char* where = method == FrictionMethod::ActiveSet ? "solveWithFriction (active set)"
                                                            : "solveWithFriction (projected gradient)";
    status = solveWithFriction(model, task, q, qd, tau, ws, options);
    if (!documented(status.code)) fuzz::failure("undocumented status", where);
    if (!finite_inputs && status.ok()) fuzz::failure("Ok for a non-finite input", where);
    if (status.ok() || status.code == StatusCode::Infeasible) checkFriction(ws, options, where);
  }

  if (finite_inputs) {
    status = inverseDynamics(model, task, q, qd, tau, ws);
    if (status.ok())
      fuzz::requireFinite(ws.tau, "tau (RNEA)", "inverseDynamics");
    else if (!documented(status.code))
      fuzz::failure("undocumented status", "inverseDynamics");
    status = jointSpaceInertia(model, q, ws);
    if (status.ok()) fuzz::requireFinite(ws.H, "H", "jointSpaceInertia");
    Eigen::MatrixXd J(6, n);
    status = frameJacobian(model, ws, q, frames - 1, Expressed::World, J);
    if (status.ok()) fuzz::requireFinite(J, "J", "frameJacobian");
  }
  return 0;
}
