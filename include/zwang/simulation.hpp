/// \file
/// Motion over time (docs/simulation.md): the friction-aware dynamics
/// (solveWithFriction) integrated with a fixed step, and the stick–slip
/// events located in time inside the step instead of smeared over it.
///
/// A DOF at rest (q̇_j exactly 0) is stuck: the friction solve decides whether
/// it sticks (q̈_j = 0, set exactly, so a sticking joint does not creep by a
/// single bit) or breaks away. The events, each located to
/// SimulationOptions::event_tolerance in time and the step cut there:
///  * stick: a moving DOF's velocity reaches zero and friction holds it (its
///    velocity is set to exactly 0; the solve at that instant decides);
///  * slip+ / slip−: a stuck DOF breaks away (|μ_j| reaches f_j), or one that
///    just stopped moves off the other way;
///  * limit: a one-DOF joint reaches a position limit: an inelastic stop, the
///    impulse along that DOF that brings its velocity to zero (the other DOFs
///    take the impulse's reaction through the task's dynamics), q set onto the limit.
///
/// Integrators: semi-implicit Euler (q̇ += q̈ h, then q ⊕= q̇ h) and the
/// classical fourth-order Runge–Kutta, on the configuration space in the
/// Munthe-Kaas form (q = q₀ ⊕ u, u̇ = tangentRate(u, q̇): quaternions stay
/// unit and the order stays four on spherical and free joints).
///
/// Every call allocates nothing after construction and never throws.
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "zwang/friction.hpp"
#include "zwang/model.hpp"
#include "zwang/status.hpp"
#include "zwang/task.hpp"
#include "zwang/workspace.hpp"

namespace zwang {

/// How a step advances the state.
enum class Integrator {
  SemiImplicitEuler,  ///< q̇ ← q̇ + q̈ h, then q ← q ⊕ q̇ h (first order; one solve per step)
  RungeKutta4,        ///< classical RK4 in Munthe-Kaas form (fourth order; four solves per step)
};
/// "euler" or "rk4".
const char* toString(Integrator integrator);

/// Options of a Simulation.
struct SimulationOptions {
  double dt = 1e-3;                                       ///< the step [s]; events cut it, the next step is whole again
  Integrator integrator = Integrator::SemiImplicitEuler;  ///< how a step advances the state
  /// Events are located in time to this [s]: a bracket this narrow about the instant, the step ending at its far side.
  double event_tolerance = 1e-12;
  /// The friction solve at every evaluation. warm_start is on (the state changes little from one call to the
  /// next); velocity_tolerance is not used: a DOF is stuck when its velocity is exactly 0.
  FrictionOptions friction = [] {
    FrictionOptions o;
    o.warm_start = true;
    return o;
  }();
  /// Events one step may hold before it is refused with EventCascade (a Zeno cascade of stops and breakaways;
  /// 0: any event inside a step is refused).
  int max_events_per_step = 64;
};

/// What happened to a DOF (docs/simulation.md, "Events").
enum class EventKind { Stick, SlipPositive, SlipNegative, Limit };
/// "stick", "slip+", "slip-" or "limit" (the CLI's spelling).
const char* toString(EventKind kind);

/// One event: its time, the DOF (an index into FrictionResult::mu: the DOFs below the root) and what happened.
struct SimulationEvent {
  double t = 0.0;                     ///< when [s], located to SimulationOptions::event_tolerance
  int dof = -1;                       ///< which DOF below the root (0 … Model::dof() − 1)
  EventKind kind = EventKind::Stick;  ///< what happened to it
};

/// The energy over the motion so far [J] (integrals with the integrator's own quadrature).
struct EnergyLedger {
  double kinetic = 0.0;               ///< ½ q̇ᵀ H q̇ now (rotor inertias included)
  double potential = 0.0;             ///< −M g·c now (the task's gravity, the whole robot's mass and centre of mass)
  double initial = 0.0;               ///< kinetic + potential at reset
  double motor_work_positive = 0.0;   ///< ∫ max(0, τ_controlᵀ q̇) dt
  double motor_work_negative = 0.0;   ///< ∫ min(0, τ_controlᵀ q̇) dt (≤ 0: work the motors took back)
  double motor_effort = 0.0;          ///< ∫ ‖τ_control‖² dt [N²m²s]
  double friction_dissipation = 0.0;  ///< ∫ −τ_frictionᵀ q̇ dt (≥ 0; zero while every DOF sticks)
  double impact_loss = 0.0;           ///< kinetic energy the limit stops took
  /// (kinetic + potential − initial) − (motor work − dissipation − impact loss): zero but for the integrator's
  /// error (and the work of the task's contacts and wrenches, when they move).
  double balanceError() const {
    return kinetic + potential - initial -
           (motor_work_positive + motor_work_negative - friction_dissipation - impact_loss);
  }
};

/// τ over time: writes τ(t) (Model::nv() entries) for the time t. Called at every evaluation of the dynamics
/// (RK4: four per step, and more while an event is located), so it must depend on t only.
using TorqueSchedule = std::function<void(double t, Eigen::Ref<Eigen::VectorXd> tau)>;

/// A robot moving under the friction-aware dynamics of one model and task.
class Simulation {
 public:
  /// Sized for the model and task (allocates here, never again). The task is read at every step: change its
  /// set points, modes or wrenches between steps as a controller would, or pass another with setTask.
  Simulation(const Model& model, const Task& task, const SimulationOptions& options = {});

  /// Starts from (q, q̇) at time t: BadOption for options out of range, checks of q and q̇ as a solve's.
  Status reset(const Eigen::Ref<const Eigen::VectorXd>& q, const Eigen::Ref<const Eigen::VectorXd>& qd,
               double t = 0.0) noexcept;
  /// Another task from the next step on (rows up to the workspace's capacity, or it makes room once).
  void setTask(const Task& task) noexcept { task_ = &task; }

  /// One step of dt with τ held over it (a controller's zero-order hold).
  Status step(const Eigen::Ref<const Eigen::VectorXd>& tau) noexcept;
  /// One step of dt with τ(t) from a schedule.
  Status stepWith(const TorqueSchedule& tau) noexcept;

  double time() const { return t_; }                 ///< now [s]
  const Eigen::VectorXd& q() const { return q_; }    ///< the configuration now (Model::nq() entries)
  const Eigen::VectorXd& qd() const { return qd_; }  ///< the velocity now (Model::nv() entries)
  /// The last start solve of the last step (q̈ with the sticking DOFs' entries exactly 0, τ_control, ν, …): at the
  /// state the step started from, or, when an event cut the step, at the last event's instant.
  const Solution& solution() const { return ws_.solution; }
  /// The friction of that solve: μ per DOF, the states, tau_friction (a moving DOF's kinetic friction).
  const FrictionResult& friction() const { return ws_.friction; }
  /// Every event since reset, in time order (clearEvents drops them: a long run that reads them as it goes).
  const std::vector<SimulationEvent>& events() const { return events_; }
  void clearEvents() noexcept { events_.clear(); }               ///< drops the events logged so far
  const EnergyLedger& energy() const { return energy_; }         ///< the energy now and its integrals since reset
  const SimulationOptions& options() const { return options_; }  ///< as given to the constructor

 private:
  // A DOF's motion as the events see it: at rest (stuck), or moving either way.
  enum class Motion : signed char { Negative = -1, Stuck = 0, Positive = 1 };

  Status advance(double h, const TorqueSchedule* schedule, const Eigen::VectorXd* held) noexcept;
  Status evaluate(Workspace& ws, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                  const TorqueSchedule* schedule, const Eigen::VectorXd* held, Eigen::VectorXd& qdd,
                  double& power_motor, double& power_friction, double& effort) noexcept;
  Status trialStep(double s, const TorqueSchedule* schedule, const Eigen::VectorXd* held) noexcept;
  double eventFunction(const TorqueSchedule* schedule, const Eigen::VectorXd* held, double s, Status& status) noexcept;
  Status locateEvent(double s_end, double g_end, const TorqueSchedule* schedule, const Eigen::VectorXd* held,
                     double& s_at) noexcept;
  Status acceptTrial(double s_at, double remaining, double t_end) noexcept;
  Status stopAtLimit(int dof) noexcept;
  bool eventDof(int dof) const;
  bool limitsOf(int dof, double& lower, double& upper, int& q_index) const;
  void logStartStates() noexcept;
  void freezeSlipDirections() noexcept;
  void updateEnergyNow() noexcept;

  const Model* model_;
  const Task* task_;
  SimulationOptions options_;
  Workspace ws_, ws_trial_, ws_impulse_;
  double t_ = 0.0, t_reset_ = 0.0;
  long steps_ = 0;  // since reset: each step ends at t_reset_ + steps_ · dt exactly, not at a sum of dt's
  Eigen::VectorXd q_, qd_;
  // The step's start: its solve (qdd_start_, powers), and the trial's stages and end state.
  Eigen::VectorXd qdd_start_, tau_, held_, tau_unit_, qdd_unit_;
  Eigen::VectorXd q_trial_, qd_trial_, q_stage_, qd_stage_, u_stage_, qdd_stage_, k_u_, k_qd_, rate_;
  double power_motor_start_ = 0.0, power_friction_start_ = 0.0, effort_start_ = 0.0;
  double trial_motor_positive_ = 0.0, trial_motor_negative_ = 0.0, trial_friction_ = 0.0, trial_effort_ = 0.0;
  std::vector<Motion> motion_;
  std::vector<char> has_friction_;  // per DOF: a box or kinetic friction (the others have no events to find)
  // per DOF: a located breakaway (|μ| reached f) not yet moving: its q̈ is not zeroed, it is no candidate again
  std::vector<signed char> breaking_;
  std::vector<int> limit_dofs_;  // the DOFs an accepted trial brought onto a limit
  // The step's friction: a DOF moving at the step's start keeps the kinetic friction of that direction through the
  // step's stages (slip_sign_; the solve gets no friction for it: solve_options_), so that the trial is one smooth
  // mode up to the event where its velocity reaches zero. Per DOF below the root: the boxes, kinetic and viscous
  // coefficients (the options' overrides or the model's), the last two with the mimic joints' folded onto leaders.
  FrictionOptions solve_options_;
  Eigen::VectorXd box_, kinetic_, viscous_, kinetic_carried_, viscous_carried_, friction_applied_;
  std::vector<signed char> slip_sign_;
  std::vector<int> mimic_of_;  // per DOF: its leader's DOF for a mimic joint, −1 otherwise
  std::vector<JointState> start_state_;
  std::vector<SimulationEvent> events_;
  EnergyLedger energy_;
  double total_mass_ = 0.0;
  bool ready_ = false;
};

}  // namespace zwang
