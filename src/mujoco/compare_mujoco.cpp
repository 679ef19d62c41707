// MuJoCo's soft joint friction against zwang's exact friction (mujoco_compare.hpp, docs/mujoco.md).
//
// The file's text is compiled twice from the same string: by MuJoCo (mj_loadXML through a virtual file system,
// for mj_forward and mj_step) and by zwang's MJCF loader. A floating base is fixed by deleting its free joint
// from the text first. MuJoCo's actuators and contacts are disabled and its joint springs zeroed so that both
// sides hold the same robot: gravity, joint torques, frictionloss, armature, damping, limits, joint equalities.
#include "zwang/mujoco_compare.hpp"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "mujoco/mujoco_model.hpp"
#include "zwang/configuration.hpp"
#include "zwang/friction.hpp"
#include "zwang/inverse_dynamics.hpp"
#include "zwang/mjcf.hpp"

namespace zwang {
namespace {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
struct VfsDeleter {
  void operator()(mjVFS* vfs) const {
    mj_deleteVFS(vfs);
    delete vfs;
  }
};
using MjModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using MjDataPtr = std::unique_ptr<mjData, DataDeleter>;

// MuJoCo's warning handler is global and prints to stdout (a JSON report's stream): silenced while we run it;
// the warnings a run raises are read from mjData::warning instead.
std::mutex& mujocoMutex() {
  static std::mutex mutex;
  return mutex;
}
void ignoreWarning(const char*) {}
class SilenceMujoco {
 public:
  SilenceMujoco() : lock_(mujocoMutex()), saved_(mju_user_warning) { mju_user_warning = ignoreWarning; }
  ~SilenceMujoco() { mju_user_warning = saved_; }
  SilenceMujoco(const SilenceMujoco&) = delete;
  SilenceMujoco& operator=(const SilenceMujoco&) = delete;

 private:
  std::lock_guard<std::mutex> lock_;
  void (*saved_)(const char*);
};

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ModelError(path + ": cannot open the file");
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

// MuJoCo's compile of `text` (one file in memory: it may include no other file).
MjModelPtr compileText(const std::string& path, const std::string& text) {
  static const char kFile[] = "zwang_compare.xml";
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);  // a large fixed-size name table: not on the stack
  mj_defaultVFS(vfs.get());
  const int size = static_cast<int>(text.size()) + 1;  // with the terminating '\0'
  if (mj_makeEmptyFileVFS(vfs.get(), kFile, size) != 0) throw ModelError(path + ": MuJoCo's VFS cannot hold it");
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), kFile)], text.c_str(), static_cast<std::size_t>(size));
  char error[1000] = "";
  const SilenceMujoco silence;
  MjModelPtr m(mj_loadXML(kFile, vfs.get(), error, sizeof error));
  if (!m) throw ModelError(path + ": MuJoCo refuses the model: " + error);
  return m;
}

// Erase every element `<tag …/>` whose opening text contains `must_contain` ("" for all); the count erased.
int eraseEmptyElements(std::string& text, const std::string& tag, const std::string& must_contain) {
  int erased = 0;
  for (std::size_t at = text.find("<" + tag); at != std::string::npos; at = text.find("<" + tag, at)) {
    const std::size_t end = text.find('>', at);
    const char next = text[at + 1 + tag.size()];
    const bool whole_tag = next == ' ' || next == '/' || next == '\t' || next == '\n' || next == '\r';
    if (end == std::string::npos || !whole_tag || text[end - 1] != '/' ||
        text.substr(at, end - at).find(must_contain) == std::string::npos) {
      ++at;
      continue;
    }
    text.erase(at, end + 1 - at);
    ++erased;
  }
  return erased;
}

// The text with the floating base's free joint and the keyframes (sized for the free joint's qpos) deleted.
std::string withoutFreeJoint(const std::string& path, std::string text) {
  const int erased = eraseEmptyElements(text, "freejoint", "") + eraseEmptyElements(text, "joint", "type=\"free\"") +
                     eraseEmptyElements(text, "joint", "type='free'");
  if (erased != 1) throw ModelError(path + ": cannot fix the floating base: its free joint is not one <freejoint/>");
  const std::size_t open = text.find("<keyframe");
  if (open != std::string::npos) {
    const std::size_t close = text.find("</keyframe>", open);
    const std::size_t end = close == std::string::npos ? text.find("/>", open) + 2 : close + 11;
    text.erase(open, end - open);
  }
  return text;
}

std::string jointName(const mjModel* m, int j) {  // as the MJCF loader names it
  const char* name = mj_id2name(m, mjOBJ_JOINT, j);
  return name && name[0] ? std::string(name) : "joint" + std::to_string(j);
}

// Both sides of the compared model and how their coordinates correspond.
struct Pair {
  MjModelPtr m;      // MuJoCo's, with contacts and actuators disabled and springs zeroed
  MjcfModel loaded;  // zwang's
  bool base_fixed = false;
  Eigen::VectorXd home;          // zwang's q of the first keyframe (empty: none)
  std::vector<int> dof;          // per zwang DOF: MuJoCo's DOF
  std::vector<int> joint_of_mj;  // per MuJoCo joint: zwang's joint
};

void mapCoordinates(const std::string& path, Pair& p) {
  const mjModel* m = p.m.get();
  const Model& model = p.loaded.model;
  p.dof.assign(static_cast<std::size_t>(model.dof()), -1);
  for (int j = 0; j < m->njnt; ++j) {
    if (m->jnt_type[j] == mjJNT_FREE)
      throw ModelError(path + ": joint '" + jointName(m, j) +
                       "' is free but not the floating base: compare-mujoco compares the joints of a tree");
    const int zj = model.jointIndex(jointName(m, j));
    p.joint_of_mj.push_back(zj);
    for (int k = 0; k < model.joint(zj).nv(); ++k)
      p.dof[static_cast<std::size_t>(model.joint(zj).v_index + k)] = m->jnt_dofadr[j] + k;
  }
  if (model.nq() != m->nq || model.nv() != m->nv) throw ModelError(path + ": zwang's and MuJoCo's sizes differ");
}

// zwang's q ↔ MuJoCo's qpos, joint by joint (the same entries: docs/mujoco.md).
void toQpos(const Pair& p, const Eigen::VectorXd& q, mjtNum* qpos) {
  for (int j = 0; j < p.m->njnt; ++j) {
    const Joint& joint = p.loaded.model.joint(p.joint_of_mj[static_cast<std::size_t>(j)]);
    for (int k = 0; k < joint.nq(); ++k) qpos[p.m->jnt_qposadr[j] + k] = q[joint.q_index + k];
  }
}

// The first keyframe's qpos of the original file as zwang's q, without the deleted free joint's entries.
Eigen::VectorXd homeFromKeyframe(const mjModel* original, int base_body, const Pair& p) {
  if (original->nkey == 0) return {};
  const int skip = base_body < 0 ? 0 : 1;  // the free joint is the original's joint 0: the world's only child's
  Eigen::VectorXd q(p.loaded.model.nq());
  for (int j = 0; j < p.m->njnt; ++j) {
    const Joint& joint = p.loaded.model.joint(p.joint_of_mj[static_cast<std::size_t>(j)]);
    const int from = original->jnt_qposadr[j + skip];
    for (int k = 0; k < joint.nq(); ++k) q[joint.q_index + k] = original->key_qpos[from + k];
  }
  return q;
}

void prepareMujoco(mjModel* m) {
  m->opt.disableflags |= mjDSBL_CONTACT | mjDSBL_ACTUATION;   // zwang: no contacts, joint torques only
  for (int j = 0; j < m->njnt; ++j) m->jnt_stiffness[j] = 0;  // zwang models no joint springs
}

Pair load(const std::string& path) {
  const std::string text = readText(path);
  const MjModelPtr original = compileText(path, text);
  const int base_body = internal::floatingBaseBody(original.get());
  Pair p;
  p.base_fixed = base_body >= 0;
  const std::string compared = p.base_fixed ? withoutFreeJoint(path, text) : text;
  p.m = p.base_fixed ? compileText(path, compared) : compileText(path, text);
  try {
    p.loaded = readMjcfString(compared);
  } catch (const ModelError& e) {
    throw ModelError(path + std::string(e.what()).substr(std::strlen("<string>")));
  }
  mapCoordinates(path, p);
  prepareMujoco(p.m.get());
  p.home = homeFromKeyframe(original.get(), base_body, p);
  return p;
}

// ---------------------------------------------------------------------------
// Settings and inputs

std::vector<MujocoSetting> settingsOf(const MujocoCompareOptions& options) {
  return {{"default", "the file's options (solver, iterations, dof_solref, dof_solimp)"},
          {"noslip", "noslip_iterations = " + std::to_string(options.noslip_iterations)},
          {"tight", "dof_solref = (2 timestep, 1), dof_solimp = (0.9999, 0.9999, 0.001, 0.5, 2)"}};
}

// The setting applied to a copy of the prepared model.
MjModelPtr withSetting(const mjModel* m, const std::string& setting, const MujocoCompareOptions& options) {
  MjModelPtr copy(mj_copyModel(nullptr, m));
  if (setting == "noslip") copy->opt.noslip_iterations = options.noslip_iterations;
  if (setting == "tight")
    for (int v = 0; v < copy->nv; ++v) {
      // The stiffest reference MuJoCo accepts (time constant ≥ 2 timesteps) and the largest impedance (mjMAXIMP).
      copy->dof_solref[mjNREF * v] = 2 * copy->opt.timestep;
      copy->dof_solref[mjNREF * v + 1] = 1;
      const mjtNum solimp[5] = {mjMAXIMP, mjMAXIMP, 0.001, 0.5, 2};
      std::copy(solimp, solimp + 5, copy->dof_solimp + mjNIMP * v);
    }
  return copy;
}

void checkOptions(const MujocoCompareOptions& o) {
  for (const double t : o.seconds)
    if (!(t > 0 && t <= 3600)) throw std::invalid_argument("seconds: each time must be in (0, 3600] s");
  if (o.seconds.empty()) throw std::invalid_argument("seconds: no time given");
  if (!(o.sample_interval > 0 && o.sample_interval <= 3600))
    throw std::invalid_argument("sample interval: must be in (0, 3600] s");
  if (o.random_postures < 0 || o.random_postures > 1000)
    throw std::invalid_argument("postures: the count must be in [0, 1000]");
  if (o.noslip_iterations < 1 || o.noslip_iterations > 10000)
    throw std::invalid_argument("noslip iterations: must be in [1, 10000]");
  if (!std::isfinite(o.gravity_compensation)) throw std::invalid_argument("gravity compensation: not finite");
  if (!std::isfinite(o.frictionloss)) throw std::invalid_argument("frictionloss: not finite");
}

void checkPosture(const Model& model, const ComparePosture& posture) {
  const std::string where = "posture '" + posture.name + "': ";
  if (posture.q.size() != model.nq())
    throw std::invalid_argument(where + "q has " + std::to_string(posture.q.size()) + " entries, the model " +
                                std::to_string(model.nq()));
  if (const Status s = checkConfiguration(model, posture.q); !s) throw std::invalid_argument(where + s.message);
  if (posture.tau.size() != 0 && posture.tau.size() != model.nv())
    throw std::invalid_argument(where + "tau has " + std::to_string(posture.tau.size()) + " entries, the model " +
                                std::to_string(model.nv()));
  if (!posture.tau.allFinite()) throw std::invalid_argument(where + "tau is not finite");
  if (!std::isfinite(posture.gravity_compensation))
    throw std::invalid_argument(where + "gravity_compensation is not finite");
}

std::vector<ComparePosture> generatedPostures(const Pair& p, const MujocoCompareOptions& options) {
  const Model& model = p.loaded.model;
  std::vector<ComparePosture> out(1 + static_cast<std::size_t>(options.random_postures));
  out[0].name = p.home.size() ? "home (keyframe 0)" : "neutral";
  out[0].q = p.home.size() ? p.home : Eigen::VectorXd::Zero(model.nq());
  if (!p.home.size()) (void)neutralConfiguration(model, out[0].q);
  std::uint64_t state = options.seed;
  for (std::size_t k = 1; k < out.size(); ++k) {
    out[k].name = "random " + std::to_string(k);
    out[k].q = Eigen::VectorXd::Zero(model.nq());
    (void)randomConfiguration(model, state, out[k].q);
  }
  for (ComparePosture& posture : out) posture.gravity_compensation = options.gravity_compensation;
  return out;
}

// ---------------------------------------------------------------------------
// The two sides

struct Side {
  const Pair& p;
  const MujocoCompareOptions& options;
  std::vector<MjModelPtr> settings;  // MujocoComparison::settings' order
};

// τ + s·G(q): G from inverse dynamics at rest with the file's gravity.
Eigen::VectorXd appliedTorques(const Side& side, const ComparePosture& posture) {
  const Model& model = side.p.loaded.model;
  Eigen::VectorXd tau = posture.tau.size() ? posture.tau : Eigen::VectorXd::Zero(model.nv());
  if (posture.gravity_compensation == 0) return tau;
  Workspace ws(model);
  Task task(model);
  task.gravity = side.p.loaded.gravity;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nv());
  if (const Status s = inverseDynamics(model, ws, posture.q, zero, zero, task); !s)
    throw std::invalid_argument("posture '" + posture.name + "': " + s.message);
  return tau + posture.gravity_compensation * ws.tau;
}

void solveZwang(const Side& side, PostureComparison& out) {
  const Model& model = side.p.loaded.model;
  Workspace ws(model);
  Task task(model);
  task.gravity = side.p.loaded.gravity;
  FrictionOptions fo;
  if (side.options.frictionloss >= 0) {
    fo.breakaway = Eigen::VectorXd::Constant(model.dof(), side.options.frictionloss);
    fo.kinetic = fo.breakaway;
  }
  const Status s = solveWithFriction(model, ws, out.q, Eigen::VectorXd::Zero(model.nv()), out.tau, task, fo);
  if (!s && s.code != StatusCode::Infeasible)
    throw std::invalid_argument("posture '" + out.name + "': zwang's solve fails: " + s.message);
  out.qdd = ws.solution.qdd;
  out.mu = ws.friction.mu;
  out.tau_friction = ws.friction.tau_friction;
  out.state = ws.friction.state;
}

// MuJoCo's data at rest in the posture, with the torques applied.
MjDataPtr restingData(const Side& side, const mjModel* m, const PostureComparison& posture) {
  MjDataPtr d(mj_makeData(m));
  toQpos(side.p, posture.q, d->qpos);
  for (std::size_t k = 0; k < side.p.dof.size(); ++k)
    d->qfrc_applied[side.p.dof[k]] = posture.tau[static_cast<Eigen::Index>(k)];
  return d;
}

void forwardAtRest(const Side& side, const mjModel* m, const PostureComparison& posture, MujocoSettingResult& r) {
  const MjDataPtr d = restingData(side, m, posture);
  mj_forward(m, d.get());
  const Eigen::Index n = static_cast<Eigen::Index>(side.p.dof.size());
  Eigen::VectorXd friction_of_mj = Eigen::VectorXd::Zero(m->nv);
  for (int i = 0; i < d->nefc; ++i)
    if (d->efc_type[i] == mjCNSTR_FRICTION_DOF) friction_of_mj[d->efc_id[i]] += d->efc_force[i];  // J is e_dof
  r.qacc.resize(n);
  r.tau_friction.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    r.qacc[k] = d->qacc[side.p.dof[static_cast<std::size_t>(k)]];
    r.tau_friction[k] = friction_of_mj[side.p.dof[static_cast<std::size_t>(k)]];
  }
}

// |q(t) − q(0)| per zwang DOF (mj_differentiatePos: a ball joint's rotation vector per DOF).
Eigen::VectorXd driftNow(const Side& side, const mjModel* m, const Eigen::VectorXd& qpos0, const mjData* d) {
  Eigen::VectorXd dq(m->nv);
  mj_differentiatePos(m, dq.data(), 1.0, qpos0.data(), d->qpos);
  Eigen::VectorXd out(static_cast<Eigen::Index>(side.p.dof.size()));
  for (Eigen::Index k = 0; k < out.size(); ++k) out[k] = std::abs(dq[side.p.dof[static_cast<std::size_t>(k)]]);
  return out;
}

// The warnings a run raised, by name (mjtWarning's order).
std::vector<std::string> warningsOf(const mjData* d) {
  static const char* const kNames[mjNWARNING] = {"inertia",
                                                 "contact buffer full",
                                                 "constraint buffer full",
                                                 "visual geom buffer full",
                                                 "bad qpos",
                                                 "bad qvel",
                                                 "bad qacc",
                                                 "bad ctrl"};
  std::vector<std::string> out;
  for (int w = 0; w < mjNWARNING; ++w)
    if (d->warning[w].number > 0) out.push_back(kNames[w]);
  return out;
}

void simulate(const Side& side, const mjModel* m, const PostureComparison& posture, MujocoSettingResult& r) {
  const MjDataPtr d = restingData(side, m, posture);
  const std::vector<double>& seconds = side.options.seconds;
  const double dt = m->opt.timestep;
  const long steps = std::lround(seconds.back() / dt);
  const long every = std::max(1L, std::lround(side.options.sample_interval / dt));
  const Eigen::VectorXd qpos0 = Eigen::Map<const Eigen::VectorXd>(d->qpos, m->nq);
  const Eigen::Index n = static_cast<Eigen::Index>(side.p.dof.size());
  r.drift.resize(static_cast<Eigen::Index>(seconds.size()), n);
  r.times.resize(steps / every + 1);
  r.drift_series.resize(r.times.size(), n);
  std::size_t next = 0;
  for (long step = 0; step <= steps; ++step) {
    if (step > 0) mj_step(m, d.get());
    if (step % every == 0) {
      r.times[step / every] = static_cast<double>(step) * dt;
      r.drift_series.row(step / every) = driftNow(side, m, qpos0, d.get()).transpose();
    }
    while (next < seconds.size() && std::lround(seconds[next] / dt) == step)
      r.drift.row(static_cast<Eigen::Index>(next++)) = driftNow(side, m, qpos0, d.get()).transpose();
  }
  r.mujoco_warnings = warningsOf(d.get());
}

PostureComparison comparePosture(const Side& side, const ComparePosture& posture) {
  PostureComparison out;
  out.name = posture.name;
  out.q = posture.q;
  out.tau = appliedTorques(side, posture);
  solveZwang(side, out);
  const SilenceMujoco silence;
  for (const MjModelPtr& m : side.settings) {
    MujocoSettingResult r;
    forwardAtRest(side, m.get(), out, r);
    simulate(side, m.get(), out, r);
    out.mujoco.push_back(std::move(r));
  }
  return out;
}

const char* integratorName(int integrator) {
  switch (integrator) {
    case mjINT_EULER: return "Euler";
    case mjINT_RK4: return "RK4";
    default: return "implicit";
  }
}

MujocoComparison describe(const std::string& path, const Pair& p, const MujocoCompareOptions& options) {
  MujocoComparison c;
  const Model& model = p.loaded.model;
  c.model_name = model.name();
  c.base_fixed = p.base_fixed;
  c.timestep = p.m->opt.timestep;
  c.integrator = integratorName(p.m->opt.integrator);
  c.frictionloss.resize(model.dof());
  for (int k = 0; k < model.dof(); ++k) {
    const Dof& dof = model.dofs()[static_cast<std::size_t>(k)];
    c.dof_names.push_back(dof.name);
    c.frictionloss[k] = options.frictionloss >= 0 ? options.frictionloss : dof.breakaway_friction;
  }
  c.seconds = options.seconds;
  c.settings = settingsOf(options);
  for (const ModelWarning& w : model.warnings())  // the loader read the text as "<string>": name the file
    c.warnings.push_back(w.message.rfind("<string>", 0) == 0 ? path + w.message.substr(8) : w.message);
  return c;
}

}  // namespace

Eigen::VectorXd heldDriftMax(const PostureComparison& posture, const Eigen::MatrixXd& drift) {
  const bool any = std::count(posture.state.begin(), posture.state.end(), JointState::Stick) > 0;
  Eigen::VectorXd out = Eigen::VectorXd::Zero(drift.rows());
  for (Eigen::Index k = 0; k < drift.cols(); ++k)
    if (!any || posture.state[static_cast<std::size_t>(k)] == JointState::Stick) out = out.cwiseMax(drift.col(k));
  return out;
}

Model mujocoCompareModel(const std::string& path) { return load(path).loaded.model; }

MujocoComparison compareWithMujoco(const std::string& path, const std::vector<ComparePosture>& postures,
                                   const MujocoCompareOptions& options) {
  MujocoCompareOptions o = options;
  checkOptions(o);
  std::sort(o.seconds.begin(), o.seconds.end());
  Pair p = load(path);
  if (o.frictionloss >= 0)
    for (int v = 0; v < p.m->nv; ++v) p.m->dof_frictionloss[v] = o.frictionloss;
  const std::vector<ComparePosture> chosen = postures.empty() ? generatedPostures(p, o) : postures;
  for (const ComparePosture& posture : chosen) checkPosture(p.loaded.model, posture);
  MujocoComparison c = describe(path, p, o);
  Side side{p, o, {}};
  for (const MujocoSetting& setting : c.settings) side.settings.push_back(withSetting(p.m.get(), setting.name, o));
  for (const ComparePosture& posture : chosen) c.postures.push_back(comparePosture(side, posture));
  return c;
}

}  // namespace zwang
