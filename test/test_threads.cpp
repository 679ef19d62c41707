// Thread safety (issue #6): one shared Model, one Task and one Workspace per
// thread (docs/solver.md, "The hot path"), 8 threads × 10⁵ solves of the Panda:
// friction with every joint stuck, friction under a 6-row tool constraint plus
// an elbow row, and the plain constrained solver. The same on the dual-arm
// tree, and on the humanoid with a free base (issue #15) standing on both
// feet (two 6-row contacts) with friction on every joint, and on a two-arm tree
// of spherical shoulders and wrists (issue #25: multi-DOF joints, a quaternion
// per ball, friction on each DOF). Every thread must
// produce bit-for-bit the outputs of a single-threaded run of the same sequence.
//
// Built twice: as an ordinary ctest test, and with ThreadSanitizer in .ci/run
// (ZWANG_TSAN=ON builds only the library and this file, 10⁵ solves per
// thread). The environment variable ZWANG_THREAD_SOLVES overrides the count;
// the humanoid, whose solve costs many of the Panda's, runs a share of it
// (kHumanoidShare).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include "zwang/zwang.hpp"

using namespace zwang;

namespace {

constexpr int kThreads = 8;

// The ThreadSanitizer build (top-level CMakeLists.txt) runs the full 10⁵ solves
// per thread; the ordinary ctest run, also under ASan, 2·10³ (8 threads × 10⁴
// cost a minute under ASan on two cores).
#ifndef ZWANG_THREAD_SOLVES_DEFAULT
#define ZWANG_THREAD_SOLVES_DEFAULT 2000
#endif

long solvesPerThread() {
  const char* env = std::getenv("ZWANG_THREAD_SOLVES");
  return env ? std::strtol(env, nullptr, 10) : ZWANG_THREAD_SOLVES_DEFAULT;
}

// FNV-1a over the bytes of the outputs: equal hashes ⇔ (with overwhelming
// probability) bit-identical outputs.
struct Hash {
  std::uint64_t h = 1469598103934665603ull;
  void add(const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < bytes; ++k) h = (h ^ p[k]) * 1099511628211ull;
  }
  void add(const Eigen::VectorXd& v) { add(v.data(), sizeof(double) * static_cast<std::size_t>(v.size())); }
  void add(double x) { add(&x, sizeof x); }
};

// Shared by every thread (a solve only reads its Task and options).
struct Tasks {
  Task free_task, constrained;
  Eigen::VectorXd home;       // the configuration the inputs vary around (nq entries)
  Eigen::VectorXd amplitude;  // how far each joint varies: 0.3 rad, inside the Panda's limits
  FrictionOptions friction;   // the humanoid's URDF has no friction: 5 N·m breakaway on every joint
  explicit Tasks(const Model& model)
      : free_task(model), constrained(model), home(model.nq()), amplitude(Eigen::VectorXd::Constant(model.dof(), 0.3)) {
    if (model.hasFloatingBase()) {  // the humanoid, standing on both feet
      constrained.addContact("l_ankle", ConstraintMatrix::Identity(6, 6), Expressed::World);
      constrained.addContact("r_ankle", ConstraintMatrix::Identity(6, 6), Expressed::World);
      home.head<7>() << 0.0, 0.0, 0.7, 1.0, 0.0, 0.0, 0.0;  // upright, 0.7 m up
      // Each joint around the middle of its range, within 40 % of its half-range of it: never on a
      // limit (a stuck joint there gets the stop's one-sided reaction, and some of its limits are
      // at 0, where the feet on the ground can drive it into the stop: Infeasible).
      for (int j = 0; j < model.dof(); ++j) {
        const Joint& joint = model.joint(j);
        home[7 + j] = 0.5 * (joint.lower + joint.upper);
        amplitude[j] = std::min(0.3, 0.2 * (joint.upper - joint.lower));
      }
      friction.breakaway = Eigen::VectorXd::Constant(model.dof(), 5.0);
      friction.kinetic = friction.breakaway;
    } else if (model.name() == "ball_arms") {  // the left hand held in the world, the hands held apart
      constrained.addConstraint("left_hand", ConstraintMatrix::Identity(6, 3), Expressed::World);
      constrained.addRelativeConstraint("left_hand", "right_hand", ConstraintMatrix::Identity(6, 3));
      constrained.targets()[2] = 0.5;
      home.setZero();
      for (const Joint& joint : model.joints())  // balls at the identity (w = 1), elbows bent
        home[joint.q_index] = joint.type == JointType::Spherical ? 1.0 : 0.5;
    } else if (model.name() == "panda") {
      constrained.addConstraint("tool0", ConstraintMatrix::Identity(6, 6), Expressed::World);
      ConstraintMatrix elbow = ConstraintMatrix::Zero(6, 1);
      elbow(2, 0) = 1.0;
      constrained.addConstraint("panda_link4", elbow, Expressed::World);
      constrained.targets()[2] = 0.5;
      home << 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785;
    } else {  // the dual arm: the left hand held in the world, and the two hands held together
      constrained.addConstraint(model.bodyFrame(8), ConstraintMatrix::Identity(6, 3), Expressed::World);
      constrained.addRelativeConstraint(model.bodyFrame(8), model.bodyFrame(15), ConstraintMatrix::Identity(6, 6));
      constrained.targets()[2] = 0.5;
      home << 0.0, 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785, 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785;
    }
  }
};

struct Outcome {
  std::uint64_t hash = 0;
  long failures = 0;  // solves whose status was not Ok
  char first_failure[240] = {};
};

// The same sequence of solves on every thread; inputs vary with the index.
// A floating base's coordinates stay at home (the joints and τ vary).
Outcome run(const Model& model, const Tasks& tasks, long solves) {
  Workspace ws(model, tasks.constrained);
  const int n = model.dof(), base_velocity_size = model.baseVelocitySize();
  Eigen::VectorXd q = tasks.home, qd(model.nv()), tau = Eigen::VectorXd::Zero(model.nv());
  const Eigen::VectorXd& home = tasks.home;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nv());
  const FrictionOptions& options = tasks.friction;
  Hash hash;
  Outcome out;
  for (long i = 0; i < solves; ++i) {
    for (const Joint& joint : model.joints()) {
      const int j = joint.v_index - base_velocity_size;
      const double phase = 0.001 * static_cast<double>(i) + j;
      if (joint.type == JointType::Spherical) {  // turned from the identity by up to 0.3 rad about a moving axis
        const Vec3 turn(std::sin(phase), std::sin(1.3 * phase + 1.0), std::sin(0.7 * phase + 2.0));
        const Eigen::Quaterniond quat(Eigen::AngleAxisd(tasks.amplitude[j] * turn.norm(), turn.normalized()));
        q.segment<4>(joint.q_index) << quat.w(), quat.x(), quat.y(), quat.z();
      } else {
        q[joint.q_index] = home[joint.q_index] + tasks.amplitude[j] * std::sin(phase);
      }
    }
    for (int j = 0; j < n; ++j) tau[base_velocity_size + j] = 2.0 * std::cos(0.002 * static_cast<double>(i) * (j + 1));
    Status status;
    switch (i % 3) {
      case 0:  // every joint stuck, gravity only (a floating base falls)
        status = solveWithFriction(model, ws, q, zero, tau, tasks.free_task, options);
        hash.add(ws.friction.mu);
        break;
      case 1:  // constrained, one joint moving, friction
        qd = zero;
        qd[base_velocity_size + 3] = 0.2;
        status = solveWithFriction(model, ws, q, qd, tau, tasks.constrained, options);
        hash.add(ws.friction.mu);
        break;
      default:  // constrained, no friction
        status = solveHybridDynamics(model, ws, q, zero, tau, tasks.constrained);
        hash.add(ws.solution.nu);
        break;
    }
    if (!status.ok() && out.failures++ == 0)
      std::snprintf(out.first_failure, sizeof out.first_failure, "solve %ld: %s", i, status.message);
    hash.add(ws.solution.qdd);
    hash.add(ws.solution.tau_control);
    hash.add(ws.solution.gauss);
  }
  out.hash = hash.h;
  return out;
}

}  // namespace

namespace {
// A tree: two Panda arms (the bodies of panda.urdf) on a torso that turns
// about z, mounted 0.25 m to either side.
zwang::Model dualPanda(const zwang::Model& panda) {
  ModelBuilder builder("dual_panda", "base");
  Joint torso;
  torso.name = "torso";
  builder.addJoint(torso, "torso_link", RigidInertia::fromMassComInertia(15.0, Vec3(0, 0, 0.3), Mat3::Identity()));
  for (const char* side : {"left", "right"}) {
    std::string parent = "torso_link";
    for (int j = 0; j < panda.dof(); ++j) {
      Joint joint = panda.joint(j);
      joint.name = std::string(side) + "_" + joint.name;
      if (j == 0)
        joint.placement = joint.placement * Transform::translation(Vec3(0, side[0] == 'l' ? 0.25 : -0.25, 0.5));
      const std::string link = std::string(side) + "_" + panda.frame(panda.bodyFrame(j + 1)).name;
      builder.addJoint(joint, link, panda.inertia(j + 1), parent);
      parent = link;
    }
  }
  return builder.build();
}

// The humanoid's share of the solve count: one of its solves (29 joints, 35
// velocity coordinates, 12 contact rows, up to 29 stuck joints) costs 8–9 of
// the Panda's (ThreadSanitizer: 8.1× at ZWANG_THREAD_SOLVES=10000, 9.4× at
// 10⁵; Release 9×; the durations `test_threads_tsan --durations yes` prints),
// so a twentieth keeps its run at about half the Panda's.
constexpr long kHumanoidShare = 20;

// A tree of multi-DOF joints: a torso turning about z, two arms of a spherical shoulder, a revolute elbow and a
// spherical wrist (15 DOFs, nq = 19), breakaway friction 2 N·m on each DOF.
Model ballArms() {
  ModelBuilder builder("ball_arms", "base");
  Joint torso;
  torso.name = "torso";
  torso.breakaway_friction = torso.kinetic_friction = 2.0;
  builder.addJoint(torso, "torso_link", RigidInertia::fromMassComInertia(15.0, Vec3(0, 0, 0.3), Mat3::Identity()));
  for (const char* side : {"left", "right"}) {
    const std::string s(side);
    const double y = s == "left" ? 0.25 : -0.25;
    Joint ball;
    ball.type = JointType::Spherical;
    ball.breakaway_friction = ball.kinetic_friction = 2.0;
    Joint elbow = torso;
    elbow.axis = Vec3::UnitY();
    const Mat3 rod = Vec3(0.02, 0.02, 0.001).asDiagonal();  // a slender link along z
    ball.name = s + "_shoulder";
    ball.placement = Transform::translation(Vec3(0, y, 0.5));
    builder.addJoint(ball, s + "_upper_arm", RigidInertia::fromMassComInertia(2.0, Vec3(0, 0, 0.15), rod),
                     "torso_link");
    elbow.name = s + "_elbow";
    elbow.placement = Transform::translation(Vec3(0, 0, 0.3));
    builder.addJoint(elbow, s + "_forearm", RigidInertia::fromMassComInertia(1.5, Vec3(0, 0, 0.12), rod),
                     s + "_upper_arm");
    ball.name = s + "_wrist";
    ball.placement = Transform::translation(Vec3(0, 0, 0.25));
    builder.addJoint(ball, s + "_hand", RigidInertia::fromMassComInertia(0.5, Vec3(0, 0, 0.05), 0.1 * rod),
                     s + "_forearm");
  }
  return builder.build();
}

// The models of the test: the Panda, the dual-arm tree, the humanoid on a free base, the ball-jointed arms.
Model threadModel(int which) {
  if (which == 3) return ballArms();
  const Model panda = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf");
  if (which == 0) return panda;
  if (which == 1) return dualPanda(panda);
  UrdfOptions options;
  options.base = BaseType::Free;
  return loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/simple_humanoid.urdf", options);
}
}  // namespace

TEST_CASE("8 threads share one model, each with its own workspace: results identical to one thread") {
  const int which = GENERATE(0, 1, 2, 3);
  const Model model = threadModel(which);
  Tasks tasks(model);
  if (which % 2 == 1) {  // the trees: the pattern search, warm-started from each thread's own last pattern
    tasks.friction.method = FrictionMethod::StickPatterns;
    tasks.friction.warm_start = true;
  }
  const long solves = which == 2 ? std::max(1L, solvesPerThread() / kHumanoidShare) : solvesPerThread();
  REQUIRE(solves > 0);
  const Outcome reference = run(model, tasks, solves);
  INFO("first failure: " << reference.first_failure);
  CHECK(reference.failures == 0);

  std::vector<Outcome> outcomes(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back(
        [&model, &tasks, &outcomes, solves, t] { outcomes[static_cast<std::size_t>(t)] = run(model, tasks, solves); });
  for (std::thread& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) {
    INFO("thread " << t);
    CHECK(outcomes[static_cast<std::size_t>(t)].failures == 0);
    CHECK(outcomes[static_cast<std::size_t>(t)].hash == reference.hash);
  }
  const char* names[] = {"Panda", "dual-arm (15-joint tree)", "humanoid (free base, 29 joints, on two feet)",
                         "two-arm tree of spherical shoulders and wrists (15 DOFs)"};
  std::printf(
      "threads: %d x %ld solves on one shared %s model, every thread bit-identical to the single-thread run"
      " (hash %016llx)\n",
      kThreads, solves, names[which], static_cast<unsigned long long>(reference.hash));
}

namespace {
// One simulation of 1 s at 1 kHz (RK4) from home under a swinging torque: every step's q, q̇, the events and the
// energy hashed. The swing breaks joints away and lets them stick again, so the events' location runs too.
Outcome simulate(const Model& model, const Tasks& tasks) {
  SimulationOptions options;
  options.integrator = Integrator::RungeKutta4;
  options.friction.breakaway = Eigen::VectorXd::Constant(model.dof(), 2.0);
  options.friction.kinetic = Eigen::VectorXd::Constant(model.dof(), 1.5);
  Simulation sim(model, tasks.free_task, options);
  Outcome out;
  Hash hash;
  Status status = sim.reset(tasks.home, Eigen::VectorXd::Zero(model.nv()));
  const TorqueSchedule tau = [](double t, Eigen::Ref<Eigen::VectorXd> value) {
    for (Eigen::Index j = 0; j < value.size(); ++j)
      value[j] = 4.0 * std::sin(2.0 * M_PI * (1.0 + 0.2 * static_cast<double>(j)) * t);
  };
  for (int k = 0; k < 1000 && status.ok(); ++k) {
    status = sim.stepWith(tau);
    hash.add(sim.q());
    hash.add(sim.qd());
  }
  if (!status.ok()) {
    ++out.failures;
    std::snprintf(out.first_failure, sizeof out.first_failure, "%s", status.message);
  }
  for (const SimulationEvent& e : sim.events()) hash.add(e.t + static_cast<double>(e.dof) * 1e3);
  hash.add(sim.energy().friction_dissipation);
  out.hash = hash.h;
  out.failures += sim.events().empty() ? 1 : 0;  // the swing must break joints away
  return out;
}
}  // namespace

TEST_CASE("8 threads simulate on one shared model: trajectories and events identical to one thread") {
  const int which = GENERATE(0, 3);  // the Panda; the tree of spherical shoulders and wrists
  const Model model = threadModel(which);
  const Tasks tasks(model);
  const Outcome reference = simulate(model, tasks);
  INFO("first failure: " << reference.first_failure);
  CHECK(reference.failures == 0);
  std::vector<Outcome> outcomes(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back(
        [&model, &tasks, &outcomes, t] { outcomes[static_cast<std::size_t>(t)] = simulate(model, tasks); });
  for (std::thread& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) {
    INFO("thread " << t);
    CHECK(outcomes[static_cast<std::size_t>(t)].hash == reference.hash);
  }
}
