// Simulation: the friction-aware dynamics over time (docs/simulation.md; issue #29). A step is a driver of stages:
//
//   start solve   solveWithFriction at (t, q, q̇): q̈ with the sticking DOFs' entries set to exactly 0, and the
//                 stick/slip events of the DOFs at rest (logStartStates);
//   trial         the integrator's step of the remaining length s (trialStep): Euler from the start solve alone,
//                 RK4 with three more solves (Munthe-Kaas: q = q₀ ⊕ u, u̇ = tangentRate(u, q̇));
//   events        one event function per candidate — a moving DOF's velocity (its sign at the start: positive until
//                 it reaches zero), a one-DOF joint's distance to its limits, a sticking DOF's room to its breakaway
//                 (1 − |μ|/f while it sticks at the trial's end, −|q̇| or −|q̈| once it moves) — and G = their
//                 minimum; G ≤ 0 at the trial's end: the first zero of G is located by Illinois regula falsi on
//                 the trial's length (locateEvent) and the step cut at the bracket's far side;
//   accept        the trial's state, its energies; a DOF whose velocity reached zero gets exactly 0, one at a limit
//                 the inelastic stop (stopAtLimit); then the rest of the step from a new start solve.
//
// A sticking DOF has q̇ = 0 and q̈ = 0 exactly, so every stage leaves it where it is: zero creep, not a small one.
// The friction solve classifies a DOF as stuck when its velocity is exactly zero (velocity_tolerance 0): only an
// event puts a velocity at zero, so nothing else sticks by rounding.
#include "zwang/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "zwang/center_of_mass.hpp"
#include "zwang/configuration.hpp"
#include "zwang/hybrid_dynamics.hpp"
#include "zwang/inverse_dynamics.hpp"

namespace zwang {

namespace {

// The value a sticking DOF's event function keeps above zero however close |μ| comes to f (so that only a
// breakaway, never a stick at its bound, counts as the event), and below zero once it moves.
constexpr double kStickFloor = 1e-300;
constexpr int kMaxLocateIterations = 200;  // Illinois halves the bracket at least every third step: 1e-300 of it

std::size_t at(int i) { return static_cast<std::size_t>(i); }

bool sticking(JointState state) { return state == JointState::Stick || state == JointState::AtLimit; }

}  // namespace

const char* toString(Integrator integrator) {
  switch (integrator) {
    case Integrator::SemiImplicitEuler: return "euler";
    case Integrator::RungeKutta4: return "rk4";
  }
  return "?";
}

const char* toString(EventKind kind) {
  switch (kind) {
    case EventKind::Stick: return "stick";
    case EventKind::SlipPositive: return "slip+";
    case EventKind::SlipNegative: return "slip-";
    case EventKind::Limit: return "limit";
  }
  return "?";
}

// The DOFs whose stick and slip the events follow: below the root, with friction (a box or kinetic), not a mimic
// joint (it moves with its leader, which carries its friction), not prescribed.
bool Simulation::eventDof(int dof) const {
  const int v = model_->baseVelocitySize() + dof;
  return has_friction_[at(dof)] && task_->dofMode(v) != DofMode::Prescribed;
}

// A one-DOF joint's limits, if it has any and is not a mimic joint (multi-DOF joints have none).
bool Simulation::limitsOf(int dof, double& lower, double& upper, int& q_index) const {
  const int v = model_->baseVelocitySize() + dof;
  const Dof& d = model_->dofs()[at(v)];
  if (!options_.friction.joint_limits || d.joint < 0 || task_->dofMode(v) == DofMode::Prescribed) return false;
  const Joint& joint = model_->joint(d.joint);
  if (joint.nv() != 1 || joint.mimic.active()) return false;
  lower = d.lower;
  upper = d.upper;
  q_index = joint.q_index;
  return std::isfinite(lower) || std::isfinite(upper);
}

Simulation::Simulation(const Model& model, const Task& task, const SimulationOptions& options)
    : model_(&model),
      task_(&task),
      options_(options),
      ws_(model, task),
      ws_trial_(model, task),
      ws_impulse_(model, task) {
  const auto nv = static_cast<Eigen::Index>(model.nv()), nq = static_cast<Eigen::Index>(model.nq());
  for (Eigen::VectorXd* v : {&qd_, &qdd_start_, &tau_, &held_, &tau_unit_, &qdd_unit_, &qd_trial_, &qd_stage_,
                             &u_stage_, &qdd_stage_, &k_u_, &k_qd_, &rate_})
    v->setZero(nv);
  for (Eigen::VectorXd* v : {&q_, &q_trial_, &q_stage_}) v->setZero(nq);
  motion_.assign(at(model.dof()), Motion::Stuck);
  breaking_.assign(at(model.dof()), 0);
  limit_dofs_.reserve(at(model.dof()));
  has_friction_.assign(at(model.dof()), 0);
  slip_sign_.assign(at(model.dof()), 0);
  mimic_of_.assign(at(model.dof()), -1);
  const FrictionOptions& f = options_.friction;
  const Eigen::Index n = model.dof();
  for (Eigen::VectorXd* v : {&box_, &kinetic_, &viscous_, &kinetic_carried_, &viscous_carried_, &friction_applied_})
    v->setZero(n);
  for (int j = 0; j < model.dof(); ++j) {
    const Dof& d = model.dofs()[at(model.baseVelocitySize() + j)];
    box_[j] = f.breakaway.size() == n ? f.breakaway[j] : d.breakaway_friction;
    kinetic_[j] = f.kinetic.size() == n ? f.kinetic[j] : d.kinetic_friction;
    viscous_[j] = f.viscous.size() == n ? f.viscous[j] : d.viscous_friction;
  }
  kinetic_carried_ = kinetic_;
  viscous_carried_ = viscous_;
  for (int j = 0; j < model.dof(); ++j) has_friction_[at(j)] = box_[j] > 0.0 || kinetic_[j] > 0.0 ? 1 : 0;
  for (const int m : model.mimicJoints()) {  // the leader carries the mimic joint's friction, as the solve does
    const Joint& mimic = model.joint(m);
    const int dof_m = mimic.v_index - model.baseVelocitySize();
    const int dof_l = model.joint(mimic.mimic.leader).v_index - model.baseVelocitySize();
    const double a = mimic.mimic.multiplier;
    kinetic_carried_[dof_l] += std::abs(a) * kinetic_[dof_m];
    viscous_carried_[dof_l] += a * a * viscous_[dof_m];
    kinetic_carried_[dof_m] = viscous_carried_[dof_m] = 0.0;
    if (has_friction_[at(dof_m)]) has_friction_[at(dof_l)] = 1;
    has_friction_[at(dof_m)] = 0;
    mimic_of_[at(dof_m)] = dof_l;
  }
  solve_options_ = options_.friction;
  solve_options_.breakaway = box_;
  solve_options_.kinetic = kinetic_;
  solve_options_.viscous = viscous_;
  start_state_.assign(at(model.dof()), JointState::Moving);
  events_.reserve(4096);                       // a long run that never clears them grows this, once in a while
  options_.friction.velocity_tolerance = 0.0;  // stuck: exactly at rest (only an event puts a velocity at 0)
  subtreeMass(model, kWholeRobot, total_mass_);
}

Status Simulation::reset(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
                         double t) noexcept {
  ready_ = false;
  if (!(options_.dt > 0.0) || !std::isfinite(options_.dt))
    return Status::error(StatusCode::BadOption, "simulation dt %g must be finite and > 0", options_.dt);
  if (!(options_.event_tolerance > 0.0) || !(options_.event_tolerance < options_.dt))
    return Status::error(StatusCode::BadOption, "simulation event_tolerance %g must be > 0 and < dt (%g)",
                         options_.event_tolerance, options_.dt);
  if (options_.max_events_per_step < 0)
    return Status::error(StatusCode::BadOption, "simulation max_events_per_step %d must be >= 0",
                         options_.max_events_per_step);
  if (!std::isfinite(t)) return Status::error(StatusCode::NonFinite, "simulation start time %g is not finite", t);
  if (Status s = checkConfiguration(*model_, q); !s) return s;
  if (qd.size() != model_->nv())
    return Status::error(StatusCode::SizeMismatch, "qd has %ld entries; the model has nv = %d",
                         static_cast<long>(qd.size()), model_->nv());
  if (!qd.allFinite()) return Status::error(StatusCode::NonFinite, "qd has an entry that is not finite");
  q_ = q;
  qd_ = qd;
  t_ = t_reset_ = t;
  steps_ = 0;
  events_.clear();
  std::fill(breaking_.begin(), breaking_.end(), 0);
  energy_ = EnergyLedger{};
  for (int j = 0; j < model_->dof(); ++j) {
    const double v = qd_[model_->baseVelocitySize() + j];
    motion_[at(j)] = v > 0.0 ? Motion::Positive : v < 0.0 ? Motion::Negative : Motion::Stuck;
  }
  updateEnergyNow();
  energy_.initial = energy_.kinetic + energy_.potential;
  ready_ = true;
  return {};
}

Status Simulation::step(const Eigen::Ref<const Eigen::VectorXd>& tau) noexcept {
  if (tau.size() != model_->nv())
    return Status::error(StatusCode::SizeMismatch, "tau has %ld entries; the model has nv = %d",
                         static_cast<long>(tau.size()), model_->nv());
  held_ = tau;
  return advance(options_.dt, nullptr, &held_);
}

Status Simulation::stepWith(const TorqueSchedule& tau) noexcept { return advance(options_.dt, &tau, nullptr); }

// ---- The dynamics at one state: q̈ (the sticking DOFs' entries exactly 0) and the powers at that state.
Status Simulation::evaluate(Workspace& ws, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                            const TorqueSchedule* schedule, const Eigen::VectorXd* held, Eigen::VectorXd& qdd,
                            double& power_motor, double& power_friction, double& effort) noexcept {
  if (held)
    tau_ = *held;
  else
    (*schedule)(t, tau_);
  if (!tau_.allFinite())
    return Status::error(StatusCode::NonFinite, "the torque schedule gave a value that is not finite at t = %.17g", t);
  const int base = model_->baseVelocitySize();
  for (int j = 0; j < model_->dof(); ++j) {  // the frozen directions' kinetic friction, applied here
    const int v = base + j;
    friction_applied_[j] =
        slip_sign_[at(j)] == 0 ? 0.0 : -kinetic_carried_[j] * slip_sign_[at(j)] - viscous_carried_[j] * qd[v];
    tau_[v] += friction_applied_[j];
  }
  if (Status s = solveWithFriction(*model_, ws, q, qd, tau_, *task_, solve_options_); !s) return s;
  qdd = ws.solution.qdd;
  power_friction = 0.0;
  for (int j = 0; j < model_->dof(); ++j) {
    const int v = base + j;
    if (slip_sign_[at(j)] != 0) {  // reported as the solve reports its own kinetic friction: not the motor's
      ws.solution.tau_control[v] -= friction_applied_[j];
      ws.friction.tau_friction[j] = friction_applied_[j];
      ws.friction.state[at(j)] = JointState::Moving;
    }
    if (qd[v] == 0.0 && !breaking_[at(j)] && sticking(ws.friction.state[at(j)])) qdd[v] = 0.0;  // exactly: no creep
    power_friction += ws.friction.tau_friction[j] * qd[v];
  }
  power_motor = ws.solution.tau_control.dot(qd);
  effort = ws.solution.tau_control.squaredNorm();
  return {};
}

// ---- The integrator's step of length s from (t, q, q̇) and the start solve: (q_trial_, qd_trial_) and its energies.
Status Simulation::trialStep(double s, const TorqueSchedule* schedule, const Eigen::VectorXd* held) noexcept {
  if (options_.integrator == Integrator::SemiImplicitEuler) {
    qd_trial_ = qd_ + s * qdd_start_;
    if (Status st = integrate(*model_, q_, qd_trial_, s, q_trial_); !st) return st;
    // The start solve's torques on the velocity that moved q (semi-implicit).
    const double motor = ws_.solution.tau_control.dot(qd_trial_);
    double friction = 0.0;
    for (int j = 0; j < model_->dof(); ++j)
      friction += ws_.friction.tau_friction[j] * qd_trial_[model_->baseVelocitySize() + j];
    trial_motor_positive_ = s * std::max(0.0, motor);
    trial_motor_negative_ = s * std::min(0.0, motor);
    trial_friction_ = -s * friction;
    trial_effort_ = s * effort_start_;
    return {};
  }
  // RK4, Munthe-Kaas: stage k at u_k = s·a_k·K^u_{k−1}, q̇_k = q̇ + s·a_k·K^q̇_{k−1}; K^u_k = dexp⁻¹_{u_k}(q̇_k).
  constexpr double kNode[4] = {0.0, 0.5, 0.5, 1.0};
  constexpr double kWeight[4] = {1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0};
  u_stage_.setZero();
  k_u_ = kWeight[0] * qd_;  // K^u_1 = q̇ (u = 0)
  k_qd_ = kWeight[0] * qdd_start_;
  rate_ = qd_;
  qdd_stage_ = qdd_start_;
  double positive = kWeight[0] * std::max(0.0, power_motor_start_);
  double negative = kWeight[0] * std::min(0.0, power_motor_start_);
  double friction = kWeight[0] * power_friction_start_, effort = kWeight[0] * effort_start_;
  for (int k = 1; k < 4; ++k) {
    u_stage_ = (s * kNode[k]) * rate_;
    qd_stage_ = qd_ + (s * kNode[k]) * qdd_stage_;
    if (Status st = integrate(*model_, q_, u_stage_, 1.0, q_stage_); !st) return st;
    double p_motor = 0.0, p_friction = 0.0, e = 0.0;
    if (Status st = evaluate(ws_trial_, t_ + s * kNode[k], q_stage_, qd_stage_, schedule, held, qdd_stage_, p_motor,
                             p_friction, e);
        !st)
      return st;
    if (Status st = tangentRate(*model_, u_stage_, qd_stage_, rate_); !st) return st;
    k_u_ += kWeight[k] * rate_;
    k_qd_ += kWeight[k] * qdd_stage_;
    positive += kWeight[k] * std::max(0.0, p_motor);
    negative += kWeight[k] * std::min(0.0, p_motor);
    friction += kWeight[k] * p_friction;
    effort += kWeight[k] * e;
  }
  u_stage_ = s * k_u_;
  qd_trial_ = qd_ + s * k_qd_;
  if (Status st = integrate(*model_, q_, u_stage_, 1.0, q_trial_); !st) return st;
  trial_motor_positive_ = s * positive;
  trial_motor_negative_ = s * negative;
  trial_friction_ = -s * friction;
  trial_effort_ = s * effort;
  return {};
}

// ---- G(s): the smallest event function after a trial of length s (positive: no event yet). Also runs the trial.
double Simulation::eventFunction(const TorqueSchedule* schedule, const Eigen::VectorXd* held, double s,
                                 Status& status) noexcept {
  status = trialStep(s, schedule, held);
  if (!status) return 0.0;
  const int base = model_->baseVelocitySize();
  double G = 1.0;
  bool breakaway_candidates = false;
  for (int j = 0; j < model_->dof(); ++j) {
    const int v = base + j;
    if (eventDof(j)) {
      if (qd_[v] != 0.0)
        G = std::min(G, qd_trial_[v] / qd_[v]);  // 1 at the start, 0 where the velocity reaches zero
      else if (sticking(start_state_[at(j)]) && !breaking_[at(j)])
        breakaway_candidates = true;
    }
    double lower, upper;
    int q_index;
    if (limitsOf(j, lower, upper, q_index)) {
      const double tol = options_.friction.limit_tolerance;  // a joint resting on a limit has no event there
      if (q_[q_index] > lower + tol) G = std::min(G, q_trial_[q_index] - lower);
      if (q_[q_index] < upper - tol) G = std::min(G, upper - q_trial_[q_index]);
    }
  }
  if (!breakaway_candidates || G <= 0.0) return G;
  // A sticking DOF's room to its breakaway at the trial's end (a solve there): 1 − |μ|/f while |μ| < f; once μ is
  // on its bound (the solve may still call a q̈ below its tolerance a stick) or the DOF moves, ≤ −kStickFloor.
  double p_motor, p_friction, e;
  status = evaluate(ws_trial_, t_ + s, q_trial_, qd_trial_, schedule, held, qdd_stage_, p_motor, p_friction, e);
  if (!status) return 0.0;
  const FrictionResult& end = ws_trial_.friction;
  for (int j = 0; j < model_->dof(); ++j) {
    const int v = base + j;
    if (!eventDof(j) || qd_[v] != 0.0 || !sticking(start_state_[at(j)]) || breaking_[at(j)]) continue;
    const double box = box_[j], mu = std::abs(end.mu[j]);
    double g;
    if (qd_trial_[v] != 0.0)
      g = -std::abs(qd_trial_[v]) - kStickFloor;
    else if (end.state[at(j)] == JointState::AtLimit)
      g = 1.0;  // the stop holds it
    else if (end.state[at(j)] == JointState::Stick && mu < box)
      g = std::max(1.0 - mu / box, kStickFloor);
    else
      g = -std::abs(ws_trial_.solution.qdd[v]) - kStickFloor;
    G = std::min(G, g);
  }
  return G;
}

// ---- The first zero of G on (0, s_end] (G(s_end) = g_end ≤ 0): Illinois regula falsi, bisection when the bracket
// does not halve in three steps; s_at is the bracket's far side (G ≤ 0), the trial left at it.
Status Simulation::locateEvent(double s_end, double g_end, const TorqueSchedule* schedule, const Eigen::VectorXd* held,
                               double& s_at) noexcept {
  Status status;
  double lo = 0.0, hi = s_end, g_lo = 1.0, g_hi = g_end, last = s_end, width = s_end;
  int kept = 0;  // +1: lo kept last time, −1: hi kept
  for (int iteration = 0; hi - lo > options_.event_tolerance && iteration < kMaxLocateIterations; ++iteration) {
    double s = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
    if (iteration % 3 == 2) {
      const bool stalled = hi - lo > 0.5 * width;
      width = hi - lo;
      if (stalled) s = 0.5 * (lo + hi);
    }
    if (!(s > lo && s < hi)) s = 0.5 * (lo + hi);
    const double g = eventFunction(schedule, held, s, status);
    if (!status) return status;
    last = s;
    if (g > 0.0) {
      lo = s;
      g_lo = g;
      if (kept == -1) g_hi *= 0.5;  // Illinois: the end kept twice counts half
      kept = -1;
    } else {
      hi = s;
      g_hi = g;
      if (kept == 1) g_lo *= 0.5;
      kept = 1;
    }
  }
  s_at = hi;
  if (last != hi) (void)eventFunction(schedule, held, hi, status);  // the trial at the far side, to accept
  return status;
}

// ---- A one-DOF joint at its limit (q already on it): the inelastic stop. The impulse along the DOF that brings its velocity to zero
// moves the others by the task's unit-impulse response r = q̈(e_v) − q̈(0) (two plain solves; gravity, velocity
// terms and set points cancel): Δq̇ = −(q̇_v / r_v) r.
Status Simulation::stopAtLimit(int dof) noexcept {
  const Model& model = *model_;
  const int v = model.baseVelocitySize() + dof;
  if (qd_[v] == 0.0) return {};
  const double kinetic_before = energy_.kinetic;
  tau_unit_.setZero();
  if (Status s = solveHybridDynamics(model, ws_impulse_, q_, qd_, tau_unit_, *task_); !s) return s;
  qdd_unit_ = ws_impulse_.solution.qdd;
  tau_unit_[v] = 1.0;
  if (Status s = solveHybridDynamics(model, ws_impulse_, q_, qd_, tau_unit_, *task_); !s) return s;
  qdd_unit_ = ws_impulse_.solution.qdd - qdd_unit_;
  if (qdd_unit_[v] > 0.0) qd_ -= (qd_[v] / qdd_unit_[v]) * qdd_unit_;
  qd_[v] = 0.0;
  updateEnergyNow();
  energy_.impact_loss += kinetic_before - energy_.kinetic;
  return {};
}

// ---- Events of the DOFs at rest after a start solve: a DOF that came to rest sticks (or moves off the other
// way), a sticking one breaks away; a located breakaway is done once the DOF moves or its μ leaves the bound.
void Simulation::logStartStates() noexcept {
  const int base = model_->baseVelocitySize();
  for (int j = 0; j < model_->dof(); ++j) {
    const JointState state = ws_.friction.state[at(j)];
    start_state_[at(j)] = state;
    if (!eventDof(j)) continue;
    if (qd_[base + j] != 0.0) {
      breaking_[at(j)] = 0;
      continue;
    }
    if (breaking_[at(j)]) {
      const double box = box_[j];
      if (!sticking(state) || std::abs(ws_.friction.mu[j]) >= box) continue;  // still on its way
      breaking_[at(j)] = 0;                                                   // held again before it moved
    }
    Motion now = Motion::Stuck;
    if (state == JointState::SlipPositive) now = Motion::Positive;
    if (state == JointState::SlipNegative) now = Motion::Negative;
    if (now == motion_[at(j)]) continue;
    const EventKind kind = now == Motion::Stuck      ? EventKind::Stick
                           : now == Motion::Positive ? EventKind::SlipPositive
                                                     : EventKind::SlipNegative;
    events_.push_back({t_, j, kind});
    motion_[at(j)] = now;
  }
}

void Simulation::updateEnergyNow() noexcept {
  if (!jointSpaceInertia(*model_, ws_impulse_, q_)) return;
  const Eigen::MatrixXd& H = ws_impulse_.H;  // its lower triangle, read in place (a product would allocate)
  double twice_kinetic = 0.0;
  for (Eigen::Index c = 0; c < H.cols(); ++c) {
    twice_kinetic += H(c, c) * qd_[c] * qd_[c];
    for (Eigen::Index r = c + 1; r < H.rows(); ++r) twice_kinetic += 2.0 * H(r, c) * qd_[r] * qd_[c];
  }
  energy_.kinetic = 0.5 * twice_kinetic;
  Vec3 c = Vec3::Zero();
  if (centerOfMass(*model_, ws_impulse_, q_, kWholeRobot, c)) energy_.potential = -total_mass_ * task_->gravity.dot(c);
}

// ---- Each DOF moving now (or breaking away) keeps its direction's kinetic friction until the step ends or its
// velocity reaches zero (an event, which ends the trial): the solve gets none for it (nor for its mimic joints),
// evaluate applies it.
void Simulation::freezeSlipDirections() noexcept {
  const int base = model_->baseVelocitySize();
  for (int j = 0; j < model_->dof(); ++j) {
    const double v = qd_[base + j];
    slip_sign_[at(j)] = eventDof(j) && v != 0.0 ? (v > 0.0 ? 1 : -1) : 0;
    // A located breakaway not yet moving: it slips the way |μ| reached f, under kinetic friction (its q̈ at the
    // instant is 0⁺ with f_c = f, the solve's rounding of it either sign).
    if (eventDof(j) && v == 0.0 && breaking_[at(j)]) slip_sign_[at(j)] = motion_[at(j)] == Motion::Positive ? 1 : -1;
  }
  for (int j = 0; j < model_->dof(); ++j) {
    const int leader = mimic_of_[at(j)];
    const bool frozen = slip_sign_[at(leader < 0 ? j : leader)] != 0;
    solve_options_.breakaway[j] = frozen ? 0.0 : box_[j];
    solve_options_.kinetic[j] = frozen ? 0.0 : kinetic_[j];
    solve_options_.viscous[j] = frozen ? 0.0 : viscous_[j];
  }
}

// ---- The trial of length s_at becomes the state; then what reached its event there: a velocity at rest (exactly
// 0), a breakaway (logged; the DOF goes on with the q̈ its solve gives), a limit (the inelastic stop).
Status Simulation::acceptTrial(double s_at, double remaining, double t_end) noexcept {
  const int base = model_->baseVelocitySize();
  const double t_at = s_at == remaining ? t_end : t_ + s_at;
  const FrictionResult& end = ws_trial_.friction;
  for (int j = 0; j < model_->dof(); ++j) {
    const int v = base + j;
    if (!eventDof(j)) continue;
    if (qd_[v] != 0.0 && qd_trial_[v] / qd_[v] <= 0.0) qd_trial_[v] = 0.0;  // reached rest
    if (s_at == remaining || qd_[v] != 0.0 || !sticking(start_state_[at(j)]) || breaking_[at(j)]) continue;
    const double box = box_[j];
    const bool moved = qd_trial_[v] != 0.0;
    if (!moved && (sticking(end.state[at(j)]) && std::abs(end.mu[j]) < box)) continue;
    // μ > 0 opposes positive motion: at +f the DOF breaks away positively.
    const bool positive = moved ? qd_trial_[v] > 0.0 : end.mu[j] > 0.0;
    events_.push_back({t_at, j, positive ? EventKind::SlipPositive : EventKind::SlipNegative});
    motion_[at(j)] = positive ? Motion::Positive : Motion::Negative;
    breaking_[at(j)] = moved ? 0 : 1;
  }
  // Limits reached: those inside at the start and at or beyond a limit now.
  for (int j = 0; j < model_->dof(); ++j) {
    double lower, upper;
    int q_index;
    if (!limitsOf(j, lower, upper, q_index)) continue;
    const double tol = options_.friction.limit_tolerance, q_start = q_[q_index], q_now = q_trial_[q_index];
    double limit = std::numeric_limits<double>::quiet_NaN();
    if (q_start > lower + tol && q_now <= lower) limit = lower;
    if (q_start < upper - tol && q_now >= upper) limit = upper;
    if (std::isnan(limit)) continue;
    q_trial_[q_index] = limit;
    limit_dofs_.push_back(j);
  }
  q_ = q_trial_;
  qd_ = qd_trial_;
  t_ = t_at;
  energy_.motor_work_positive += trial_motor_positive_;
  energy_.motor_work_negative += trial_motor_negative_;
  energy_.friction_dissipation += trial_friction_;
  energy_.motor_effort += trial_effort_;
  updateEnergyNow();
  for (const int j : limit_dofs_) {
    if (Status s = stopAtLimit(j); !s) return s;
    events_.push_back({t_, j, EventKind::Limit});
    motion_[at(j)] = Motion::Stuck;
    breaking_[at(j)] = 0;
  }
  limit_dofs_.clear();
  return {};
}

// ---- One step of length h: start solve, trial, events, accept; again for what an event left of the step.
Status Simulation::advance(double h, const TorqueSchedule* schedule, const Eigen::VectorXd* held) noexcept {
  if (!ready_) return Status::error(StatusCode::BadOption, "simulation: reset(q, qd) before the first step");
  const double t_start = t_, t_end = t_reset_ + static_cast<double>(steps_ + 1) * h;
  for (int events = 0; t_ < t_end; ++events) {
    if (events > options_.max_events_per_step)
      return Status::error(StatusCode::EventCascade,
                           "simulation: more than %d events in the step from t = %.17g (max_events_per_step)",
                           options_.max_events_per_step, t_start);
    freezeSlipDirections();
    if (Status s = evaluate(ws_, t_, q_, qd_, schedule, held, qdd_start_, power_motor_start_, power_friction_start_,
                            effort_start_);
        !s)
      return s;
    logStartStates();
    const double remaining = t_end - t_;
    Status status;
    double s_at = remaining;
    const double g_end = eventFunction(schedule, held, remaining, status);
    if (!status) return status;
    if (g_end <= 0.0)
      if (Status s = locateEvent(remaining, g_end, schedule, held, s_at); !s) return s;
    if (Status s = acceptTrial(s_at, remaining, t_end); !s) return s;
  }
  ++steps_;
  return {};
}

}  // namespace zwang
