// Instructions per call of the solvers on the robots of models/ (callgrind:
// the instrumentation is on only around 100 calls of each case, one dump per
// case, named by it). Counts are the same on a busy machine as on a quiet
// one, so two builds can be compared where timings are too noisy; they are
// instructions, not time (a long dependency chain or a cache miss counts as
// one). Uses only the public API, so the same file builds against any commit
// (the calls below in either argument order: zwang/version.hpp came with 0.2's).
// Built and run by bench/instructions/compare.sh, not by CMake.
#include <valgrind/callgrind.h>

#include <cstdio>
#include <string>
#include <vector>

#include "zwang/zwang.hpp"

#if __has_include("zwang/version.hpp")
#define ZWANG_ARGUMENTS(model, ws, q, qd, x, task) model, ws, q, qd, x, task
#define ZWANG_CRBA_ARGUMENTS(model, ws, q) model, ws, q
#else  // before 0.2: the task second, the workspace last
#define ZWANG_ARGUMENTS(model, ws, q, qd, x, task) model, task, q, qd, x, ws
#define ZWANG_CRBA_ARGUMENTS(model, ws, q) model, q, ws
#endif

namespace {

using namespace zwang;

constexpr int kCalls = 100;

template <class Call>
void count(const std::string& name, Call call) {
  call();  // warm: the first call may touch memory the others find in cache
  CALLGRIND_ZERO_STATS;
  CALLGRIND_START_INSTRUMENTATION;
  for (int k = 0; k < kCalls; ++k) call();
  CALLGRIND_STOP_INSTRUMENTATION;
  CALLGRIND_DUMP_STATS_AT(name.c_str());
}

// A moving state: every joint off zero, turning, driven; a free base upright and moving.
struct State {
  Eigen::VectorXd q, qd, tau;
};
State movingState(const Model& m) {
  State s{Eigen::VectorXd::Zero(m.nq()), Eigen::VectorXd::Zero(m.nv()), Eigen::VectorXd::Zero(m.nv())};
  const int base_q = m.nq() - m.dof(), base_v = m.nv() - m.dof();
  if (base_q == 7) s.q[3] = 1.0;  // quaternion w
  for (int j = 0; j < m.dof(); ++j) {
    s.q[base_q + j] = 0.3 + 0.05 * j;
    s.qd[base_v + j] = 0.5 - 0.07 * j;
    s.tau[base_v + j] = 0.2 * j;
  }
  for (int k = 0; k < base_v; ++k) s.qd[k] = 0.1 * (k + 1);
  return s;
}

struct Case {
  std::string name;
  const Model* model;
  std::vector<std::pair<std::string, int>> rows;  // frame, rows (world axes): held still
  bool contacts;
};

void countCase(const Case& c) {
  const Model& m = *c.model;
  const State s = movingState(m);
  Task task(m);
  for (const auto& [frame, rows] : c.rows) {
    const ConstraintMatrix A = ConstraintMatrix::Identity(6, 6).leftCols(rows);
    if (c.contacts)
      task.addContact(frame, A, Expressed::World);
    else
      task.addConstraint(frame, A, Expressed::World);
  }
  Workspace ws(m, task);
  count(c.name + "_hd", [&] { (void)solveHybridDynamics(ZWANG_ARGUMENTS(m, ws, s.q, s.qd, s.tau, task)); });
  const Eigen::VectorXd at_rest = Eigen::VectorXd::Zero(m.nv());  // every joint with friction stuck
  const FrictionOptions options;
  count(c.name + "_fric", [&] { (void)solveWithFriction(ZWANG_ARGUMENTS(m, ws, s.q, at_rest, s.tau, task), options); });
  if (!c.rows.empty()) return;
  const Eigen::VectorXd qdd = Eigen::VectorXd::Constant(m.nv(), 0.3);
  count(c.name + "_rnea", [&] { (void)inverseDynamics(ZWANG_ARGUMENTS(m, ws, s.q, s.qd, qdd, task)); });
  count(c.name + "_crba", [&] { (void)jointSpaceInertia(ZWANG_CRBA_ARGUMENTS(m, ws, s.q)); });
}

// A URDF of `links` moving links, link k hanging from link parent(k) by a
// revolute joint with an axis and offset that vary from joint to joint (a
// long chain, or a tree, where cache misses rather than instructions may
// decide the time: their counts show what the instructions cost there).
template <class Parent>
std::string generatedUrdf(int links, Parent parent) {
  std::string xml = "<robot name='generated'><link name='l0'/>";
  const char* axes[] = {"0 0 1", "0 1 0", "1 0 0"};
  for (int k = 1; k <= links; ++k) {
    const std::string name = "l" + std::to_string(k), offset = std::to_string(0.05 + 0.01 * (k % 5));
    xml += "<link name='" + name + "'><inertial><origin xyz='0 0 " + offset + "'/><mass value='" +
           std::to_string(1.0 + 0.1 * (k % 7)) +
           "'/><inertia ixx='0.02' iyy='0.03' izz='0.01' ixy='0' ixz='0' iyz='0'/></inertial></link>";
    xml += "<joint name='j" + std::to_string(k) + "' type='revolute'><parent link='l" + std::to_string(parent(k)) +
           "'/><child link='" + name + "'/><origin xyz='0 0.02 " + offset + "' rpy='0.1 0 0'/><axis xyz='" +
           axes[k % 3] + "'/><limit lower='-3' upper='3' effort='100' velocity='10'/></joint>";
  }
  return xml + "</robot>";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s MODELS_DIR (under valgrind --tool=callgrind --instr-atstart=no)\n", argv[0]);
    return 2;
  }
  const std::string dir = std::string(argv[1]) + "/";
  UrdfOptions free_base;
  free_base.base = BaseType::Free;
  const Model panda = loadUrdfFile(dir + "panda.urdf");
  const Model dual = loadUrdfFile(dir + "dual_panda.urdf");
  const Model humanoid = loadUrdfFile(dir + "simple_humanoid.urdf", free_base);
  const Model solo = loadUrdfFile(dir + "solo12.urdf", free_base);
  const Model chain64 = loadUrdfString(generatedUrdf(64, [](int k) { return k - 1; }));
  const Model tree63 = loadUrdfString(generatedUrdf(63, [](int k) { return k / 2; }));  // binary, in heap order
  const std::string tip = panda.frames().back().name;
  const std::vector<Case> cases = {
      {"panda_m0", &panda, {}, false},
      {"panda_m6", &panda, {{tip, 6}}, false},
      {"dual_panda_m0", &dual, {}, false},
      {"humanoid_m0", &humanoid, {}, true},
      {"humanoid_m12", &humanoid, {{"r_ankle", 6}, {"l_ankle", 6}}, true},
      {"solo12_m0", &solo, {}, true},
      {"chain64_m0", &chain64, {}, false},
      {"chain64_m6", &chain64, {{"l64", 6}}, false},
      {"tree63_m0", &tree63, {}, false},
      {"solo12_m12", &solo, {{"FL_FOOT", 3}, {"FR_FOOT", 3}, {"HL_FOOT", 3}, {"HR_FOOT", 3}}, true},
  };
  for (const Case& c : cases) countCase(c);
  return 0;
}
