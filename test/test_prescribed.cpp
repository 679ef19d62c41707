// Prescribed and locked joints (issue #27 item 1) against the independent references, on random trees of every
// joint type (support/joint_types_problem) on a fixed, free or planar base:
//  * solveHybridDynamics with random DOFs prescribed — one-DOF joints, all or some DOFs of a multi-DOF joint, the
//    floating base's own — against the dense KKT reference with the prescribed accelerations as equality rows (a
//    row q̈_k = y_k per prescribed DOF, its force the joint's own generalized force: support/floating_reference,
//    no recursive algorithm): q̈, ν of the task's rows, τ_c, τ_control (the prescribed DOFs' torques in them) and
//    Z, with frame rows, relative rows and contacts;
//  * every DOF prescribed: τ_control is inverse dynamics (the dense reference's H q̈ + C);
//  * solveWithFriction with prescribed DOFs against the brute-force enumeration of every stick/slip pattern on the
//    same reference (the prescribed DOFs as rows there, with no friction unknown: their box is [0, 0]);
//  * what a user can get wrong: a mimic joint, an index out of range, a non-finite or resized acceleration vector.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "support/floating_reference.hpp"
#include "support/friction_reference.hpp"
#include "support/joint_types_problem.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// Which DOFs a draw prescribes, and how many of each kind.
struct Prescription {
  std::vector<int> dofs;  // entries of v, ascending
  int one_dof = 0, multi_dof = 0, partial_joints = 0, base = 0;
};

// Prescribe random DOFs in `task` and add their rows to the reference's input: each moving joint with probability
// `p` (a multi-DOF joint then all its DOFs or, half the time, a random subset), each base DOF with probability
// p / 3; mimic joints never (they follow their leaders). Accelerations in ±3; a joint locked (all zero) one time in
// four. Rows are added after the input's own, so the reference's ν keeps those first.
Prescription prescribeRandomly(std::mt19937_64& rng, const ChainSpec& spec, const FloatingBase& base, double p,
                               Task& task, FloatingInput& in) {
  Prescription out;
  const int base_velocity_size = base.baseVelocitySize();
  auto add_row = [&](int v, double y) {
    task.setDofMode(v, DofMode::Prescribed);
    task.prescribedAccelerations()[v] = y;
    ConstraintInput c;
    if (v < base_velocity_size)
      c.base_dof = v;
    else
      c.joint = v - base_velocity_size;
    c.A = Matrix6Xd::Zero(6, 1);
    c.b = Eigen::VectorXd::Constant(1, y);
    in.constraints.push_back(c);
    out.dofs.push_back(v);
  };
  for (int v = 0; v < base_velocity_size; ++v)
    if (uniform01(rng) < p / 3) {
      add_row(v, uniform(rng, -3.0, 3.0));
      ++out.base;
    }
  int v = base_velocity_size;
  for (const int k : spec.movingJoints()) {
    const JointSpec& joint = spec.joints[static_cast<std::size_t>(k)];
    const int nv = joint.nv();
    if (!joint.isMimic() && uniform01(rng) < p) {
      const bool locked = uniform01(rng)<0.25, subset = nv> 1 && uniform01(rng) < 0.5;
      int taken = 0;
      for (int a = 0; a < nv; ++a)
        if (!subset || uniform01(rng) < 0.5) {
          add_row(v + a, locked ? 0.0 : uniform(rng, -3.0, 3.0));
          ++taken;
        }
      if (taken > 0) (nv == 1 ? out.one_dof : out.multi_dof) += 1;
      if (taken > 0 && taken < nv) ++out.partial_joints;
    }
    v += nv;
  }
  std::sort(out.dofs.begin(), out.dofs.end());
  return out;
}

}  // namespace

TEST_CASE("prescribed joints: solveHybridDynamics against the dense KKT with the prescriptions as rows",
          "[prescribed]") {
  std::mt19937_64 rng(stressSeedOr(2026112801ULL));
  int compared = 0, draws = 0, constrained = 0, contacts = 0, one_dof = 0, multi_dof = 0, partial = 0, base_dofs = 0;
  double e_qdd = 0, e_nu = 0, e_tau_c = 0, e_tau_control = 0, e_gauss = 0, e_prescribed = 0;
  while (compared < 400) {
    REQUIRE(++draws < 4000);
    auto [spec, base, in, model] = drawLoadedTree(rng, 2, 14, 0.3, rowOptions(6, 0.3));
    // A contact half the time on a floating base: forces the motors do not give, which the prescribed torques see.
    const int has_contact = makeContact(rng, base, in) ? 1 : 0;
    Task task = floatingTaskFromInput(model, in);
    const int user_rows = task.constraintRows();
    const Prescription prescribed = prescribeRandomly(rng, spec, base, 0.4, task, in);
    if (prescribed.dofs.empty()) continue;
    const FloatingResult dense = floatingDynamics(spec, base, in);
    if (!wellPosed(dense)) continue;
    Workspace ws(model, task);
    const Status s = solveHybridDynamics(model, ws, in.q, in.v, in.tau, task);
    INFO("draw " << draws << " (" << toString(base.kind) << " base, " << model.nv() << " DOFs, "
                 << prescribed.dofs.size() << " prescribed): " << s.message);
    REQUIRE(s);
    ++compared;
    constrained += user_rows > 0 ? 1 : 0;
    contacts += has_contact;
    one_dof += prescribed.one_dof;
    multi_dof += prescribed.multi_dof;
    partial += prescribed.partial_joints;
    base_dofs += prescribed.base;
    e_qdd = std::max(e_qdd, relativeError(ws.solution.qdd, dense.qdd));
    e_nu = std::max(e_nu, relativeError(ws.solution.nu, dense.nu.head(user_rows)));
    e_tau_c = std::max(e_tau_c, relativeError(ws.solution.tau_constraint, dense.tau_c));
    e_tau_control = std::max(e_tau_control, relativeError(ws.solution.tau_control, dense.tau_control));
    // Z with the given τ on every DOF: a prescribed DOF's term τ·q̈ is fixed by the prescription.
    e_gauss = std::max(e_gauss, std::abs(ws.solution.gauss - dense.gauss) / std::max(1.0, std::abs(dense.gauss)));
    for (const int v : prescribed.dofs)  // exactly what was asked: the sweep copies it
      e_prescribed = std::max(e_prescribed, std::abs(ws.solution.qdd[v] - task.prescribedAccelerations()[v]));
  }
  std::printf(
      "prescribed joints vs the dense reference: %d compared (%d draws), %d with task rows, %d with a contact\n"
      "  prescribed: %d one-DOF joints, %d multi-DOF joints (%d of them in part), %d base DOFs\n"
      "  max rel. error qdd %.2g, nu %.2g, tau_c %.2g, tau_control %.2g, Gauss %.2g; |qdd - prescribed| %.2g\n",
      compared, draws, constrained, contacts, one_dof, multi_dof, partial, base_dofs, e_qdd, e_nu, e_tau_c,
      e_tau_control, e_gauss, e_prescribed);
  CHECK(constrained > 150);
  CHECK(contacts > 30);
  CHECK(multi_dof > 60);
  CHECK(partial > 20);
  CHECK(base_dofs > 30);
  // Both sides solve the same KKT system exactly, kept draws conditioned below 1e6: round-off only.
  CHECK(e_qdd < 1e-9);
  CHECK(e_nu < 1e-9);
  CHECK(e_tau_c < 1e-9);
  CHECK(e_tau_control < 1e-9);
  CHECK(e_gauss < 1e-9);
  CHECK(e_prescribed == 0.0);
}

TEST_CASE("prescribed joints: with every DOF prescribed the torques are inverse dynamics", "[prescribed]") {
  std::mt19937_64 rng(stressSeedOr(2026112802ULL));
  double e_tau = 0;
  int compared = 0;
  for (int draw = 0; draw < 200; ++draw) {
    auto [spec, base, in, model] = drawLoadedTree(rng, 1, 16, 0.3, rowOptions(0, 0.0));
    Task task = floatingTaskFromInput(model, in);
    if (!model.mimicJoints().empty()) continue;  // a mimic joint follows its leader: it cannot be prescribed
    const Eigen::VectorXd qdd = randomVector(rng, model.nv(), 3.0);
    for (int v = 0; v < model.nv(); ++v) task.setDofMode(v, DofMode::Prescribed);
    task.prescribedAccelerations() = qdd;
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.v, in.tau, task));
    const Eigen::VectorXd tau = floatingInverseDynamics(spec, base, in.q, in.v, qdd, in.gravity, in.wrenches);
    e_tau = std::max(e_tau, relativeError(ws.solution.tau_control, tau));
    CHECK(ws.solution.qdd == qdd);
    ++compared;
  }
  std::printf("every DOF prescribed vs dense inverse dynamics: %d trees, max rel. error tau %.2g\n", compared, e_tau);
  CHECK(compared > 100);
  CHECK(e_tau < 1e-10);  // H q̈ + C against RNEA: no system solved, round-off of sums only
}

TEST_CASE("prescribed joints: friction matches the brute-force enumeration with the prescriptions as rows",
          "[prescribed][friction]") {
  // The automatic choice (the active set for most of these small stuck sets) and the pattern search forced.
  const FrictionMethod method = GENERATE(FrictionMethod::Automatic, FrictionMethod::StickPatterns);
  INFO("method " << toString(method));
  std::mt19937_64 rng(stressSeedOr(2026112803ULL));
  int compared = 0, draws = 0, unique = 0, moving_prescribed = 0, resting_prescribed = 0;
  double e_qdd = 0, e_g = 0, e_mu = 0, e_tau_control = 0;
  while (compared < 300) {
    REQUIRE(++draws < 5000);
    const ChainSpec spec = randomJointTypesTree(rng, 2, 5, 0.4);
    const int n = spec.dof();
    if (n > 11) continue;  // the enumeration is 3^stuck
    const FloatingBase base = randomBase(rng);
    RandomProblemOptions options;
    options.max_constraint_rows = std::min(3, n);
    options.max_constraint_frames = 2;
    options.relative_probability = 0.2;
    FloatingInput in = loadedInput(rng, spec, base, options);
    const int base_velocity_size = base.baseVelocitySize();
    const Model model = floatingModelFromSpec(spec, base);
    Task task = floatingTaskFromInput(model, in);
    const Prescription prescribed = prescribeRandomly(rng, spec, base, 0.35, task, in);
    if (prescribed.dofs.empty()) continue;

    // Every DOF moving at 0.1–2; then up to 5 of the torque-driven ones and about half the prescribed ones at rest.
    FrictionSetup setup = sizedFrictionSetup(n);
    moveEveryDof(rng, base_velocity_size, n, in);
    int stuck_count = 0;
    for (int k = 0; k < n; ++k) {
      setup.breakaway(k) = uniform(rng, 0.0, 15.0);
      setup.kinetic(k) = uniform(rng, 0.0, setup.breakaway(k));
      setup.viscous(k) = uniform(rng, 0.0, 1.0);
      const int v = base_velocity_size + k;
      const bool is_prescribed = std::binary_search(prescribed.dofs.begin(), prescribed.dofs.end(), v);
      if (is_prescribed) {
        if (uniform01(rng) < 0.5) {
          in.v(v) = 0.0;
          ++resting_prescribed;
        } else {
          ++moving_prescribed;
        }
      } else if (stuck_count < 5 && uniform01(rng) < 0.4) {
        in.v(v) = 0.0;
        setup.stuck.push_back(k);
        ++stuck_count;
      }
    }
    FrictionOptions fo;
    fo.method = method;
    fo.joint_limits = false;  // multi-DOF joints have none; the one-DOF ones are drawn inside theirs
    fo.breakaway = setup.breakaway;
    fo.kinetic = setup.kinetic;
    fo.viscous = setup.viscous;
    // The reference: a prescribed DOF at rest has no friction at all (no unknown, and no kinetic term at q̇ = 0);
    // a moving one its kinetic friction, as any moving DOF.
    for (int k = 0; k < n; ++k)
      if (in.v(base_velocity_size + k) == 0.0 &&
          std::find(setup.stuck.begin(), setup.stuck.end(), k) == setup.stuck.end())
        setup.kinetic(k) = setup.viscous(k) = 0.0;

    const FloatingResult dense = floatingDynamics(spec, base, in);
    if (!wellPosed(dense)) continue;
    const FrictionReference ref = bruteForceFloatingFriction(spec, base, in, setup);
    REQUIRE(ref.feasible);                // no limits: some pattern is always valid
    if (ref.qdd_spread > 1e-9) continue;  // the reference itself cannot tell q̈* apart

    Workspace ws(model, task);
    const Status s = solveWithFriction(model, ws, in.q, in.v, in.tau, task, fo);
    INFO("draw " << draws << " (" << toString(base.kind) << " base, " << n << " DOFs, " << prescribed.dofs.size()
                 << " prescribed, " << stuck_count << " stuck): " << s.message);
    REQUIRE(s);
    ++compared;
    const FrictionResult& fr = ws.friction;
    REQUIRE(fr.stuck == setup.stuck);  // prescribed DOFs are never friction unknowns
    for (const int v : prescribed.dofs)
      if (v >= base_velocity_size)
        CHECK(fr.state[static_cast<std::size_t>(v - base_velocity_size)] == JointState::Prescribed);
    const double eq = relativeError(ws.solution.qdd, ref.qdd);
    const double eg = std::abs(fr.gauss_dual - ref.gauss_dual) / std::max(1.0, std::abs(ref.gauss_dual));
    CHECK(eq < 1e-8);  // both sides solve the same motion; rounding of condition ≤ 1e6 systems
    CHECK(eg < 1e-8);
    e_qdd = std::max(e_qdd, eq);
    e_g = std::max(e_g, eg);
    const bool mu_unique = ref.mu_spread <= 1e-9 * (1.0 + setup.breakaway.maxCoeff()) && !ref.pinned;
    if (!mu_unique) continue;
    ++unique;
    const double em = (fr.mu - ref.mu).cwiseAbs().maxCoeff() / (1.0 + setup.breakaway.maxCoeff());
    const double et = relativeError(ws.solution.tau_control, ref.tau_control);
    CHECK(em < 1e-8);
    CHECK(et < 1e-8);
    e_mu = std::max(e_mu, em);
    e_tau_control = std::max(e_tau_control, et);
  }
  std::printf(
      "prescribed joints, friction vs brute force: %d compared (%d draws); prescribed DOFs %d moving, %d at rest\n"
      "  max rel. error qdd %.2e, g(mu*) %.2e; mu* unique in %d: mu %.2e, tau_control %.2e\n",
      compared, draws, moving_prescribed, resting_prescribed, e_qdd, e_g, unique, e_mu, e_tau_control);
  CHECK(unique > 150);
  CHECK(moving_prescribed > 100);
  CHECK(resting_prescribed > 100);
}

TEST_CASE("prescribed joints: what a user can get wrong is refused, naming it", "[prescribed][errors]") {
  const Model model = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/baxter.urdf");
  Task task(model);
  // A mimic joint follows its leader: prescribing it would prescribe the leader through the coupling.
  CHECK_THROWS_WITH(task.prescribe("l_gripper_r_finger_joint"),
                    Catch::Contains("'l_gripper_r_finger_joint' is a mimic joint") && Catch::Contains("leader"));
  CHECK_THROWS_WITH(task.lock("no_such_joint"), Catch::Contains("no moving joint 'no_such_joint'"));
  CHECK_THROWS_WITH(task.prescribe(static_cast<int>(model.joints().size())), Catch::Contains("out of range"));
  CHECK_THROWS_WITH(task.setDofMode(-1, DofMode::Prescribed), Catch::Contains("DOF index -1 out of range"));
  CHECK(task.prescribedCount() == 0);          // nothing half-done by the refusals
  task.prescribe("l_gripper_l_finger_joint");  // the leader: its mimic joint follows
  task.lock("left_s0");
  CHECK(task.prescribedCount() == 2);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nq()), zero = Eigen::VectorXd::Zero(model.nv());
  Workspace ws(model, task);
  const int s0 = model.joint(model.jointIndex("left_s0")).v_index;
  task.prescribedAccelerations()[s0] = std::nan("");
  Status s = solveHybridDynamics(model, ws, q, zero, zero, task);
  CHECK(s.code == StatusCode::NonFinite);
  CHECK_THAT(s.message, Catch::Contains("prescribed acceleration of 'left_s0'"));
  task.prescribedAccelerations().resize(3);
  s = solveHybridDynamics(model, ws, q, zero, zero, task);
  CHECK(s.code == StatusCode::SizeMismatch);
  CHECK_THAT(s.message, Catch::Contains("prescribed accelerations have 3 entries"));
  task.prescribedAccelerations() = zero;
  REQUIRE(solveHybridDynamics(model, ws, q, zero, zero, task));
  CHECK(ws.solution.qdd[s0] == 0.0);  // locked
  task.release("left_s0");
  task.release("l_gripper_l_finger_joint");
  CHECK(task.prescribedCount() == 0);
  REQUIRE(solveHybridDynamics(model, ws, q, zero, zero, task));
  const Eigen::VectorXd released = ws.solution.qdd;
  const Task fresh(model);
  REQUIRE(solveHybridDynamics(model, ws, q, zero, zero, fresh));
  CHECK(released == ws.solution.qdd);  // released: the plain solve's path, bit for bit
}
