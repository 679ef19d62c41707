// Many rows (issue #27 item 4): a workspace made with the default room (6 rows) solves a task of 30 rows over 10
// frames of a tree by making room itself, against the dense KKT reference (support/floating_reference: no recursive
// algorithm); Workspace::reserve refuses another model and keeps its room when asked for less.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "support/floating_reference.hpp"
#include "support/joint_types_problem.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// `frames` distinct links of the tree below its root, each with `rows_each` random unit rows (an axis-aligned unit
// force or moment, or a random direction), in local or world axes, set points in ±3.
void addRowsOnFrames(std::mt19937_64& rng, const ChainSpec& spec, int frames, int rows_each, FloatingInput& in) {
  std::vector<std::size_t> links(spec.links.size() - 1);
  for (std::size_t k = 0; k < links.size(); ++k) links[k] = k + 1;
  std::shuffle(links.begin(), links.end(), rng);
  for (int f = 0; f < frames; ++f) {
    ConstraintInput c;
    c.link = spec.links[links[static_cast<std::size_t>(f)]].name;
    c.A = Matrix6Xd::Zero(6, rows_each);
    for (int r = 0; r < rows_each; ++r) {
      if (uniform01(rng) < 0.5)
        c.A(uniformInt(rng, 0, 5), r) = 1.0;
      else
        c.A.col(r) = randomVector(rng, 6, 1.0).normalized();
    }
    c.b = randomVector(rng, rows_each, 3.0);
    c.axes = uniform01(rng) < 0.5 ? Axes::Local : Axes::World;
    in.constraints.push_back(c);
  }
}

}  // namespace

TEST_CASE("many rows: a default workspace makes room for 30 rows over 10 frames of a tree", "[many_rows]") {
  std::mt19937_64 rng(stressSeedOr(2026112901ULL));
  int compared = 0, draws = 0, floating = 0;
  double e_qdd = 0, e_nu = 0, e_tau_control = 0;
  while (compared < 10) {
    REQUIRE(++draws < 400);
    const ChainSpec spec = randomJointTypesTree(rng, 14, 18, 0.6);  // some 30–40 DOFs
    if (spec.dof() < 32) continue;                                  // room for 30 independent rows
    const FloatingBase base = randomBase(rng);
    RandomProblemOptions options;
    options.max_constraint_rows = 0;  // the rows below instead
    FloatingInput in = loadedInput(rng, spec, base, options);
    addRowsOnFrames(rng, spec, 10, 3, in);
    const Model model = floatingModelFromSpec(spec, base);
    const Task task = floatingTaskFromInput(model, in);
    REQUIRE(task.constraintRows() == 30);
    const FloatingResult dense = floatingDynamics(spec, base, in);
    if (!wellPosed(dense)) continue;
    Workspace ws(model);  // room for 6 rows
    REQUIRE(ws.constraintCapacity() == 6);
    const Status s = solveHybridDynamics(model, ws, in.q, in.v, in.tau, task);
    INFO("draw " << draws << " (" << toString(base.kind) << " base, " << model.nv() << " DOFs): " << s.message);
    REQUIRE(s);
    CHECK(ws.constraintCapacity() == 30);
    ++compared;
    floating += base.kind == BaseKind::Fixed ? 0 : 1;
    e_qdd = std::max(e_qdd, relativeError(ws.solution.qdd, dense.qdd));
    e_nu = std::max(e_nu, relativeError(ws.solution.nu, dense.nu.head(30)));
    e_tau_control = std::max(e_tau_control, relativeError(ws.solution.tau_control, dense.tau_control));
    // The same workspace solves with friction too, in the room it has now.
    Workspace ws_friction(model, 2);
    REQUIRE(solveWithFriction(model, ws_friction, in.q, in.v, in.tau, task));
    CHECK(ws_friction.constraintCapacity() == 30);
  }
  std::printf(
      "30 rows over 10 frames, default workspace: %d trees (%d draws, %d floating), max rel. error qdd %.2g, "
      "nu %.2g, tau_control %.2g\n",
      compared, draws, floating, e_qdd, e_nu, e_tau_control);
  CHECK(floating > 3);
  // Both sides solve the same KKT system exactly, kept draws conditioned below 1e6: round-off only.
  CHECK(e_qdd < 1e-9);
  CHECK(e_nu < 1e-9);
  CHECK(e_tau_control < 1e-9);
}

TEST_CASE("many rows: Workspace::reserve", "[many_rows]") {
  const Model panda = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf");
  const Model arm = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.urdf");
  Workspace ws(panda, 2);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(7, 0.3);
  REQUIRE(forwardKinematics(panda, ws, q));
  CHECK(ws.reserve(panda, 1));  // less than it has: nothing changes, the kinematics stay
  CHECK(ws.constraintCapacity() == 2);
  CHECK(ws.kinematics.stage == KinematicsStage::Poses);
  CHECK(ws.reserve(panda, 12));
  CHECK(ws.constraintCapacity() == 12);
  CHECK(ws.kinematics.stage == KinematicsStage::None);  // they lived in the scratch made anew
  const Status s = ws.reserve(arm, 20);
  CHECK(s.code == StatusCode::ModelMismatch);
  CHECK_THAT(s.message, Catch::Contains("Workspace::reserve") && Catch::Contains("7 joints"));
  CHECK(ws.constraintCapacity() == 12);
}
