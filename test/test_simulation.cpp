// Simulation over time (issue #29) against closed forms: the report's 1-DOF arm under a torque ramp (stick, slip,
// stick again: event times and the motion in closed form), a held Panda that must not creep by a bit, the
// integrators' orders on a chain with a ball joint, a joint stopped at its limit, and the energy balance.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "support/simulation_models.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;

namespace {

// The report's chapter 6 arm: revolute about z (gravity along −z exerts no torque on it), I = 2.25 kg·m² about
// the joint; breakaway f and kinetic f_c.
Model rampArm(double f, double f_c) {
  Joint j;
  j.name = "joint1";
  j.axis = Vec3::UnitZ();
  j.breakaway_friction = f;
  j.kinetic_friction = f_c;
  const RigidInertia link = RigidInertia::fromMassComInertia(1.0, Vec3(0.5, 0, 0), Vec3(1.0, 1.0, 2.0).asDiagonal());
  return ModelBuilder("ramp_arm", "base").addJoint(j, "link1", link).build();
}

// The ramp up and back: τ = a t until t_p, then a (2 t_p − t).
constexpr double kRate = 20.0, kPeak = 1.0, kInertia = 2.25, kBox = 10.0;
double rampTorque(double t) { return t <= kPeak ? kRate * t : kRate * (2.0 * kPeak - t); }

// The closed form with f_c = f: sticks until a t = f (t_s), slips with I q̈ = τ − f, comes to rest at
// t_r = t_p + (1 + √2)(t_p − t_s) (where ∫ (τ − f) dt = 0 again; |τ| < f there: it sticks), breaks away negatively
// at 2 t_p + t_s (τ = −f).
struct RampClosedForm {
  double t_slip = kBox / kRate;
  double t_rest = kPeak + (1.0 + std::sqrt(2.0)) * (kPeak - kBox / kRate);
  double t_slip_back = 2.0 * kPeak + kBox / kRate;
  // q̇ and q − q₀ while it slips forwards (t_s ≤ t ≤ t_rest).
  double velocity(double t) const {
    const double d = std::min(t, kPeak) - t_slip;
    double v = kRate * d * d / (2.0 * kInertia);
    if (t > kPeak) {
      const double T = t - kPeak, D = kPeak - t_slip;
      v += kRate / kInertia * (D * T - 0.5 * T * T);
    }
    return v;
  }
  double position(double t) const {
    const double d = std::min(t, kPeak) - t_slip;
    double x = kRate * d * d * d / (6.0 * kInertia);
    if (t > kPeak) {
      const double T = t - kPeak, D = kPeak - t_slip;
      x += kRate * D * D / (2.0 * kInertia) * T + kRate / kInertia * (0.5 * D * T * T - T * T * T / 6.0);
    }
    return x;
  }
};

struct RampRun {
  std::vector<SimulationEvent> events;
  double q_at_1_5 = 0.0, qd_at_1_5 = 0.0;
  double q_rest_first = 0.0, q_rest_last = 0.0;  // while it sticks after t_rest
  bool rest_bitwise = true;
  EnergyLedger energy;
};

RampRun runRamp(Integrator integrator, double dt, double duration) {
  const Model model = rampArm(kBox, kBox);
  Task task(model);
  SimulationOptions options;
  options.dt = dt;
  options.integrator = integrator;
  Simulation sim(model, task, options);
  REQUIRE(sim.reset(Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1)));
  const TorqueSchedule tau = [](double t, Eigen::Ref<Eigen::VectorXd> out) { out[0] = rampTorque(t); };
  RampRun run;
  const RampClosedForm exact;
  const auto steps = static_cast<long>(std::llround(duration / dt));
  bool resting = false;
  for (long k = 0; k < steps; ++k) {
    REQUIRE(sim.stepWith(tau));
    if (std::abs(sim.time() - 1.5) < 0.5 * dt) {
      run.q_at_1_5 = sim.q()[0];
      run.qd_at_1_5 = sim.qd()[0];
    }
    if (sim.time() > exact.t_rest + 2 * dt && sim.time() < exact.t_slip_back - 2 * dt) {
      if (!resting) run.q_rest_first = sim.q()[0];
      resting = true;
      run.rest_bitwise = run.rest_bitwise && sim.q()[0] == run.q_rest_first && sim.qd()[0] == 0.0;
      run.q_rest_last = sim.q()[0];
    }
  }
  run.events = sim.events();
  run.energy = sim.energy();
  return run;
}

}  // namespace

TEST_CASE("simulation: the 1-DOF arm under a torque ramp sticks, slips and sticks again at the closed form's times") {
  const RampClosedForm exact;
  for (const Integrator integrator : {Integrator::RungeKutta4, Integrator::SemiImplicitEuler}) {
    CAPTURE(toString(integrator));
    const RampRun run = runRamp(integrator, 1e-3, 2.6);
    REQUIRE(run.events.size() == 3);
    CHECK(run.events[0].kind == EventKind::SlipPositive);
    CHECK(run.events[1].kind == EventKind::Stick);
    CHECK(run.events[2].kind == EventKind::SlipNegative);
    // The breakaways depend on τ(t) alone while the arm sticks: located to the event tolerance whatever the
    // integrator (the solve's |μ| reaching f, 1e-12 s, and the rounding of τ = a t near it).
    CHECK(std::abs(run.events[0].t - exact.t_slip) < 1e-9);
    CHECK(std::abs(run.events[2].t - exact.t_slip_back) < 1e-9);
    // The stop is where the integrated velocity reaches zero: exact for RK4 (q̈ is linear in t between the
    // ramp's kink and the events, which fall on the steps' edges), first order for Euler.
    if (integrator == Integrator::RungeKutta4) {
      CHECK(std::abs(run.events[1].t - exact.t_rest) < 1e-9);
      CHECK(run.q_at_1_5 == Approx(exact.position(1.5)).epsilon(1e-9));
      CHECK(run.qd_at_1_5 == Approx(exact.velocity(1.5)).epsilon(1e-9));
      CHECK(run.q_rest_first == Approx(exact.position(exact.t_rest)).epsilon(1e-9));
    } else {
      CHECK(std::abs(run.events[1].t - exact.t_rest) < 5e-3);
    }
    // Resting between the stop and the next breakaway: not a bit of creep.
    CHECK(run.rest_bitwise);
    // f_c = f: the arm's kinetic energy at rest is 0, all the motor's work went into friction.
    CHECK(std::abs(run.energy.balanceError()) < (integrator == Integrator::RungeKutta4 ? 1e-9 : 5e-2));
    CHECK(run.energy.friction_dissipation > 0.0);
  }
}

TEST_CASE("simulation: Euler's stop time converges at first order to the closed form") {
  const RampClosedForm exact;
  const double e1 = std::abs(runRamp(Integrator::SemiImplicitEuler, 2e-3, 2.3).events.at(1).t - exact.t_rest);
  const double e2 = std::abs(runRamp(Integrator::SemiImplicitEuler, 1e-3, 2.3).events.at(1).t - exact.t_rest);
  const double e3 = std::abs(runRamp(Integrator::SemiImplicitEuler, 5e-4, 2.3).events.at(1).t - exact.t_rest);
  INFO("errors " << e1 << " " << e2 << " " << e3);
  // First order: halving the step halves the error (±20 %: the step's edges fall differently on the events).
  CHECK(e1 / e2 == Approx(2.0).epsilon(0.2));
  CHECK(e2 / e3 == Approx(2.0).epsilon(0.2));
}

TEST_CASE("simulation: a Panda held by its joint friction does not move by a single bit over 10⁴ steps") {
  const Model model = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf");
  Task task(model);
  Eigen::VectorXd q(model.nq());
  q << 0.0, -0.6, 0.0, -2.2, 0.0, 1.6, 0.8;
  Workspace ws(model, task);
  // Friction that holds it against gravity with a torque swinging inside what is left of each box.
  REQUIRE(inverseDynamics(model, ws, q, Eigen::VectorXd::Zero(7), Eigen::VectorXd::Zero(7), task));
  const Eigen::VectorXd gravity = ws.tau;
  for (const Integrator integrator : {Integrator::SemiImplicitEuler, Integrator::RungeKutta4}) {
    SimulationOptions options;
    options.integrator = integrator;
    options.friction.breakaway = gravity.cwiseAbs().array() + 2.0;
    Simulation sim(model, task, options);
    REQUIRE(sim.reset(q, Eigen::VectorXd::Zero(7)));
    const TorqueSchedule tau = [](double t, Eigen::Ref<Eigen::VectorXd> out) {
      for (Eigen::Index j = 0; j < out.size(); ++j) out[j] = 1.5 * std::sin(2.0 * M_PI * (0.5 + 0.1 * j) * t);
    };
    for (int k = 0; k < 10000; ++k) REQUIRE(sim.stepWith(tau));
    CHECK(sim.q() == q);  // bitwise
    CHECK(sim.qd() == Eigen::VectorXd::Zero(7));
    CHECK(sim.events().empty());
    CHECK(sim.energy().friction_dissipation == 0.0);
    CHECK(sim.energy().balanceError() == 0.0);
  }
}

namespace {

// A frictionless chain with a ball joint in the middle: hinge, ball, hinge.
Model ballChain() {
  Joint hinge;
  hinge.name = "hinge1";
  hinge.axis = Vec3::UnitY();
  Joint ball;
  ball.name = "ball";
  ball.type = JointType::Spherical;
  ball.placement = Transform::translation(Vec3(0.4, 0, 0));
  Joint hinge2 = hinge;
  hinge2.name = "hinge2";
  hinge2.axis = Vec3(1, 1, 0).normalized();
  hinge2.placement = Transform::translation(Vec3(0.3, 0.1, 0));
  const RigidInertia a = RigidInertia::fromMassComInertia(1.2, Vec3(0.2, 0, 0), Vec3(0.02, 0.03, 0.04).asDiagonal());
  const RigidInertia b =
      RigidInertia::fromMassComInertia(0.8, Vec3(0.15, 0.05, 0), Vec3(0.01, 0.02, 0.02).asDiagonal());
  const RigidInertia c =
      RigidInertia::fromMassComInertia(0.5, Vec3(0.1, 0, 0.05), Vec3(0.01, 0.01, 0.015).asDiagonal());
  return ModelBuilder("ball_chain", "base")
      .addJoint(hinge, "a", a)
      .addJoint(ball, "b", b)
      .addJoint(hinge2, "c", c)
      .build();
}

// The state after 0.3 s from a tumbling start, with step dt.
void swing(const Model& model, Integrator integrator, double dt, Eigen::VectorXd& q, Eigen::VectorXd& qd) {
  Task task(model);
  SimulationOptions options;
  options.dt = dt;
  options.integrator = integrator;
  Simulation sim(model, task, options);
  Eigen::VectorXd q0(model.nq()), qd0(model.nv());
  q0 << 0.3, std::cos(0.4), std::sin(0.4) * 0.6, std::sin(0.4) * 0.8, 0.0, -0.5;
  qd0 << 1.0, 2.0, -1.5, 3.0, 0.7;
  REQUIRE(sim.reset(q0, qd0));
  const Eigen::VectorXd tau = Eigen::VectorXd::Zero(model.nv());
  const auto steps = std::llround(0.3 / dt);
  for (long k = 0; k < steps; ++k) REQUIRE(sim.step(tau));
  q = sim.q();
  qd = sim.qd();
  CHECK(sim.energy().balanceError() == Approx(0.0).margin(integrator == Integrator::RungeKutta4 ? 1e-6 : 0.5));
}

double stateError(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& q_ref,
                  const Eigen::VectorXd& qd_ref) {
  Eigen::VectorXd dq(model.nv());
  REQUIRE(difference(model, q_ref, q, dq));
  return std::max(dq.cwiseAbs().maxCoeff(), (qd - qd_ref).cwiseAbs().maxCoeff());
}

}  // namespace

TEST_CASE("simulation: RK4 is fourth order and Euler first order on a chain with a ball joint") {
  const Model model = ballChain();
  Eigen::VectorXd q_ref, qd_ref;
  swing(model, Integrator::RungeKutta4, 1.25e-4, q_ref, qd_ref);
  for (const Integrator integrator : {Integrator::RungeKutta4, Integrator::SemiImplicitEuler}) {
    CAPTURE(toString(integrator));
    const bool rk4 = integrator == Integrator::RungeKutta4;
    const double h = rk4 ? 4e-3 : 1e-3;
    Eigen::VectorXd q1, qd1, q2, qd2;
    swing(model, integrator, h, q1, qd1);
    swing(model, integrator, h / 2, q2, qd2);
    const double e1 = stateError(model, q1, qd1, q_ref, qd_ref), e2 = stateError(model, q2, qd2, q_ref, qd_ref);
    INFO("errors " << e1 << " " << e2);
    // Halving the step divides the error by 2^order (±25 %: the asymptotic range, and RK4's reference error).
    CHECK(e1 / e2 == Approx(rk4 ? 16.0 : 2.0).epsilon(0.25));
    CHECK(std::abs(q2.segment(1, 4).norm() - 1.0) < 1e-14);  // the quaternion stays unit
  }
}

TEST_CASE("simulation: a pendulum falling onto its limit stops there, inelastically") {
  const Model model = zwang::testing::limitPendulum();
  Task task(model);
  SimulationOptions options;
  options.integrator = Integrator::RungeKutta4;
  Simulation sim(model, task, options);
  REQUIRE(sim.reset(Eigen::VectorXd::Constant(1, 0.2), Eigen::VectorXd::Constant(1, 3.0)));
  const Eigen::VectorXd tau = Eigen::VectorXd::Zero(1);
  for (int k = 0; k < 400; ++k) REQUIRE(sim.step(tau));
  bool hit = false;
  for (const SimulationEvent& e : sim.events()) hit = hit || e.kind == EventKind::Limit;
  REQUIRE(hit);
  CHECK(sim.events().front().kind == EventKind::Limit);
  CHECK(sim.energy().impact_loss > 0.0);
  // Energy: what the stop took and friction dissipated, to RK4's accuracy.
  CHECK(std::abs(sim.energy().balanceError()) < 1e-6);
  // After the stop gravity swings it back: it leaves the limit and its motion carries on inside.
  CHECK(sim.q()[0] <= 0.5);
  CHECK(sim.q()[0] >= -0.5);
}

TEST_CASE("simulation: bad options and inputs come back as a Status naming them") {
  const Model model = rampArm(kBox, kBox);
  Task task(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1);
  auto resetWith = [&](const SimulationOptions& options) {
    Simulation sim(model, task, options);
    return sim.reset(zero, zero);
  };
  SimulationOptions options;
  options.dt = 0.0;
  Status s = resetWith(options);
  CHECK(s.code == StatusCode::BadOption);
  CHECK(std::string(s.message) == "simulation dt 0 must be finite and > 0");
  options = {};
  options.event_tolerance = 1.0;
  s = resetWith(options);
  CHECK(s.code == StatusCode::BadOption);
  CHECK(std::string(s.message) == "simulation event_tolerance 1 must be > 0 and < dt (0.001)");
  options = {};
  options.max_events_per_step = -1;
  CHECK(resetWith(options).code == StatusCode::BadOption);

  Simulation sim(model, task);
  s = sim.step(zero);
  CHECK(s.code == StatusCode::BadOption);
  CHECK(std::string(s.message) == "simulation: reset(q, qd) before the first step");
  CHECK(sim.reset(zero, Eigen::VectorXd::Zero(2)).code == StatusCode::SizeMismatch);
  CHECK(sim.reset(zero, Eigen::VectorXd::Constant(1, NAN)).code == StatusCode::NonFinite);
  REQUIRE(sim.reset(zero, zero));
  CHECK(sim.step(Eigen::VectorXd::Zero(3)).code == StatusCode::SizeMismatch);
  s = sim.stepWith([](double, Eigen::Ref<Eigen::VectorXd> out) { out[0] = INFINITY; });
  CHECK(s.code == StatusCode::NonFinite);
  CHECK(std::string(s.message) == "the torque schedule gave a value that is not finite at t = 0");

  // An event inside a step with max_events_per_step = 0: the breakaway of the ramp at 0.5 s.
  options = {};
  options.max_events_per_step = 0;
  Simulation strict(model, task, options);
  REQUIRE(strict.reset(zero, zero));
  const TorqueSchedule tau = [](double t, Eigen::Ref<Eigen::VectorXd> out) { out[0] = rampTorque(t + 0.0005); };
  Status last;
  for (int k = 0; k < 600 && last; ++k) last = strict.stepWith(tau);
  CHECK(last.code == StatusCode::EventCascade);
  CHECK(std::string(last.message).find("simulation: more than 0 events in the step from t = 0.49") == 0);
}
