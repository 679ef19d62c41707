// MJCF → Model through MuJoCo's compiler (see mjcf.hpp, docs/mujoco.md).
//
// MuJoCo compiles the XML (defaults, classes, angle units, euler sequences,
// inertias from geoms) into an mjModel; this file reads only the compiled
// arrays, so whatever MJCF spells a value, zwang sees what MuJoCo simulates.
// Bodies come in MuJoCo's order, which is depth first (a body's id is larger
// than its parent's and a subtree's ids are contiguous), the order
// ModelBuilder::addJoint asks for.
//
// MuJoCo moves a body with joints j = 1 … n as (mj_kinematics)
//   X_body = X_parent · (body_pos, body_quat) · M_1 · … · M_n,
//   M_j = T(p_j) · R(a_j, qpos_j − qpos0_j) · T(−p_j)  (hinge; ball: R(quat)),
//   M_j = T(a_j · (qpos_j − qpos0_j))                  (slide),
// with the anchor p_j and the axis a_j in the body frame as the joints before
// have moved it. zwang's joint k is the joint frame (its placement in the
// previous frame) moved by q: the placement is T(p_j) · R(a_j, −qpos0_j) (a
// slide's T(−a_j qpos0_j)), which commutes with the motion about the same
// axis, so q is qpos itself; the frame after the joint is placed back by
// T(−p_j) (addJoint's child placement). Every joint but a body's last ends in
// a massless intermediate frame "<body>:<joint>".
#include "zwang/mjcf.hpp"

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <vector>

#include "model/loader_messages.hpp"
#include "mujoco/mujoco_model.hpp"

namespace zwang {
namespace {

using internal::fmt;
using internal::nameList;
using internal::Reporter;

// ---------------------------------------------------------------------------
// MuJoCo's compiler

// mj_loadXML and MuJoCo's global handlers are not ours to share between
// threads: one load at a time.
std::mutex& loadMutex() {
  static std::mutex mutex;
  return mutex;
}

// MuJoCo's default warning handler prints to stdout and appends to
// MUJOCO_LOG.TXT; while we load, its warnings are collected instead.
std::vector<std::string>& capturedWarnings() {
  static std::vector<std::string> warnings;
  return warnings;
}
void captureWarning(const char* text) { capturedWarnings().emplace_back(text ? text : ""); }

// The name of the document's root element ("" when there is none to read): mj_loadXML also takes URDF (<robot>),
// which MuJoCo's importer reads without what zwang reads from URDF (rotor inertias, mimic joints): refused here.
std::string rootElement(const std::string& text) {
  std::size_t at = 0;
  for (;;) {
    at = text.find('<', at);
    if (at == std::string::npos || at + 1 >= text.size()) return "";
    if (text.compare(at, 4, "<!--") == 0) {
      at = text.find("-->", at);
      if (at == std::string::npos) return "";
    } else if (text[at + 1] != '?' && text[at + 1] != '!') {
      const std::size_t end = text.find_first_of(" \t\r\n/>", at + 1);
      return text.substr(at + 1, end == std::string::npos ? std::string::npos : end - at - 1);
    }
    ++at;
  }
}

void requireMjcf(const Reporter& report, const std::string& text) {
  const std::string root = rootElement(text);
  if (!root.empty() && root != "mujoco")
    report.fail("the root element is <" + root + ">, not <mujoco>: not an MJCF file" +
                (root == "robot" ? " (a URDF: loadUrdfFile)" : ""));
}

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
using MjModelPtr = std::unique_ptr<mjModel, ModelDeleter>;

// MuJoCo's messages span lines ("Error: …\nObject name = …, line = 3"): one line, as every message of zwang's.
std::string oneLine(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '\n' || c == '\r' || c == '\t') {
      if (!out.empty() && out.back() != ' ') out += ' ';
    } else {
      out += c;
    }
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

// The compiled model and the warnings MuJoCo gave; ModelError with MuJoCo's message when it refuses the file.
// `vfs`: the text in memory (loadString) or null (a file on disk).
MjModelPtr compile(const Reporter& report, const std::string& file, const mjVFS* vfs,
                   std::vector<std::string>& warnings) {
  const std::lock_guard<std::mutex> lock(loadMutex());
  capturedWarnings().clear();
  struct Capture {  // MuJoCo's handler back however the load ends
    void (*saved)(const char*) = mju_user_warning;
    Capture() { mju_user_warning = captureWarning; }
    ~Capture() { mju_user_warning = saved; }
    Capture(const Capture&) = delete;
    Capture& operator=(const Capture&) = delete;
  };
  char error[2000] = "";
  MjModelPtr model;
  {
    const Capture capture;
    model.reset(mj_loadXML(file.c_str(), vfs, error, sizeof error));
  }
  warnings = capturedWarnings();
  if (!model) report.fail("MuJoCo refuses the model: " + (error[0] ? oneLine(error) : std::string("no message")));
  if (error[0]) warnings.push_back(oneLine(error));  // with a model, the buffer holds the compiler's warning
  return model;
}

// ---------------------------------------------------------------------------
// Reading the compiled model

Vec3 vec3(const mjtNum* v) { return Vec3(v[0], v[1], v[2]); }
Mat3 rotation(const mjtNum* quat) {  // MuJoCo's quaternions are w x y z
  return Eigen::Quaterniond(quat[0], quat[1], quat[2], quat[3]).normalized().toRotationMatrix();
}
std::string objectName(const mjModel* m, mjtObj type, int id, const char* fallback) {
  const char* name = mj_id2name(m, type, id);
  return name && name[0] ? std::string(name) : fallback + std::to_string(id);
}

// The warnings and settings the walk shares.
struct Loading {
  const mjModel* m;
  const Reporter& report;
  std::vector<ModelWarning> warnings;
  std::vector<std::string> frame_of_body;  // per body id, the zwang frame of its MuJoCo frame (empty: none)
  int base_body = -1;                      // the floating base's body id, −1 on a fixed base
  bool limits = true, frictionloss = true, passive = true, equality = true;  // what <flag> leaves enabled

  void unmapped(const std::string& message) { warnings.push_back({WarningCode::Unmapped, message}); }
};

// A compiled quaternion rotation() can use: MuJoCo keeps a zero or non-finite one as written (and its kinematics
// turns one below mjMINVAL into the identity, which Eigen's normalisation would not).
void requireQuaternion(const Loading& L, const mjtNum* quat, const std::string& what) {
  const Eigen::Map<const Eigen::Vector4d> q(quat);
  if (!q.allFinite() || q.norm() < mjMINVAL)
    L.report.fail(what + ": the quaternion (" + fmt(q[0]) + ", " + fmt(q[1]) + ", " + fmt(q[2]) + ", " + fmt(q[3]) +
                  ") is zero or not finite");
}

RigidInertia bodyInertia(const mjModel* m, int b) {
  const Mat3 R = rotation(m->body_iquat + 4 * b);
  const Mat3 I = R * vec3(m->body_inertia + 3 * b).asDiagonal() * R.transpose();
  return RigidInertia::fromMassComInertia(m->body_mass[b], vec3(m->body_ipos + 3 * b), I);
}

// Per-DOF values of a joint must agree (zwang keeps one per joint).
double perJointValue(const Loading& L, const mjtNum* values, int joint, const char* what) {
  const int first = L.m->jnt_dofadr[joint];
  const int count = L.m->jnt_type[joint] == mjJNT_FREE ? 6 : L.m->jnt_type[joint] == mjJNT_BALL ? 3 : 1;
  for (int k = 1; k < count; ++k)
    if (values[first + k] != values[first])
      L.report.fail("joint '" + objectName(L.m, mjOBJ_JOINT, joint, "joint") + "': " + what +
                    " differs between its DOFs: zwang has one value per joint");
  return values[first];
}

// A joint's drive, friction and limits.
void readJointData(Loading& L, int j, Joint& joint) {
  const mjModel* m = L.m;
  joint.rotor_inertia = perJointValue(L, m->dof_armature, j, "armature");
  if (L.frictionloss) {
    joint.breakaway_friction = perJointValue(L, m->dof_frictionloss, j, "frictionloss");
    joint.kinetic_friction = joint.breakaway_friction;  // default f_c = f: docs/friction.md, "The model of friction"
  }
  if (L.passive) joint.viscous_friction = perJointValue(L, m->dof_damping, j, "damping");
  if (m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE) {
    if (m->jnt_limited[j] && L.limits) {
      joint.lower = m->jnt_range[2 * j];
      joint.upper = m->jnt_range[2 * j + 1];
    } else if (m->jnt_type[j] == mjJNT_HINGE) {
      joint.type = JointType::Continuous;
    }
  } else if (m->jnt_type[j] == mjJNT_BALL && m->jnt_limited[j] && L.limits) {
    L.unmapped("joint '" + joint.name + "': the cone limit of a ball joint (range " + fmt(m->jnt_range[2 * j + 1]) +
               ") is not mapped: zwang's spherical joints have no limits");
  }
  if (m->jnt_stiffness[j] != 0.0 && L.passive)
    L.unmapped("joint '" + joint.name + "': its spring (stiffness " + fmt(m->jnt_stiffness[j]) +
               ") is not mapped: zwang models no joint springs");
}

// Joint j of body b: its placement in the frame before it (X_body first for the body's first joint).
Joint makeJoint(Loading& L, int j, const Transform& before) {
  const mjModel* m = L.m;
  Joint joint;
  joint.name = objectName(m, mjOBJ_JOINT, j, "joint");
  const Vec3 anchor = vec3(m->jnt_pos + 3 * j);
  const Vec3 axis = vec3(m->jnt_axis + 3 * j).normalized();
  const double ref = m->qpos0[m->jnt_qposadr[j]];
  Transform at_anchor = Transform::translation(anchor);
  switch (m->jnt_type[j]) {
    case mjJNT_HINGE:
      joint.type = JointType::Revolute;
      at_anchor = Transform::fromPose(Eigen::AngleAxisd(-ref, axis).toRotationMatrix(), anchor);
      break;
    case mjJNT_SLIDE:
      joint.type = JointType::Prismatic;
      at_anchor = Transform::translation(anchor - ref * axis);
      break;
    case mjJNT_BALL: joint.type = JointType::Spherical; break;
    default:
      L.report.fail("joint '" + joint.name + "': a free joint below the world's children (MuJoCo takes none there)");
  }
  joint.axis = axis;
  joint.placement = at_anchor * before;  // ʲX_prev = ʲX_at · ᵃᵗX_prev
  readJointData(L, j, joint);
  return joint;
}

// A free joint on a child of the world that is not the floating base: zwang's free joint from the world.
Joint makeFreeJoint(Loading& L, int j) {
  Joint joint;
  joint.name = objectName(L.m, mjOBJ_JOINT, j, "joint");
  joint.type = JointType::Free;  // qpos is the body's pose in the world: the joint frame is the world's
  readJointData(L, j, joint);
  if (joint.rotor_inertia != 0.0)
    L.unmapped("joint '" + joint.name + "': armature " + fmt(joint.rotor_inertia) +
               " on a free joint is zwang's rotor inertia on the body-frame velocity; MuJoCo's acts on the "
               "world-axes velocity (the dynamics differ by armature · ω × v, docs/mujoco.md)");
  return joint;
}

// Body b with its joints (the chain of intermediate frames) or welded to its parent.
void addBody(Loading& L, ModelBuilder& builder, int b) {
  const mjModel* m = L.m;
  const std::string name = objectName(m, mjOBJ_BODY, b, "body");
  const std::string parent = L.frame_of_body[static_cast<std::size_t>(m->body_parentid[b])];
  if (parent.empty())
    L.report.fail("body '" + name + "' hangs from the world of a floating-base model: zwang's world is no frame then");
  requireQuaternion(L, m->body_quat + 4 * b, "body '" + name + "': its orientation");
  requireQuaternion(L, m->body_iquat + 4 * b, "body '" + name + "': its inertia's orientation");
  const Transform X_body = Transform::fromPose(rotation(m->body_quat + 4 * b), vec3(m->body_pos + 3 * b));
  const RigidInertia inertia = bodyInertia(m, b);
  const int count = m->body_jntnum[b];
  L.frame_of_body[static_cast<std::size_t>(b)] = name;
  try {
    if (count == 0) {
      builder.addFixedFrame(name, parent, X_body, inertia);
      return;
    }
    std::string previous = parent;
    for (int k = 0; k < count; ++k) {
      const int j = m->body_jntadr[b] + k;
      const bool last = k + 1 == count;
      if (m->jnt_type[j] == mjJNT_FREE) {  // MuJoCo: a free joint is its body's only joint, on a child of the world
        builder.addJoint(makeFreeJoint(L, j), name, inertia, previous);
        return;
      }
      const Joint joint = makeJoint(L, j, k == 0 ? X_body : Transform::identity());
      const std::string frame = last ? name : name + ":" + joint.name;
      builder.addJoint(joint, frame, last ? inertia : RigidInertia{}, previous,
                       Transform::translation(-vec3(m->jnt_pos + 3 * j)));
      previous = frame;
    }
  } catch (const ModelError& e) {
    L.report.fail(e.what());
  }
}

// The floating base: its body is the root link; what the free joint carries is not mapped.
void addFloatingBase(Loading& L, ModelBuilder& builder) {
  const mjModel* m = L.m;
  const int b = L.base_body;
  const int j = m->body_jntadr[b];
  if (m->body_jntnum[b] != 1) L.report.fail("the floating base's body has more joints than its free joint");
  const int dof = m->jnt_dofadr[j];
  for (int k = 0; k < 6; ++k)
    if (m->dof_armature[dof + k] != 0.0 || m->dof_frictionloss[dof + k] != 0.0 || m->dof_damping[dof + k] != 0.0) {
      L.unmapped("joint '" + objectName(m, mjOBJ_JOINT, j, "joint") +
                 "': the floating base's armature, frictionloss and damping are not mapped (zwang's root joint is "
                 "unactuated and frictionless)");
      break;
    }
  requireQuaternion(L, m->body_iquat + 4 * b,
                    "body '" + objectName(m, mjOBJ_BODY, b, "body") + "': its inertia's orientation");
  try {
    builder.setBase(BaseType::Free);
    builder.addBaseLinkInertia(bodyInertia(m, b));
  } catch (const ModelError& e) {
    L.report.fail(e.what());
  }
  L.frame_of_body[static_cast<std::size_t>(b)] = objectName(m, mjOBJ_BODY, b, "body");
}

// Sites: frames on their bodies (a name a body has already is skipped, said).
void addSites(Loading& L, ModelBuilder& builder) {
  const mjModel* m = L.m;
  std::vector<std::string> skipped;
  for (int s = 0; s < m->nsite; ++s) {
    const std::string name = objectName(m, mjOBJ_SITE, s, "site");
    const std::string& body = L.frame_of_body[static_cast<std::size_t>(m->site_bodyid[s])];
    requireQuaternion(L, m->site_quat + 4 * s, "site '" + name + "': its orientation");
    const Transform X = Transform::fromPose(rotation(m->site_quat + 4 * s), vec3(m->site_pos + 3 * s));
    if (body.empty() || mj_name2id(m, mjOBJ_BODY, name.c_str()) >= 0) {
      skipped.push_back(name);
      continue;
    }
    try {
      builder.addFixedFrame(name, body, X);
    } catch (const ModelError&) {
      skipped.push_back(name);  // a name an intermediate frame has
    }
  }
  if (!skipped.empty())
    L.unmapped("sites " + nameList(skipped) +
               " are not frames: a body or an intermediate frame has the name, or the site is on the world of a "
               "floating base");
}

// ---------------------------------------------------------------------------
// What zwang does not model

std::vector<std::string> names(const mjModel* m, mjtObj type, int count, const char* fallback) {
  std::vector<std::string> out;
  for (int k = 0; k < count; ++k) out.push_back(objectName(m, type, k, fallback));
  return out;
}

// A joint equality q1 = qpos0_1 + c0 + c1 (q2 − qpos0_2) between one-DOF joints → a mimic joint; false if not one.
bool addMimic(Loading& L, ModelBuilder& builder, int e) {
  const mjModel* m = L.m;
  const int j1 = m->eq_obj1id[e], j2 = m->eq_obj2id[e];
  const mjtNum* c = m->eq_data + mjNEQDATA * e;
  const auto oneDof = [m](int j) { return j >= 0 && (m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE); };
  if (m->eq_type[e] != mjEQ_JOINT || !m->eq_active[e] || !oneDof(j1) || !oneDof(j2) || c[2] != 0.0 || c[3] != 0.0 ||
      c[4] != 0.0)
    return false;
  const double q1 = m->qpos0[m->jnt_qposadr[j1]], q2 = m->qpos0[m->jnt_qposadr[j2]];
  try {
    builder.setMimic(objectName(m, mjOBJ_JOINT, j1, "joint"), objectName(m, mjOBJ_JOINT, j2, "joint"), c[1],
                     q1 + c[0] - c[1] * q2);
  } catch (const ModelError& error) {
    L.report.fail(error.what());
  }
  return true;
}

void warnUnmapped(Loading& L, ModelBuilder& builder) {
  const mjModel* m = L.m;
  if (m->ntendon > 0)
    L.unmapped("tendons " + nameList(names(m, mjOBJ_TENDON, m->ntendon, "tendon")) + " are not mapped");
  if (m->nu > 0)
    L.unmapped("actuators " + nameList(names(m, mjOBJ_ACTUATOR, m->nu, "actuator")) +
               " are not mapped (their gears, gains and biases): zwang takes joint torques");
  if (m->ngeom > 0)
    L.unmapped(std::to_string(m->ngeom) +
               " geoms are not mapped: zwang models no contacts (a contact is a task "
               "constraint) and takes the inertias MuJoCo compiled");
  std::vector<std::string> equalities;
  for (int e = 0; e < m->neq; ++e)
    if (!L.equality || !addMimic(L, builder, e)) equalities.push_back(objectName(m, mjOBJ_EQUALITY, e, "equality"));
  if (!equalities.empty())
    L.unmapped("equality constraints " + nameList(equalities) +
               " are not mapped (only an active joint equality with a degree-1 polynomial is: a mimic joint)");
  const int off = m->opt.disableflags;
  if (off & (mjDSBL_LIMIT | mjDSBL_FRICTIONLOSS | mjDSBL_PASSIVE | mjDSBL_EQUALITY | mjDSBL_CONSTRAINT))
    L.unmapped(
        "<option><flag> disables some of limits, frictionloss, passive forces and equalities: those are not "
        "mapped");
}

// ---------------------------------------------------------------------------
// The whole load

void refuseWarnings(const Reporter& report, const Model& model) {
  std::string all;
  for (const ModelWarning& w : model.warnings())
    all += (all.empty() ? "" : "; ") + w.message.substr(report.source().size() + 2);  // without "<source>: "
  if (!all.empty())
    report.fail("refused in strict mode (" + std::to_string(model.warnings().size()) + " warning" +
                (model.warnings().size() == 1 ? "" : "s") + "): " + all);
}

Loading settings(const mjModel* m, const Reporter& report) {
  Loading L{m, report, {}, std::vector<std::string>(static_cast<std::size_t>(m->nbody)), internal::floatingBaseBody(m)};
  const int off = m->opt.disableflags;
  L.limits = !(off & (mjDSBL_LIMIT | mjDSBL_CONSTRAINT));
  L.frictionloss = !(off & (mjDSBL_FRICTIONLOSS | mjDSBL_CONSTRAINT));
  L.equality = !(off & (mjDSBL_EQUALITY | mjDSBL_CONSTRAINT));
  L.passive = !(off & mjDSBL_PASSIVE);
  return L;
}

MjcfModel build(const Reporter& report, const mjModel* m, const std::vector<std::string>& mujoco_warnings,
                const MjcfOptions& options) {
  Loading L = settings(m, report);
  if (m->nv == 0) report.fail("the model has no joint: nothing moves");
  if (!(m->opt.disableflags & mjDSBL_GRAVITY) && !vec3(m->opt.gravity).allFinite())
    report.fail("<option gravity> (" + fmt(m->opt.gravity[0]) + ", " + fmt(m->opt.gravity[1]) + ", " +
                fmt(m->opt.gravity[2]) + ") is not finite");
  const std::string world = objectName(m, mjOBJ_BODY, 0, "body");
  const std::string model_name = m->names[0] ? std::string(m->names) : "robot";  // <mujoco model> is names' first
  ModelBuilder builder(model_name, L.base_body < 0 ? world : objectName(m, mjOBJ_BODY, L.base_body, "body"));
  if (L.base_body < 0)
    L.frame_of_body[0] = world;
  else
    addFloatingBase(L, builder);
  for (int b = 1; b < m->nbody; ++b)
    if (b != L.base_body) addBody(L, builder, b);
  addSites(L, builder);
  warnUnmapped(L, builder);
  for (const std::string& w : mujoco_warnings) builder.addWarning(WarningCode::Mujoco, "MuJoCo: " + w);
  for (const ModelWarning& w : L.warnings) builder.addWarning(w.code, w.message);
  builder.prefixWarnings(report.source() + ": ");
  MjcfModel out;
  try {
    out.model = builder.build();
  } catch (const ModelError& e) {
    report.fail(e.what());
  }
  if (options.strict) refuseWarnings(report, out.model);
  out.gravity = (m->opt.disableflags & mjDSBL_GRAVITY) ? Vec3::Zero() : vec3(m->opt.gravity);
  return out;
}

struct VfsDeleter {
  void operator()(mjVFS* vfs) const {
    mj_deleteVFS(vfs);
    delete vfs;
  }
};

}  // namespace

MjcfModel readMjcfString(const std::string& xml, const MjcfOptions& options) {
  const Reporter report("<string>");
  static const char kFile[] = "zwang_model.xml";
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);  // a large fixed-size name table: not on the stack
  mj_defaultVFS(vfs.get());
  // One byte more than the text: the buffer ends in '\0' whether or not the parser relies on a terminator.
  const int size = static_cast<int>(xml.size()) + 1;
  if (xml.size() + 1 > static_cast<std::size_t>(std::numeric_limits<int>::max()) ||
      mj_makeEmptyFileVFS(vfs.get(), kFile, size) != 0)
    report.fail("MuJoCo's virtual file system cannot hold the text");
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), kFile)], xml.c_str(), static_cast<std::size_t>(size));
  requireMjcf(report, xml);
  std::vector<std::string> warnings;
  const MjModelPtr m = compile(report, kFile, vfs.get(), warnings);
  return build(report, m.get(), warnings, options);
}

MjcfModel readMjcfFile(const std::string& path, const MjcfOptions& options) {
  const Reporter report(path);
  std::ifstream in = report.open();
  std::ostringstream content;
  content << in.rdbuf();
  requireMjcf(report, content.str());
  std::vector<std::string> warnings;
  const MjModelPtr m = compile(report, path, nullptr, warnings);
  return build(report, m.get(), warnings, options);
}

Model loadMjcfFile(const std::string& path, const MjcfOptions& options) { return readMjcfFile(path, options).model; }

Model loadMjcfString(const std::string& xml, const MjcfOptions& options) { return readMjcfString(xml, options).model; }

}  // namespace zwang
