// zwang_bench: cost per call of zwang's solvers, side by side with KDL and with
// the report's own way of finding the static friction torques (issue 5).
//
// Every benchmark is named  <family>/<model>,  <model> = "N=<dof>" for a random
// revolute chain, "panda", "N=<dof>,b=<branching>" for a tree or "dual_panda";
// counters N (dof), m (constraint rows), k (stuck joints). Families:
//   ours_hd_m{0,1,6}       zwang::solveHybridDynamics, m end-effector rows (world axes)
//   ours_hd_m6x2           6 rows on 2 frames: 3 linear on the last link, 3 angular on the middle link
//   ours_rnea, ours_crba   zwang::inverseDynamics, zwang::jointSpaceInertia
//   kdl_hd_m{0,1,6}        KDL::ChainHdSolver_Vereshchagin on the same chain (m = 0: one zero column)
//   kdl_rne                KDL::ChainIdSolver_RNE
//   fric_{as,pg,auto,sp}_{free,ee6}_k{0,1,2,half,all}
//                          zwang::solveWithFriction, active set / projected gradient / the automatic choice /
//                          the pattern search forced (FrictionMethod), no constraint / the 6-row end-effector
//                          task, k = 0, 1, 2, N/2, N stuck joints (q̇_j = 0; k = 2 is the grid method's case)
//   fric_warm_{free,ee6}_kall
//                          every joint stuck, the pattern kept from the call before (warm_start)
//   hd_traj/<model>, fric_warm_traj/<model>
//                          along a trajectory of a 1 kHz loop (makeTrajectory; <model> = panda, N=64,
//                          humanoid): the plain solve on each state, the friction solve warm-started from the
//                          state before; sim_{euler,rk4}/<model>: Simulation steps with the trajectory's torques
//                          (sim_per_wall: simulated seconds per wall second); worst_warm_traj/panda: 10⁶ of those calls, each timed, and the
//                          plain solve's on the same states between them (plain_*)
//   grid_{free,ee6}_k{1,2} the report's method: 21 friction values per stuck joint, one full
//                          solveHybridDynamics per grid point, keep the largest g(μ)
//   naivepg_{free,ee6}_k{1,2}
//                          projected gradient on g with one full solve per gradient (∇g = q̈_Θ(μ)),
//                          step 1/L (L estimated once from k unit-torque solves), stopped at the
//                          tolerance solveWithFriction uses; no ∂q̈/∂μ reuse
// Trees (issue 14):
//   tree_hd_m{0,6}/N=<n>,b=<b>
//                          zwang::solveHybridDynamics on the chain N=<n> with its joints re-hung as a
//                          complete b-ary tree (b = 2, 4; b = 1 is the chain itself, timed again here so
//                          that a filtered run compares within one run); m = 6: the 6 rows on the deepest
//                          leaf (world axes); extra counters b, depth (joints from the base to that
//                          leaf) and rank (of the balance: below 6 when the leaf has fewer than 6 joints)
//   ours_hd_{hands12,rel6}/dual_panda, fric_as_{hands12,rel6}_kall/dual_panda
//                          models/dual_panda.urdf (torso + 2 Panda arms, 15 joints) in a two-handed grasp
//                          pose: 12 rows (each hand, tool0, held still in world axes) or 6 rows (the left
//                          hand held to the right one: Task::addRelativeConstraint, the right hand's axes);
//                          plain (solveHybridDynamics) and with friction, all 15 joints stuck (q̇ = 0)
// Floating bases (issue 15):
//   floating_hd_{m0,m12}/<robot>, floating_fric_as_{m0,m12}_kall/<robot>
//                          <robot> = humanoid (models/simple_humanoid.urdf, 29 joints, free base, nv = 35)
//                          or solo12 (models/solo12.urdf, 12 joints, free base, nv = 18), standing at rest
//                          (q̇ = 0, τ = 0); m12: the feet held by contacts (Task::addContact, world axes):
//                          6 rows per humanoid foot, 3 linear rows per solo12 foot; m0: no rows (free
//                          fall). plain (solveHybridDynamics) and with friction, every joint stuck (breakaway
//                          friction raised to kStuckBreakaway so that all stay stuck; checked before timing)
//                          <robot> = chain_N=<n>: the fixed-base random chain of the chain benchmarks
//                          (randomChain, same seed) with n = nv or n = dof of a robot (35, 29, 18, 12), the
//                          same friction, at rest; m12: contacts holding the last link and the middle link
//                          (6 rows each, world axes); extra counters nv and bodies (moving bodies)
// Solvers, workspaces, tasks and KDL arrays are made outside the timed loops.
// Before anything is timed, main() checks that ours and KDL solve the same
// problems (q̈ and RNEA torques) and puts the largest differences into the
// benchmark context.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <urdf_parser/urdf_parser.h>
#include <kdl/chain.hpp>
#include <kdl/chainhdsolver_vereshchagin.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/frames.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>

#include "support/kdl_bridge.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"

namespace {

using namespace zwang;
using namespace zwang::testing;

// ---------------------------------------------------------------------------
// The robots and their states

struct Problem {
  std::string label;  // "N=7" or "panda"
  int n = 0;
  ChainSpec spec;                   // the same chain as a plain description, for KDL
  Model model;                      // ours
  Eigen::VectorXd q, qd, qdd, tau;  // every joint moving: 0.1 ≤ |q̇_j| ≤ 2
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};
  std::string tip, middle;  // link names: the last one, and one half way
  std::string tip2;         // dual arm: the other hand (the right one; tip is the left)
  int branching = 0;        // trees: children per body (1: the chain); 0: not a tree benchmark
  int depth = 0;            // trees: joints from the base to `tip`
  // floating benchmarks: the frames held by contacts, with their rows (6: the
  // whole acceleration, 3: the linear part), world axes
  std::vector<std::pair<std::string, int>> feet;
};

constexpr std::uint64_t kSeed = 0x2a5eedULL;  // fixed: the same chains in every run

std::unique_ptr<Problem> randomProblemOfSize(int n) {
  auto p = std::make_unique<Problem>();
  std::mt19937_64 rng(kSeed + static_cast<std::uint64_t>(n));
  RandomChainOptions options;
  options.min_moving_joints = options.max_moving_joints = n;
  options.fixed_joint_probability = 0.0;
  options.prismatic_probability = 0.0;
  options.continuous_probability = 0.0;  // revolute, with limits
  options.rotor_inertia = true;
  p->spec = randomChain(rng, options);
  p->label = "N=" + std::to_string(n);
  p->n = n;
  p->model = modelFromSpec(p->spec);
  p->q.resize(n);
  p->qd.resize(n);
  const std::vector<int> moving = p->spec.movingJoints();
  for (int j = 0; j < n; ++j) {
    const JointSpec& joint = p->spec.joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(j)])];
    const double margin = 0.05 * (joint.upper - joint.lower);  // well inside the limits
    p->q[j] = uniform(rng, joint.lower + margin, joint.upper - margin);
    p->qd[j] = (uniform01(rng) < 0.5 ? -1.0 : 1.0) * uniform(rng, 0.1, 2.0);
  }
  p->qdd = randomVector(rng, n, 2.0);
  p->tau = randomVector(rng, n, 10.0);
  p->tip = p->spec.links.back().name;
  p->middle = p->spec.links[static_cast<std::size_t>(std::max(1, n / 2))].name;
  return p;
}

// The chain of randomProblemOfSize(n) (the same links, joints and state) with
// its joints re-hung so that the bodies form a complete b-ary tree: in heap
// order body v's parent is ⌊(v − 1)/b⌋ (0: the base, which has b children),
// the branching-factor trees of Featherstone's benchmarks. The model needs
// depth-first order, so the heap is renumbered depth first: link i of the
// spec (and q_i) keeps its data, only its parent changes. `tip` is the last
// body in heap order, a leaf as deep as any. b = 1 returns the chain itself.
std::unique_ptr<Problem> treeProblemOfSize(int n, int branching) {
  auto p = randomProblemOfSize(n);
  p->label = "N=" + std::to_string(n) + ",b=" + std::to_string(branching);
  p->branching = branching;
  if (branching == 1) {
    p->depth = n;
    return p;
  }
  std::vector<int> order, stack{0};  // heap nodes (0 = the base) in depth-first order
  while (!stack.empty()) {
    const int v = stack.back();
    stack.pop_back();
    order.push_back(v);
    for (int c = std::min(branching * v + branching, n); c > branching * v; --c) stack.push_back(c);
  }
  std::vector<int> position(static_cast<std::size_t>(n) + 1), depth(static_cast<std::size_t>(n) + 1, 0);
  for (int i = 0; i <= n; ++i) position[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])] = i;
  for (int v = 1; v <= n; ++v)
    depth[static_cast<std::size_t>(v)] = depth[static_cast<std::size_t>((v - 1) / branching)] + 1;
  for (int i = 1; i <= n; ++i)
    p->spec.joints[static_cast<std::size_t>(i) - 1].parent =
        position[static_cast<std::size_t>((order[static_cast<std::size_t>(i)] - 1) / branching)];
  p->spec.name = "balanced_tree";
  p->spec.check();
  p->model = modelFromSpec(p->spec);
  if (p->model.isChain()) throw std::runtime_error(p->label + ": the tree came out a chain");
  p->tip = p->spec.links[static_cast<std::size_t>(position[static_cast<std::size_t>(n)])].name;
  p->middle.clear();  // no split task on trees
  p->depth = depth[static_cast<std::size_t>(n)];
  return p;
}

Eigen::Vector3d toEigen(const urdf::Vector3& v) { return Eigen::Vector3d(v.x, v.y, v.z); }
Eigen::Vector3d rpyOf(const urdf::Rotation& r) {
  double roll = 0, pitch = 0, yaw = 0;
  r.getRPY(roll, pitch, yaw);
  return Eigen::Vector3d(roll, pitch, yaw);
}

// The Panda's moving chain panda_link0 → panda_link7 as a ChainSpec (read with
// urdfdom, independently of zwang's loader), for KDL. The fixed, massless
// flange and tool0 frames behind panda_link7 change nothing in the dynamics.
ChainSpec specFromUrdf(const std::string& path, const std::string& root, const std::string& tip) {
  const urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDFFile(path);
  if (!urdf) throw std::runtime_error("cannot parse " + path);
  std::vector<urdf::JointConstSharedPtr> joints;
  for (urdf::LinkConstSharedPtr link = urdf->getLink(tip); link && link->name != root; link = link->getParent())
    joints.push_back(link->parent_joint);
  std::reverse(joints.begin(), joints.end());
  auto linkSpec = [&](const std::string& name) {
    LinkSpec l;
    l.name = name;
    const urdf::LinkConstSharedPtr link = urdf->getLink(name);
    if (link && link->inertial) {
      const urdf::Inertial& in = *link->inertial;
      l.mass = in.mass;
      l.com = toEigen(in.origin.position);
      l.inertial_rpy = rpyOf(in.origin.rotation);
      l.inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    }
    return l;
  };
  ChainSpec spec;
  spec.name = urdf->getName();
  spec.links.push_back(linkSpec(root));
  for (const urdf::JointConstSharedPtr& j : joints) {
    JointSpec js;
    js.name = j->name;
    js.type = j->type == urdf::Joint::PRISMATIC    ? "prismatic"
              : j->type == urdf::Joint::CONTINUOUS ? "continuous"
              : j->type == urdf::Joint::REVOLUTE   ? "revolute"
                                                   : "fixed";
    js.xyz = toEigen(j->parent_to_joint_origin_transform.position);
    js.rpy = rpyOf(j->parent_to_joint_origin_transform.rotation);
    js.axis = toEigen(j->axis);
    if (j->limits) {
      js.lower = j->limits->lower;
      js.upper = j->limits->upper;
      js.effort = j->limits->effort;
      js.velocity = j->limits->velocity;
    }
    if (j->dynamics) {
      js.friction = j->dynamics->friction;
      js.damping = j->dynamics->damping;
    }
    spec.joints.push_back(js);
    spec.links.push_back(linkSpec(j->child_link_name));
  }
  spec.check();
  return spec;
}

std::unique_ptr<Problem> pandaProblem() {
  const std::string path = std::string(ZWANG_BENCH_MODELS_DIR) + "/panda.urdf";
  auto p = std::make_unique<Problem>();
  p->label = "panda";
  p->model = loadUrdfFile(path);
  p->n = p->model.dof();
  p->spec = specFromUrdf(path, "panda_link0", "panda_link7");
  if (p->spec.dof() != p->n) throw std::runtime_error("panda: chain and model differ in dof");
  p->q.resize(p->n);
  p->q << 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785;  // the demo's "ready" pose
  p->qd.resize(p->n);
  for (int j = 0; j < p->n; ++j) p->qd[j] = j % 2 ? -0.5 : 0.5;
  p->qdd = Eigen::VectorXd::Constant(p->n, 0.3);
  p->tau = Eigen::VectorXd::Zero(p->n);  // motors off: friction and the task carry the arm
  p->tip = "panda_link7";
  p->middle = "panda_link3";
  return p;
}

// The dual arm holding a box 0.5 m in front of the torso: the hands (tool0) at
// (0.5, ±0.15, 0.35) m, pointing at each other — the grasp that
// `python3 models/make_dual_panda.py --check` solves for (rounded to 4 digits).
std::unique_ptr<Problem> dualPandaProblem() {
  const std::string path = std::string(ZWANG_BENCH_MODELS_DIR) + "/dual_panda.urdf";
  auto p = std::make_unique<Problem>();
  p->label = "dual_panda";
  p->model = loadUrdfFile(path);  // the whole tree (no tip)
  p->n = p->model.dof();
  if (p->n != 15 || p->model.isChain()) throw std::runtime_error("dual_panda: not a 15-joint tree");
  p->q.resize(p->n);
  p->q.setZero();
  const double left[7] = {-0.0597, 0.9013, 0.2395, -2.0689, -0.7983, 2.8788, -0.6992};
  const double right[7] = {-0.1724, 0.8639, -0.0690, -2.1175, 0.3159, 2.9720, 1.0418};
  p->q[p->model.jointIndex("torso_joint")] = 0.0;
  for (int j = 0; j < 7; ++j) {
    p->q[p->model.jointIndex("left_panda_joint" + std::to_string(j + 1))] = left[j];
    p->q[p->model.jointIndex("right_panda_joint" + std::to_string(j + 1))] = right[j];
  }
  p->qd.resize(p->n);
  for (int j = 0; j < p->n; ++j) p->qd[j] = j % 2 ? -0.5 : 0.5;
  p->qdd = Eigen::VectorXd::Constant(p->n, 0.3);
  p->tau = Eigen::VectorXd::Zero(p->n);  // motors off: friction and the task carry the arms
  p->tip = "left_tool0";
  p->tip2 = "right_tool0";
  return p;
}

// Where the dual arm's hands are in the benchmark's pose (world frame), for the context.
std::string dualPandaHands(const Problem& p) {
  Workspace ws(p.model, 0);
  if (!forwardKinematics(p.model, ws, p.q)) return "forward kinematics failed";
  std::string out;
  for (const std::string& hand : {p.tip, p.tip2}) {
    Eigen::Isometry3d pose;
    if (!framePose(p.model, ws, p.q, p.model.frameIndex(hand), pose)) return "framePose failed";
    char buffer[160];
    std::snprintf(buffer, sizeof buffer, "%s%s at (%.4f, %.4f, %.4f) m, z axis (%.3f, %.3f, %.3f)",
                  out.empty() ? "" : "; ", hand.c_str(), pose.translation().x(), pose.translation().y(),
                  pose.translation().z(), pose.linear()(0, 2), pose.linear()(1, 2), pose.linear()(2, 2));
    out += buffer;
  }
  return out;
}

// ---------------------------------------------------------------------------
// Floating bases and their fixed-base baselines

// Every joint's breakaway friction for the floating benchmarks' friction solves
// [N·m]: far above what gravity asks of any joint of these robots (the humanoid
// weighs about 100 kg on legs 0.65 m long: at most some 640 N·m), so that every
// stuck joint sticks and the maximiser works on all of them; main() checks it.
constexpr double kStuckBreakaway = 1e4;

Model withStuckFriction(const Model& model) {
  ModelBuilder builder(model);
  for (const Joint& j : model.joints())
    builder.setFriction(j.name, kStuckBreakaway, j.kinetic_friction, j.viscous_friction);
  return builder.build();
}

// Lifts a free base (identity orientation, at the origin in q) so that the
// lowest of the feet's frames is at z = 0; returns the feet's positions.
std::string standOnFeet(Problem& p) {
  Workspace ws(p.model, 0);
  if (!forwardKinematics(p.model, ws, p.q)) throw std::runtime_error(p.label + ": forward kinematics failed");
  std::vector<Eigen::Vector3d> feet;
  double lowest = std::numeric_limits<double>::infinity();
  for (const auto& foot : p.feet) {
    Eigen::Isometry3d pose;
    if (!framePose(p.model, ws, p.q, p.model.frameIndex(foot.first), pose))
      throw std::runtime_error(p.label + ": framePose failed");
    feet.push_back(pose.translation());
    lowest = std::min(lowest, pose.translation().z());
  }
  p.q[2] = -lowest;
  std::string out = p.label + ": base at z = " + std::to_string(p.q[2]).substr(0, 6) + " m, feet";
  for (std::size_t f = 0; f < feet.size(); ++f) {
    char buffer[96];
    std::snprintf(buffer, sizeof buffer, " %s (%.3f, %.3f, %.3f)", p.feet[f].first.c_str(), feet[f].x(), feet[f].y(),
                  feet[f].z() - lowest);
    out += buffer;
  }
  return out;
}

// The smallest distance of a joint from its limits in the problem's pose [rad].
double limitMargin(const Problem& p) {
  double margin = std::numeric_limits<double>::infinity();
  const int offset = p.model.baseConfigurationSize();
  for (int j = 0; j < p.model.dof(); ++j) {
    const Joint& joint = p.model.joint(j);
    margin = std::min({margin, p.q[offset + j] - joint.lower, joint.upper - p.q[offset + j]});
  }
  return margin;
}

// A free-base robot from models/, at rest (q̇ = 0, τ = 0), its base upright at
// the height that puts its feet on the ground.
std::unique_ptr<Problem> floatingRobotProblem(const std::string& label, const std::string& file,
                                              const std::vector<std::pair<std::string, double>>& pose,
                                              const std::vector<std::pair<std::string, int>>& feet,
                                              std::string* description) {
  UrdfOptions options;
  options.base = BaseType::Free;
  auto p = std::make_unique<Problem>();
  p->label = label;
  p->model = withStuckFriction(loadUrdfFile(std::string(ZWANG_BENCH_MODELS_DIR) + "/" + file, options));
  p->n = p->model.dof();
  p->q = Eigen::VectorXd::Zero(p->model.nq());
  p->q[3] = 1.0;  // quaternion w: upright
  for (const auto& [joint, value] : pose) p->q[7 + p->model.jointIndex(joint)] = value;
  p->qd = Eigen::VectorXd::Zero(p->model.nv());
  p->tau = Eigen::VectorXd::Zero(p->model.nv());  // motors off: friction and the contacts carry the robot
  p->feet = feet;
  *description = standOnFeet(*p);
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, ", every joint at least %.3f rad inside its limits", limitMargin(*p));
  *description += buffer;
  if (!(limitMargin(*p) > 0.01)) throw std::runtime_error(label + ": a joint is at or beyond a limit");
  return p;
}

// models/simple_humanoid.urdf standing on both feet, knees slightly bent (hip
// pitch + knee + ankle pitch = 0 keeps the soles level). The file has no sole
// links: the ankle links (r_ankle, l_ankle) are the feet. Its limits are not
// mirrored left to right (the knees' ranges are [0, 2.618] and [−2.095, 0.7]),
// hence the values: one posture inside both sides' ranges.
std::unique_ptr<Problem> humanoidProblem(std::string* description) {
  std::vector<std::pair<std::string, double>> pose;
  for (const char* side : {"RLEG_", "LLEG_"})
    for (const auto& [joint, value] : {std::pair{"HIP_P", -0.3}, std::pair{"KNEE", 0.25}, std::pair{"ANKLE_P", 0.05}})
      pose.emplace_back(std::string(side) + joint, value);
  for (const char* side : {"RARM_", "LARM_"})
    for (const auto& [joint, value] :
         {std::pair{"SHOULDER_R", 0.1}, std::pair{"ELBOW", -0.3}, std::pair{"WRIST_Y", -0.1}})
      pose.emplace_back(std::string(side) + joint, value);
  auto p =
      floatingRobotProblem("humanoid", "simple_humanoid.urdf", pose, {{"r_ankle", 6}, {"l_ankle", 6}}, description);
  if (p->n != 29) throw std::runtime_error("humanoid: not 29 joints");
  return p;
}

// models/solo12.urdf standing on its four point feet (the crouch
// test/python/test_floating.py uses: knees 1.6 rad, front and hind legs mirrored).
std::unique_ptr<Problem> solo12Problem(std::string* description) {
  std::vector<std::pair<std::string, double>> pose;
  for (const char* leg : {"FL_", "FR_"}) {
    pose.emplace_back(std::string(leg) + "HFE", 0.8);
    pose.emplace_back(std::string(leg) + "KFE", -1.6);
  }
  for (const char* leg : {"HL_", "HR_"}) {
    pose.emplace_back(std::string(leg) + "HFE", -0.8);
    pose.emplace_back(std::string(leg) + "KFE", 1.6);
  }
  auto p = floatingRobotProblem("solo12", "solo12.urdf", pose,
                                {{"FL_FOOT", 3}, {"FR_FOOT", 3}, {"HL_FOOT", 3}, {"HR_FOOT", 3}}, description);
  if (p->n != 12) throw std::runtime_error("solo12: not 12 joints");
  return p;
}

// The fixed-base baseline: the random chain of the chain benchmarks (same
// seed, same pose) at rest, with the robots' friction; m12 holds its last
// and its middle link (6 rows each).
std::unique_ptr<Problem> floatingBaselineChain(int n) {
  auto p = randomProblemOfSize(n);
  p->label = "chain_N=" + std::to_string(n);
  p->model = withStuckFriction(p->model);
  p->qd.setZero();
  p->tau.setZero();
  p->feet = {{p->tip, 6}, {p->middle, 6}};
  return p;
}

// ---------------------------------------------------------------------------
// Tasks (as DynamicsInput, so the same problem goes to ours and to KDL)

enum class TaskKind { None, Ee1, Ee6, Split6, Hands12, Relative6 };

DynamicsInput makeInput(const Problem& p, TaskKind kind, const Eigen::VectorXd& qd) {
  DynamicsInput in;
  in.q = p.q;
  in.qd = qd;
  in.tau = p.tau;
  in.gravity = p.gravity;
  auto constraint = [](const std::string& link, Matrix6Xd A) {
    ConstraintInput c;
    c.link = link;
    c.b = Eigen::VectorXd::Zero(A.cols());  // hold still
    c.A = std::move(A);
    c.axes = Axes::World;
    return c;
  };
  switch (kind) {
    case TaskKind::None: break;
    case TaskKind::Ee1: {  // one unit force along world z on the end effector
      Matrix6Xd A = Matrix6Xd::Zero(6, 1);
      A(2, 0) = 1.0;
      in.constraints.push_back(constraint(p.tip, A));
      break;
    }
    case TaskKind::Ee6: in.constraints.push_back(constraint(p.tip, Matrix6Xd::Identity(6, 6))); break;
    case TaskKind::Split6:
      in.constraints.push_back(constraint(p.tip, Matrix6Xd::Identity(6, 6).leftCols(3)));      // position
      in.constraints.push_back(constraint(p.middle, Matrix6Xd::Identity(6, 6).rightCols(3)));  // orientation
      break;
    case TaskKind::Hands12:  // both hands held still
      in.constraints.push_back(constraint(p.tip, Matrix6Xd::Identity(6, 6)));
      in.constraints.push_back(constraint(p.tip2, Matrix6Xd::Identity(6, 6)));
      break;
    case TaskKind::Relative6: {  // the hands held together (a rigid box between them)
      ConstraintInput c = constraint(p.tip, Matrix6Xd::Identity(6, 6));
      c.relative_to = p.tip2;
      c.axes = Axes::Reference;
      in.constraints.push_back(std::move(c));
      break;
    }
  }
  return in;
}

int rowsOf(TaskKind kind) {
  return kind == TaskKind::None ? 0 : kind == TaskKind::Ee1 ? 1 : kind == TaskKind::Hands12 ? 12 : 6;
}

// k stuck joints spread evenly along the chain (k = N: all of them).
std::vector<int> stuckSet(int n, int k) {
  std::vector<int> s;
  for (int i = 0; i < k; ++i) s.push_back((2 * i + 1) * n / (2 * k));
  return s;
}

Eigen::VectorXd stuckVelocities(const Problem& p, const std::vector<int>& stuck) {
  Eigen::VectorXd qd = p.qd;
  for (int j : stuck) qd[j] = 0.0;
  return qd;
}

void setCounters(benchmark::State& state, const Problem& p, int m, int k) {
  state.counters["N"] = p.n;
  state.counters["m"] = m;
  state.counters["k"] = k;
}

// The timed benchmarks below first solve once outside the clock: a failed solve
// skips the benchmark with its message (a number for a wrong problem is worse
// than none), and the first call warms the workspace.
bool firstSolveSucceeded(benchmark::State& state, const Status& first) {
  if (!first) state.SkipWithError(first.message);
  return static_cast<bool>(first);
}

void timeHybridSolves(benchmark::State& state, const Problem& p, const Task& task, const Eigen::VectorXd& qd,
                      Workspace& ws) {
  for (auto _ : state) {
    const Status s = solveHybridDynamics(p.model, ws, p.q, qd, p.tau, task);
    benchmark::DoNotOptimize(s.code);
    benchmark::DoNotOptimize(ws.solution.qdd.data());
    benchmark::ClobberMemory();
  }
}

void timeFrictionSolves(benchmark::State& state, const Problem& p, const Task& task, const Eigen::VectorXd& qd,
                        const FrictionOptions& options, Workspace& ws) {
  for (auto _ : state) {
    const Status s = solveWithFriction(p.model, ws, p.q, qd, p.tau, task, options);
    benchmark::DoNotOptimize(s.code);
    benchmark::DoNotOptimize(ws.solution.qdd.data());
    benchmark::ClobberMemory();
  }
}

// ---------------------------------------------------------------------------
// Ours

void benchOursHybrid(benchmark::State& state, const Problem* p, TaskKind kind) {
  const DynamicsInput in = makeInput(*p, kind, p->qd);
  const Task task = taskFromInput(p->model, in);
  Workspace ws(p->model, task);
  if (!firstSolveSucceeded(state, solveHybridDynamics(p->model, ws, p->q, p->qd, p->tau, task))) return;
  timeHybridSolves(state, *p, task, p->qd, ws);
  setCounters(state, *p, task.constraintRows(), 0);
}

// Every other joint prescribed at the plain solve's q̈ (the same motion), or the same as joint rows (as_rows):
// what a prescribed joint costs against the plain solve and against a row.
void benchHalfPrescribed(benchmark::State& state, const Problem* p, TaskKind kind, bool as_rows) {
  Task task = taskFromInput(p->model, makeInput(*p, kind, p->qd));
  Workspace plain(p->model, task);
  if (!firstSolveSucceeded(state, solveHybridDynamics(p->model, plain, p->q, p->qd, p->tau, task))) return;
  for (int j = 1; j < p->n; j += 2) {
    if (as_rows) {
      task.targets()[task.addJointConstraint(j)] = plain.solution.qdd[j];
    } else {
      task.prescribe(j);
      task.prescribedAccelerations()[j] = plain.solution.qdd[j];
    }
  }
  Workspace ws(p->model, task);
  if (!firstSolveSucceeded(state, solveHybridDynamics(p->model, ws, p->q, p->qd, p->tau, task))) return;
  timeHybridSolves(state, *p, task, p->qd, ws);
  setCounters(state, *p, task.constraintRows(), 0);
  state.counters["prescribed"] = task.prescribedCount();
}

// The same on a tree (or its chain, b = 1), with the tree's counters.
void benchTreeHybrid(benchmark::State& state, const Problem* p, TaskKind kind) {
  const Task task = taskFromInput(p->model, makeInput(*p, kind, p->qd));
  Workspace ws(p->model, task);
  if (!firstSolveSucceeded(state, solveHybridDynamics(p->model, ws, p->q, p->qd, p->tau, task))) return;
  const int rank = ws.solution.balance.rank;
  timeHybridSolves(state, *p, task, p->qd, ws);
  setCounters(state, *p, task.constraintRows(), 0);
  state.counters["b"] = p->branching;
  state.counters["depth"] = p->depth;
  state.counters["rank"] = rank;
}

// Many rows (docs/solver.md "Many rows"): a comb, 10 branches of 6 joints from the base (randomProblemOfSize(60)'s
// joints re-hung), with `rows` spread evenly over the 10 tips (each tip's first rows/10 axes, world axes, held
// still): every row independent. Solved in a workspace made with the default room; the first solve, outside the
// clock, makes room.
constexpr int kCombBranches = 10, kCombLength = 6;

std::unique_ptr<Problem> combProblem() {
  auto p = randomProblemOfSize(kCombBranches * kCombLength);
  p->label = "comb10x6";
  for (int j = 0; j < p->n; ++j)  // a branch's first joint hangs from the base, the others from the joint before
    p->spec.joints[static_cast<std::size_t>(j)].parent = j % kCombLength == 0 ? 0 : j;
  p->spec.name = "comb";
  p->spec.check();
  p->model = modelFromSpec(p->spec);
  return p;
}

void benchCombRows(benchmark::State& state, const Problem* p, int rows) {
  Task task(p->model);
  for (int b = 0; b < kCombBranches && rows > 0; ++b) {
    const auto tip = static_cast<std::size_t>((b + 1) * kCombLength);
    task.addConstraint(p->spec.links[tip].name, ConstraintMatrix::Identity(6, rows / kCombBranches), Expressed::World);
  }
  Workspace ws(p->model);
  if (!firstSolveSucceeded(state, solveHybridDynamics(p->model, ws, p->q, p->qd, p->tau, task))) return;
  const int rank = ws.solution.balance.rank;
  const bool singular = ws.solution.balance.singular;  // the eigendecomposition path (docs/solver.md)
  timeHybridSolves(state, *p, task, p->qd, ws);
  setCounters(state, *p, task.constraintRows(), 0);
  state.counters["rank"] = rank;
  state.counters["singular"] = singular;
}

void benchOursRnea(benchmark::State& state, const Problem* p) {
  const Task task(p->model);  // gravity (0, 0, −9.81), no wrenches
  Workspace ws(p->model, task);
  for (auto _ : state) {
    const Status s = inverseDynamics(p->model, ws, p->q, p->qd, p->qdd, task);
    benchmark::DoNotOptimize(s.code);
    benchmark::DoNotOptimize(ws.tau.data());
    benchmark::ClobberMemory();
  }
  setCounters(state, *p, 0, 0);
}

void benchOursCrba(benchmark::State& state, const Problem* p) {
  Workspace ws(p->model, 0);
  for (auto _ : state) {
    const Status s = jointSpaceInertia(p->model, ws, p->q);
    benchmark::DoNotOptimize(s.code);
    benchmark::DoNotOptimize(ws.H.data());
    benchmark::ClobberMemory();
  }
  setCounters(state, *p, 0, 0);
}

// ---------------------------------------------------------------------------
// KDL

KDL::JntArray jnt(const Eigen::VectorXd& x) {
  KDL::JntArray a(static_cast<unsigned int>(x.size()));
  a.data = x;
  return a;
}

void benchKdlHybrid(benchmark::State& state, const Problem* p, TaskKind kind) {
  const DynamicsInput in = makeInput(*p, kind, p->qd);
  // The bridge converts our problem to KDL's inputs (alpha, beta, root
  // acceleration, f_ext) once; only CartToJnt is timed.
  const KdlHybridResult ref = kdlHybridDynamics(p->spec, in);
  const KDL::Chain chain = toKdlChain(p->spec);
  const auto nc = static_cast<unsigned int>(ref.alpha.cols());
  const KDL::Twist root_acc(KDL::Vector(ref.root_acc[0], ref.root_acc[1], ref.root_acc[2]),
                            KDL::Vector(ref.root_acc[3], ref.root_acc[4], ref.root_acc[5]));
  KDL::ChainHdSolver_Vereshchagin solver(chain, root_acc, nc);
  const KDL::JntArray q = jnt(p->q), qd = jnt(p->qd), tau = jnt(p->tau), beta = jnt(ref.beta);
  KDL::JntArray qdd(static_cast<unsigned int>(p->n)), constraint_tau(static_cast<unsigned int>(p->n));
  KDL::Jacobian alpha(nc);
  alpha.data = ref.alpha;
  const KDL::Wrenches f_ext(chain.getNrOfSegments(), KDL::Wrench::Zero());
  for (auto _ : state) {
    const int error = solver.CartToJnt(q, qd, qdd, alpha, beta, f_ext, tau, constraint_tau);
    benchmark::DoNotOptimize(error);
    benchmark::DoNotOptimize(qdd.data.data());
    benchmark::ClobberMemory();
  }
  setCounters(state, *p, rowsOf(kind), 0);
}

void benchKdlRne(benchmark::State& state, const Problem* p) {
  const KDL::Chain chain = toKdlChain(p->spec);
  KDL::ChainIdSolver_RNE solver(chain, KDL::Vector(p->gravity.x(), p->gravity.y(), p->gravity.z()));
  const KDL::JntArray q = jnt(p->q), qd = jnt(p->qd), qdd = jnt(p->qdd);
  KDL::JntArray tau(static_cast<unsigned int>(p->n));
  const KDL::Wrenches f_ext(chain.getNrOfSegments(), KDL::Wrench::Zero());
  for (auto _ : state) {
    const int error = solver.CartToJnt(q, qd, qdd, f_ext, tau);
    benchmark::DoNotOptimize(error);
    benchmark::DoNotOptimize(tau.data.data());
    benchmark::ClobberMemory();
  }
  setCounters(state, *p, 0, 0);
}

// ---------------------------------------------------------------------------
// Static friction: ours

void benchFriction(benchmark::State& state, const Problem* p, TaskKind kind, int k, FrictionMethod method,
                   bool warm_start = false) {
  const std::vector<int> stuck = stuckSet(p->n, k);
  const Eigen::VectorXd qd = stuckVelocities(*p, stuck);
  const Task task = taskFromInput(p->model, makeInput(*p, kind, qd));
  Workspace ws(p->model, task);
  FrictionOptions options;
  options.method = method;
  options.warm_start = warm_start;  // the first solve below keeps the pattern the timed ones start from
  if (!firstSolveSucceeded(state, solveWithFriction(p->model, ws, p->q, qd, p->tau, task, options))) return;
  if (static_cast<int>(ws.friction.stuck.size()) != k) {
    state.SkipWithError("stuck set has the wrong size");
    return;
  }
  timeFrictionSolves(state, *p, task, qd, options, ws);
  setCounters(state, *p, task.constraintRows(), k);
  state.counters["iterations"] = ws.friction.iterations;
  state.counters["warm"] = ws.friction.warm_started;
}

// ---------------------------------------------------------------------------
// Worst case, not median: 10⁶ timed friction solves (issue 6, real-time
// guarantees). Each call is timed on its own with steady_clock (its overhead,
// some 20 ns, is included); counters give the maximum and the tail.

void setQuantileCounters(benchmark::State& state, std::vector<double>& ns, const std::string& prefix = "") {
  std::sort(ns.begin(), ns.end());
  auto quantile = [&](double q) { return ns[std::min(ns.size() - 1, static_cast<std::size_t>(q * ns.size()))]; };
  state.counters[prefix + "calls"] = static_cast<double>(ns.size());
  state.counters[prefix + "median_ns"] = quantile(0.5);
  state.counters[prefix + "p99_ns"] = quantile(0.99);
  state.counters[prefix + "p99.99_ns"] = quantile(0.9999);
  state.counters[prefix + "max_ns"] = ns.back();
}

void benchWorstCase(benchmark::State& state, const Problem* p, TaskKind kind, int calls) {
  const std::vector<int> stuck = stuckSet(p->n, p->n);
  const Eigen::VectorXd qd = stuckVelocities(*p, stuck);
  const Task task = taskFromInput(p->model, makeInput(*p, kind, qd));
  Workspace ws(p->model, task);
  FrictionOptions options;
  options.method = FrictionMethod::ActiveSet;
  std::vector<double> ns(static_cast<std::size_t>(calls));
  for (auto _ : state) {
    for (int c = 0; c < calls; ++c) {
      const auto t0 = std::chrono::steady_clock::now();
      const Status s = solveWithFriction(p->model, ws, p->q, qd, p->tau, task, options);
      const auto t1 = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(s.code);
      benchmark::DoNotOptimize(ws.solution.qdd.data());
      ns[static_cast<std::size_t>(c)] = std::chrono::duration<double, std::nano>(t1 - t0).count();
    }
  }
  setCounters(state, *p, task.constraintRows(), p->n);
  setQuantileCounters(state, ns);
}

// ---------------------------------------------------------------------------
// Floating bases: the robots and their fixed-base chains, plain and with every
// joint stuck.

Task floatingTask(const Problem& p, bool held) {
  Task task(p.model);
  task.gravity = p.gravity;
  if (held)
    for (const auto& [frame, rows] : p.feet)
      task.addContact(frame, ConstraintMatrix::Identity(6, 6).leftCols(rows), Expressed::World);
  return task;
}

void setFloatingCounters(benchmark::State& state, const Problem& p, int m, int k) {
  setCounters(state, p, m, k);
  state.counters["nv"] = p.model.nv();
  state.counters["bodies"] = p.model.hasFloatingBase() ? p.model.bodyCount() : p.model.dof();  // moving ones
}

void benchFloatingHybrid(benchmark::State& state, const Problem* p, bool held) {
  const Task task = floatingTask(*p, held);
  Workspace ws(p->model, task);
  if (!firstSolveSucceeded(state, solveHybridDynamics(p->model, ws, p->q, p->qd, p->tau, task))) return;
  const int rank = ws.solution.balance.rank;
  timeHybridSolves(state, *p, task, p->qd, ws);
  setFloatingCounters(state, *p, task.constraintRows(), 0);
  state.counters["rank"] = rank;
}

void benchFloatingFriction(benchmark::State& state, const Problem* p, bool held, FrictionMethod method) {
  const Task task = floatingTask(*p, held);
  Workspace ws(p->model, task);
  FrictionOptions options;
  options.method = method;
  if (!firstSolveSucceeded(state, solveWithFriction(p->model, ws, p->q, p->qd, p->tau, task, options))) return;
  // Every joint stuck (q̇ = 0) and staying stuck: what the benchmark is about.
  if (static_cast<int>(ws.friction.stuck.size()) != p->n ||
      std::any_of(ws.friction.state.begin(), ws.friction.state.end(),
                  [](JointState js) { return js != JointState::Stick; })) {
    state.SkipWithError("not every joint sticks");
    return;
  }
  timeFrictionSolves(state, *p, task, p->qd, options, ws);
  setFloatingCounters(state, *p, task.constraintRows(), p->n);
  state.counters["iterations"] = ws.friction.iterations;
  state.counters["indeterminate"] = ws.friction.indeterminate ? 1 : 0;
}

// ---------------------------------------------------------------------------
// Along a trajectory (#28): the states a 1 kHz control loop visits, simulated once with the friction solve
// (semi-implicit Euler; a joint whose velocity crosses zero stops there, as an event would put it), then replayed
// state by state. The fixed-base arms hold their starting pose with gravity compensation while sinusoidal torques of
// 1.3 boxes at 0.3–1 Hz make joints break away and stop again: the pattern changes now and then. The humanoid
// stands on both feet, its motors adding 20 N·m swings to the load friction holds (every joint sticks).

struct Trajectory {
  explicit Trajectory(const Problem& p) : task(floatingTask(p, !p.feet.empty())) {}
  Task task;
  FrictionOptions options;  // the loop's friction: the automatic method, warm-started
  std::vector<Eigen::VectorXd> q, qd, tau;
  int stuck_changes = 0, pattern_changes = 0;
};

constexpr int kTrajectorySteps = 2000;  // 2 s at 1 kHz

std::unique_ptr<Trajectory> makeTrajectory(const Problem& p) {
  auto t = std::make_unique<Trajectory>(p);
  const Model& model = p.model;
  const int n = model.dof(), base_velocity_size = model.baseVelocitySize();
  const double h = 1e-3;
  Workspace ws(model, t->task);
  Eigen::VectorXd hold = Eigen::VectorXd::Zero(model.nv()), amplitude = hold, omega = hold, phase = hold;
  t->options.warm_start = true;
  t->options.joint_limits = false;  // the arms drift a little: a limit is not what this measures
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> frequency(0.3, 1.0), angle(0.0, 2.0 * M_PI);
  if (p.feet.empty()) {  // hold the pose with gravity compensation; friction a fifth of that load plus 1 N·m
    if (!inverseDynamics(model, ws, p.q, Eigen::VectorXd::Zero(model.nv()), Eigen::VectorXd::Zero(model.nv()), t->task))
      throw std::runtime_error(p.label + ": inverse dynamics failed");
    hold = ws.solution.tau_control;
    t->options.breakaway = 0.2 * hold.tail(n).cwiseAbs().array() + 1.0;
    t->options.kinetic = 0.8 * t->options.breakaway;
    t->options.viscous = Eigen::VectorXd::Constant(n, 0.1);
    for (int k = 0; k < n; ++k) amplitude[base_velocity_size + k] = 1.3 * t->options.breakaway[k];
  } else {
    hold = p.tau;
    amplitude.tail(n).setConstant(20.0);
  }
  for (int k = base_velocity_size; k < model.nv(); ++k) {
    omega[k] = 2.0 * M_PI * frequency(rng);
    phase[k] = angle(rng);
  }
  Eigen::VectorXd q = p.q, qd = Eigen::VectorXd::Zero(model.nv());
  std::vector<int> last_stuck;
  std::vector<JointState> last_state;
  for (int step = 0; step < kTrajectorySteps; ++step) {
    const Eigen::VectorXd tau = hold + amplitude.cwiseProduct((omega * (step * h) + phase).array().sin().matrix());
    t->q.push_back(q);
    t->qd.push_back(qd);
    t->tau.push_back(tau);
    const Status s = solveWithFriction(model, ws, q, qd, tau, t->task, t->options);
    if (!s) throw std::runtime_error(p.label + " trajectory: " + s.message);
    if (step > 0) {
      t->stuck_changes += ws.friction.stuck != last_stuck ? 1 : 0;
      t->pattern_changes += ws.friction.stuck == last_stuck && ws.friction.state != last_state ? 1 : 0;
    }
    last_stuck = ws.friction.stuck;
    last_state = ws.friction.state;
    const Eigen::VectorXd qd_before = qd;
    qd += h * ws.solution.qdd;
    for (int k = base_velocity_size; k < model.nv(); ++k)
      if (qd_before[k] * qd[k] < 0.0) qd[k] = 0.0;
    if (!integrate(model, q, qd, h, q)) throw std::runtime_error(p.label + " trajectory: integrate failed");
  }
  return t;
}

void setTrajectoryCounters(benchmark::State& state, const Problem& p, const Trajectory& t) {
  state.counters["N"] = p.n;
  state.counters["m"] = t.task.constraintRows();
  state.counters["steps"] = kTrajectorySteps;
  state.counters["stuck_changes"] = t.stuck_changes;
  state.counters["pattern_changes"] = t.pattern_changes;
}

void benchTrajectoryHybrid(benchmark::State& state, const Problem* p, const Trajectory* t) {
  Workspace ws(p->model, t->task);
  std::size_t i = 0;
  for (auto _ : state) {
    const Status s = solveHybridDynamics(p->model, ws, t->q[i], t->qd[i], t->tau[i], t->task);
    benchmark::DoNotOptimize(s.code);
    benchmark::DoNotOptimize(ws.solution.qdd.data());
    benchmark::ClobberMemory();
    i = i + 1 == t->q.size() ? 0 : i + 1;
  }
  setTrajectoryCounters(state, *p, *t);
}

// One pass over the trajectory first: how many of its calls the warm start answers.
double warmShare(const Problem& p, const Trajectory& t, Workspace& ws) {
  int warm = 0;
  for (std::size_t i = 0; i < t.q.size(); ++i) {
    if (!solveWithFriction(p.model, ws, t.q[i], t.qd[i], t.tau[i], t.task, t.options)) return -1.0;
    warm += ws.friction.warm_started ? 1 : 0;
  }
  return static_cast<double>(warm) / static_cast<double>(t.q.size());
}

void benchTrajectoryFriction(benchmark::State& state, const Problem* p, const Trajectory* t) {
  Workspace ws(p->model, t->task);
  const double warm = warmShare(*p, *t, ws);
  std::size_t i = 0;
  for (auto _ : state) {
    const Status s = solveWithFriction(p->model, ws, t->q[i], t->qd[i], t->tau[i], t->task, t->options);
    benchmark::DoNotOptimize(s.code);
    benchmark::DoNotOptimize(ws.solution.qdd.data());
    benchmark::ClobberMemory();
    i = i + 1 == t->q.size() ? 0 : i + 1;
  }
  setTrajectoryCounters(state, *p, *t);
  state.counters["warm_share"] = warm;
}

// Simulation (issue #29): the trajectory's torques held over 1 ms steps from its first state, events located, the
// friction warm-started; one step per iteration (a reset every kTrajectorySteps). sim_per_wall: simulated seconds
// per wall second.
void benchSimulation(benchmark::State& state, const Problem* p, const Trajectory* t, Integrator integrator) {
  SimulationOptions options;
  options.integrator = integrator;
  options.friction = t->options;
  Simulation sim(p->model, t->task, options);
  if (!firstSolveSucceeded(state, sim.reset(t->q[0], t->qd[0]))) return;
  std::size_t k = 0;
  long events = 0, runs = 0;
  for (auto _ : state) {
    const Status s = sim.step(t->tau[k]);
    if (!s) {
      state.SkipWithError(s.message);
      return;
    }
    if (++k == t->tau.size()) {
      events += static_cast<long>(sim.events().size());
      ++runs;
      state.PauseTiming();
      k = 0;
      if (!sim.reset(t->q[0], t->qd[0])) state.SkipWithError("reset failed");
      state.ResumeTiming();
    }
  }
  setTrajectoryCounters(state, *p, *t);
  state.counters["sim_per_wall"] = benchmark::Counter(1e-3, benchmark::Counter::kIsIterationInvariantRate);
  // Over the whole runs (2 s each); the events of the one cut short when timing stopped left out.
  state.counters["events_per_run"] = runs > 0 ? static_cast<double>(events) / static_cast<double>(runs) : -1.0;
}

// The friction solve's tail and, interleaved call by call on the same states, the plain solve's (plain_*): what
// the machine adds to any call (interrupts, migrations) shows in both.
void benchTrajectoryWorstCase(benchmark::State& state, const Problem* p, const Trajectory* t, int calls) {
  Workspace ws(p->model, t->task), ws_plain(p->model, t->task);
  const double warm = warmShare(*p, *t, ws);
  std::vector<double> ns(static_cast<std::size_t>(calls)), ns_plain(static_cast<std::size_t>(calls));
  for (auto _ : state) {
    std::size_t i = 0;
    for (int c = 0; c < calls; ++c) {
      const auto t0 = std::chrono::steady_clock::now();
      const Status s = solveWithFriction(p->model, ws, t->q[i], t->qd[i], t->tau[i], t->task, t->options);
      const auto t1 = std::chrono::steady_clock::now();
      const Status s_plain = solveHybridDynamics(p->model, ws_plain, t->q[i], t->qd[i], t->tau[i], t->task);
      const auto t2 = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(s.code);
      benchmark::DoNotOptimize(s_plain.code);
      benchmark::DoNotOptimize(ws.solution.qdd.data());
      benchmark::DoNotOptimize(ws_plain.solution.qdd.data());
      ns[static_cast<std::size_t>(c)] = std::chrono::duration<double, std::nano>(t1 - t0).count();
      ns_plain[static_cast<std::size_t>(c)] = std::chrono::duration<double, std::nano>(t2 - t1).count();
      i = i + 1 == t->q.size() ? 0 : i + 1;
    }
  }
  setTrajectoryCounters(state, *p, *t);
  state.counters["warm_share"] = warm;
  // Each state's fastest call over the passes (the machine's interruptions removed; the warm start sees the same
  // state before it every pass): their median and slowest are the solver's own on this trajectory.
  const std::size_t states = t->q.size();
  auto perState = [&](const std::vector<double>& times, const std::string& prefix) {
    std::vector<double> fastest(states, std::numeric_limits<double>::infinity());
    for (std::size_t c = 0; c < times.size(); ++c) fastest[c % states] = std::min(fastest[c % states], times[c]);
    std::sort(fastest.begin(), fastest.end());
    state.counters[prefix + "state_median_ns"] = fastest[states / 2];
    state.counters[prefix + "state_max_ns"] = fastest.back();
  };
  perState(ns, "");
  perState(ns_plain, "plain_");
  setQuantileCounters(state, ns);
  setQuantileCounters(state, ns_plain, "plain_");
}

// ---------------------------------------------------------------------------
// Static friction: the report's method and a naive gradient method, both
// calling the full solver (solveHybridDynamics) for every evaluation of g.
//
// With the joint torques τ_eff − Wᵀμ passed in, Solution::gauss is
// Z₀(q̈) + μᵀ W q̈ at the solution, i.e. exactly g(μ) (docs/friction.md), and
// ∇g(μ) = W q̈(μ).

struct FrictionSetupOurs {
  std::vector<int> stuck;
  Eigen::VectorXd qd, tau_eff, f;  // τ plus kinetic friction on the moving joints; f per stuck joint
};

FrictionSetupOurs frictionSetup(const Problem& p, int k) {
  FrictionSetupOurs s;
  s.stuck = stuckSet(p.n, k);
  s.qd = stuckVelocities(p, s.stuck);
  s.tau_eff = p.tau;
  for (int j = 0; j < p.n; ++j) {
    const Joint& joint = p.model.joint(j);
    if (s.qd[j] != 0.0)
      s.tau_eff[j] += -joint.kinetic_friction * (s.qd[j] > 0 ? 1.0 : -1.0) - joint.viscous_friction * s.qd[j];
  }
  s.f.resize(k);
  for (int a = 0; a < k; ++a) s.f[a] = p.model.joint(s.stuck[static_cast<std::size_t>(a)]).breakaway_friction;
  return s;
}

// g(μ*) by our solver, for the accuracy counters of the comparison methods.
double exactDual(const Problem& p, const Task& task, const FrictionSetupOurs& s, Eigen::VectorXd* mu_star) {
  Workspace ws(p.model, task);
  FrictionOptions options;
  options.joint_limits = false;
  if (Status st = solveWithFriction(p.model, ws, p.q, s.qd, p.tau, task, options); !st) return std::nan("");
  mu_star->resize(static_cast<Eigen::Index>(s.stuck.size()));
  for (std::size_t a = 0; a < s.stuck.size(); ++a)
    (*mu_star)[static_cast<Eigen::Index>(a)] = ws.friction.mu[s.stuck[a]];
  return ws.friction.gauss_dual;
}

constexpr int kGridPoints = 21;

void benchGrid(benchmark::State& state, const Problem* p, TaskKind kind, int k) {
  const FrictionSetupOurs s = frictionSetup(*p, k);
  const Task task = taskFromInput(p->model, makeInput(*p, kind, s.qd));
  Workspace ws(p->model, task);
  Eigen::VectorXd torque(p->n), mu(k), best_mu(k), best_qdd(p->n);
  int evaluations = 1;
  for (int a = 0; a < k; ++a) evaluations *= kGridPoints;
  double best = -std::numeric_limits<double>::infinity();
  for (auto _ : state) {
    best = -std::numeric_limits<double>::infinity();
    for (int e = 0; e < evaluations; ++e) {
      torque = s.tau_eff;
      for (int a = 0, rest = e; a < k; ++a, rest /= kGridPoints) {
        mu[a] = s.f[a] * (-1.0 + 2.0 * (rest % kGridPoints) / (kGridPoints - 1));
        torque[s.stuck[static_cast<std::size_t>(a)]] -= mu[a];
      }
      const Status st = solveHybridDynamics(p->model, ws, p->q, s.qd, torque, task);
      benchmark::DoNotOptimize(st.code);
      if (ws.solution.gauss > best) {
        best = ws.solution.gauss;
        best_mu = mu;
        best_qdd = ws.solution.qdd;
      }
    }
    benchmark::DoNotOptimize(best);
    benchmark::DoNotOptimize(best_qdd.data());
    benchmark::ClobberMemory();
  }
  Eigen::VectorXd mu_star;
  const double g_star = exactDual(*p, task, s, &mu_star);
  setCounters(state, *p, task.constraintRows(), k);
  state.counters["solves"] = evaluations;
  state.counters["g_gap"] = g_star - best;  // ≥ 0: what the grid misses of max g
  state.counters["mu_err"] = (best_mu - mu_star).cwiseAbs().maxCoeff();
}

void benchNaiveGradient(benchmark::State& state, const Problem* p, TaskKind kind, int k) {
  const FrictionSetupOurs s = frictionSetup(*p, k);
  const Task task = taskFromInput(p->model, makeInput(*p, kind, s.qd));
  Workspace ws(p->model, task);
  const FrictionOptions defaults;  // the same stopping rule as ours
  constexpr int kMaxIterations = 100000;
  Eigen::VectorXd torque(p->n), mu(k), grad(k), qdd0(p->n);
  Eigen::MatrixXd K(k, k);
  int solves = 0, iterations = 0;
  bool converged = false;
  auto solve = [&](const Eigen::VectorXd& t) {
    const Status st = solveHybridDynamics(p->model, ws, p->q, s.qd, t, task);
    benchmark::DoNotOptimize(st.code);
    ++solves;
  };
  for (auto _ : state) {
    solves = 0;
    // q̈(0), and L = λ_max(K_ΘΘ) from k unit-torque solves (estimated once per call).
    solve(s.tau_eff);
    qdd0 = ws.solution.qdd;
    for (int b = 0; b < k; ++b) {
      torque = s.tau_eff;
      torque[s.stuck[static_cast<std::size_t>(b)]] += 1.0;
      solve(torque);
      for (int a = 0; a < k; ++a)
        K(a, b) = ws.solution.qdd[s.stuck[static_cast<std::size_t>(a)]] - qdd0[s.stuck[static_cast<std::size_t>(a)]];
    }
    double L = K(0, 0);
    if (k == 2) {
      const double mean = 0.5 * (K(0, 0) + K(1, 1)), half = 0.5 * (K(0, 0) - K(1, 1));
      const double off = 0.5 * (K(0, 1) + K(1, 0));
      L = mean + std::sqrt(half * half + off * off);
    }
    L = std::max(L, 1e-15);  // a stuck joint the task holds: g is linear, the step goes to a vertex
    const double tolerance = defaults.kkt_tolerance * (1.0 + qdd0.cwiseAbs().maxCoeff());
    mu.setZero();
    for (int a = 0; a < k; ++a) grad[a] = qdd0[s.stuck[static_cast<std::size_t>(a)]];
    converged = false;
    for (iterations = 0; iterations < kMaxIterations; ++iterations) {
      double residual = 0.0;  // ‖μ − Π(μ + ∇g)‖∞, as boxQpKktResidual
      for (int a = 0; a < k; ++a)
        residual = std::max(residual, std::abs(mu[a] - std::clamp(mu[a] + grad[a], -s.f[a], s.f[a])));
      if (residual <= tolerance) {
        converged = true;
        break;
      }
      torque = s.tau_eff;
      for (int a = 0; a < k; ++a) {
        mu[a] = std::clamp(mu[a] + grad[a] / L, -s.f[a], s.f[a]);
        torque[s.stuck[static_cast<std::size_t>(a)]] -= mu[a];
      }
      solve(torque);
      for (int a = 0; a < k; ++a) grad[a] = ws.solution.qdd[s.stuck[static_cast<std::size_t>(a)]];
    }
    benchmark::DoNotOptimize(mu.data());
    benchmark::DoNotOptimize(ws.solution.qdd.data());
    benchmark::ClobberMemory();
  }
  Eigen::VectorXd mu_star;
  exactDual(*p, task, s, &mu_star);
  setCounters(state, *p, task.constraintRows(), k);
  state.counters["solves"] = solves;
  state.counters["iterations"] = iterations;
  state.counters["converged"] = converged ? 1 : 0;
  state.counters["mu_err"] = (mu - mu_star).cwiseAbs().maxCoeff();
}

// ---------------------------------------------------------------------------
// Same problem for ours and KDL?

struct Check {
  double hd = 0.0, rnea = 0.0;
};

Check checkAgainstKdl(const Problem& p) {
  Check c;
  for (TaskKind kind : {TaskKind::None, TaskKind::Ee1, TaskKind::Ee6}) {
    if (rowsOf(kind) > p.n) continue;  // over-constrained: damped (ours) versus truncated SVD (KDL)
    const DynamicsInput in = makeInput(p, kind, p.qd);
    const Task task = taskFromInput(p.model, in);
    Workspace ws(p.model, task);
    if (!solveHybridDynamics(p.model, ws, p.q, p.qd, p.tau, task)) return {std::nan(""), std::nan("")};
    c.hd = std::max(c.hd, relativeError(ws.solution.qdd, kdlHybridDynamics(p.spec, in).qdd));
  }
  const Task task(p.model);
  Workspace ws(p.model, task);
  if (!inverseDynamics(p.model, ws, p.q, p.qd, p.qdd, task)) return {std::nan(""), std::nan("")};
  c.rnea = relativeError(ws.tau, kdlInverseDynamics(p.spec, p.q, p.qd, p.qdd, p.gravity));
  return c;
}

std::string fmt(double x) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.3g", x);
  return buffer;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::unique_ptr<Problem>> problems, trees;
  std::unique_ptr<Problem> dual, comb;
  std::vector<std::unique_ptr<Problem>> floating;  // the robots first, then their chains
  std::string floating_poses;
  try {
    for (int n : {1, 2, 4, 7, 16, 32, 64, 128}) problems.push_back(randomProblemOfSize(n));
    problems.push_back(pandaProblem());
    for (int n : {7, 16, 32, 64, 128})
      for (int b : {1, 2, 4}) trees.push_back(treeProblemOfSize(n, b));
    dual = dualPandaProblem();
    comb = combProblem();
    std::string humanoid_pose, solo_pose;
    floating.push_back(humanoidProblem(&humanoid_pose));
    floating.push_back(solo12Problem(&solo_pose));
    floating_poses = humanoid_pose + "; " + solo_pose;
    // The chains of the same size: as many joints as each robot's nv, and as its dof.
    for (int n : {35, 29, 18, 12}) floating.push_back(floatingBaselineChain(n));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "zwang_bench: %s\n", e.what());
    return 1;
  }

  // The trajectories: made once, before anything is timed.
  std::vector<std::pair<const Problem*, std::unique_ptr<Trajectory>>> trajectories;
  try {
    for (const auto& p : problems)
      if (p->label == "panda" || p->label == "N=64") trajectories.emplace_back(p.get(), makeTrajectory(*p));
    trajectories.emplace_back(floating.front().get(), makeTrajectory(*floating.front()));  // the humanoid
  } catch (const std::exception& e) {
    std::fprintf(stderr, "zwang_bench: %s\n", e.what());
    return 1;
  }

  std::string checks;
  for (const auto& p : problems) {
    const Check c = checkAgainstKdl(*p);
    checks += (checks.empty() ? "" : ", ") + p->label + ": qdd " + fmt(c.hd) + ", rnea " + fmt(c.rnea);
    if (!(c.hd <= 1e-6 && c.rnea <= 1e-6))
      std::fprintf(stderr, "zwang_bench: WARNING: ours and KDL disagree on %s (qdd %g, rnea %g)\n", p->label.c_str(),
                   c.hd, c.rnea);
  }
  benchmark::AddCustomContext("zwang_check_vs_kdl_max_rel_err", checks);
  benchmark::AddCustomContext("zwang_compiler", ZWANG_BENCH_COMPILER);
  benchmark::AddCustomContext("zwang_cxx_flags", ZWANG_BENCH_FLAGS);
  benchmark::AddCustomContext("zwang_build_type", ZWANG_BENCH_BUILD_TYPE);
  benchmark::AddCustomContext("zwang_chain_seed", std::to_string(kSeed));
  benchmark::AddCustomContext("zwang_dual_panda_hands", dualPandaHands(*dual));
  benchmark::AddCustomContext("zwang_floating_poses", floating_poses);
  benchmark::AddCustomContext("zwang_floating_breakaway", fmt(kStuckBreakaway));

  auto reg = [](const std::string& family, const Problem& p, auto&& fn) {
    benchmark::RegisterBenchmark((family + "/" + p.label).c_str(), fn)->Unit(benchmark::kNanosecond);
  };
  const std::pair<TaskKind, const char*> hd_tasks[] = {
      {TaskKind::None, "m0"}, {TaskKind::Ee1, "m1"}, {TaskKind::Ee6, "m6"}, {TaskKind::Split6, "m6x2"}};
  const std::pair<TaskKind, const char*> fric_tasks[] = {{TaskKind::None, "free"}, {TaskKind::Ee6, "ee6"}};
  const std::pair<FrictionMethod, const char*> methods[] = {{FrictionMethod::ActiveSet, "as"},
                                                            {FrictionMethod::ProjectedGradient, "pg"},
                                                            {FrictionMethod::Automatic, "auto"},
                                                            {FrictionMethod::StickPatterns, "sp"}};

  for (const auto& [kind, name] : hd_tasks)
    for (const auto& p : problems)
      reg(std::string("ours_hd_") + name, *p,
          [q = p.get(), kind = kind](benchmark::State& s) { benchOursHybrid(s, q, kind); });
  for (const auto& [kind, name] : {std::pair{TaskKind::None, "m0"}, std::pair{TaskKind::Ee1, "m1"}})
    for (const bool as_rows : {false, true})
      for (const auto& p : problems)
        if (p->n > 1)
          reg(std::string("ours_hd_") + name + (as_rows ? "_halfrows" : "_halfprescribed"), *p,
              [q = p.get(), kind = kind, as_rows](benchmark::State& s) { benchHalfPrescribed(s, q, kind, as_rows); });
  for (const auto& p : problems) reg("ours_rnea", *p, [q = p.get()](benchmark::State& s) { benchOursRnea(s, q); });
  for (const auto& p : problems) reg("ours_crba", *p, [q = p.get()](benchmark::State& s) { benchOursCrba(s, q); });
  for (const auto& [kind, name] : hd_tasks) {
    if (kind == TaskKind::Split6) continue;  // KDL constrains the end effector only
    for (const auto& p : problems)
      reg(std::string("kdl_hd_") + name, *p,
          [q = p.get(), kind = kind](benchmark::State& s) { benchKdlHybrid(s, q, kind); });
  }
  for (const auto& p : problems) reg("kdl_rne", *p, [q = p.get()](benchmark::State& s) { benchKdlRne(s, q); });

  for (const auto& [method, method_name] : methods)
    for (const auto& [kind, task_name] : fric_tasks)
      for (const char* k_name : {"k0", "k1", "k2", "khalf", "kall"})
        for (const auto& p : problems) {
          const std::string kn = k_name;
          const int k = kn == "k0" ? 0 : kn == "k1" ? 1 : kn == "k2" ? 2 : kn == "khalf" ? p->n / 2 : p->n;
          if (k > p->n) continue;
          if (kn == "khalf" && (k <= 2 || k == p->n)) continue;  // the same as another row
          if (kn == "kall" && p->n == 1) continue;               // = k1
          reg(std::string("fric_") + method_name + "_" + task_name + "_" + kn, *p,
              [q = p.get(), kind = kind, k, method = method](benchmark::State& s) {
            benchFriction(s, q, kind, k, method);
          });
        }

  // Warm start (#28): every joint stuck, the last solve's pattern kept, against the same cold and the plain solve.
  for (const auto& [kind, task_name] : fric_tasks)
    for (const auto& p : problems)
      if (p->n > 1)
        reg(std::string("fric_warm_") + task_name + "_kall", *p, [q = p.get(), kind = kind](benchmark::State& s) {
          benchFriction(s, q, kind, q->n, FrictionMethod::ActiveSet, true);
        });
  for (const auto& [kind, task_name] : fric_tasks)
    for (int k : {1, 2})
      for (const auto& p : problems) {
        if (k > p->n) continue;
        reg(std::string("grid_") + task_name + "_k" + std::to_string(k), *p,
            [q = p.get(), kind = kind, k](benchmark::State& s) { benchGrid(s, q, kind, k); });
      }
  for (const auto& [kind, task_name] : fric_tasks)
    for (int k : {1, 2})
      for (const auto& p : problems) {
        if (k > p->n) continue;
        reg(std::string("naivepg_") + task_name + "_k" + std::to_string(k), *p,
            [q = p.get(), kind = kind, k](benchmark::State& s) { benchNaiveGradient(s, q, kind, k); });
      }

  // Trees next to their chains; the dual arm.
  for (const auto& [kind, name] : {std::pair{TaskKind::None, "m0"}, std::pair{TaskKind::Ee6, "m6"}})
    for (const auto& p : trees)
      reg(std::string("tree_hd_") + name, *p,
          [q = p.get(), kind = kind](benchmark::State& s) { benchTreeHybrid(s, q, kind); });
  for (const int rows : {0, 10, 20, 30, 40, 60})
    reg("comb_rows" + std::to_string(rows), *comb,
        [q = comb.get(), rows](benchmark::State& s) { benchCombRows(s, q, rows); });
  const std::pair<TaskKind, const char*> dual_tasks[] = {{TaskKind::Hands12, "hands12"}, {TaskKind::Relative6, "rel6"}};
  for (const auto& [kind, name] : dual_tasks)
    reg(std::string("ours_hd_") + name, *dual,
        [q = dual.get(), kind = kind](benchmark::State& s) { benchOursHybrid(s, q, kind); });
  for (const auto& [kind, name] : dual_tasks)
    reg(std::string("fric_as_") + name + "_kall", *dual, [q = dual.get(), kind = kind](benchmark::State& s) {
      benchFriction(s, q, kind, q->n, FrictionMethod::ActiveSet);
    });

  // Floating bases and the chains of the same size.
  for (const bool held : {false, true}) {
    const std::string rows = held ? "m12" : "m0";
    for (const auto& p : floating)
      reg("floating_hd_" + rows, *p, [q = p.get(), held](benchmark::State& s) { benchFloatingHybrid(s, q, held); });
    for (const auto& [method, method_name] :
         {std::pair{FrictionMethod::ActiveSet, "as"}, std::pair{FrictionMethod::Automatic, "auto"}})
      for (const auto& p : floating)
        reg("floating_fric_" + std::string(method_name) + "_" + rows + "_kall", *p,
            [q = p.get(), held, method = method](benchmark::State& s) { benchFloatingFriction(s, q, held, method); });
  }

  // Along the trajectories: the plain solve and the warm-started friction solve on the same states.
  for (const auto& [p, t] : trajectories) {
    reg("hd_traj", *p, [p = p, t = t.get()](benchmark::State& s) { benchTrajectoryHybrid(s, p, t); });
    reg("fric_warm_traj", *p, [p = p, t = t.get()](benchmark::State& s) { benchTrajectoryFriction(s, p, t); });
    reg("sim_euler", *p,
        [p = p, t = t.get()](benchmark::State& s) { benchSimulation(s, p, t, Integrator::SemiImplicitEuler); });
    reg("sim_rk4", *p,
        [p = p, t = t.get()](benchmark::State& s) { benchSimulation(s, p, t, Integrator::RungeKutta4); });
    if (p->label == "panda")
      benchmark::RegisterBenchmark(
          ("worst_warm_traj/" + p->label).c_str(),
          [p = p, t = t.get()](benchmark::State& s) { benchTrajectoryWorstCase(s, p, t, 1000000); })
          ->Iterations(1)
          ->Unit(benchmark::kMillisecond);
  }

  // Worst case over 10⁶ calls, Panda with every joint stuck (plain and 6 rows).
  for (const auto& p : problems)
    if (p->label == "panda")
      for (const auto& [kind, task_name] : fric_tasks)
        benchmark::RegisterBenchmark(
            (std::string("worst_as_") + task_name + "_kall/" + p->label).c_str(),
            [q = p.get(), kind = kind](benchmark::State& s) { benchWorstCase(s, q, kind, 1000000); })
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond);

  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
