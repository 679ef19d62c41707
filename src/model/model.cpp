#include "zwang/model.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "model/validate.hpp"

namespace zwang {

const char* toString(JointType type) {
  switch (type) {
    case JointType::Revolute: return "revolute";
    case JointType::Continuous: return "continuous";
    case JointType::Prismatic: return "prismatic";
    case JointType::Spherical: return "spherical";
    case JointType::Planar: return "planar";
    case JointType::Free: return "free";
  }
  return "unknown";
}

namespace {
// The rotation a unit quaternion (w, x, y, z) makes: child axes in the joint frame.
Mat3 rotationOfQuaternion(double w, double x, double y, double z) {
  Mat3 R;
  R << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),   //
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  return R;
}
}  // namespace

Transform Joint::transform(const double* q) const {
  // ʲX_parent = X_J(q) · X_T: X_J is the child's pose (rotation R, origin p)
  // in the joint frame, so E = Rᵀ E_T and the origin is r_T + E_Tᵀ p.
  switch (type) {
    case JointType::Revolute:
    case JointType::Continuous:
    case JointType::Prismatic: return transform(q[0]);
    case JointType::Spherical:
      return {rotationOfQuaternion(q[0], q[1], q[2], q[3]).transpose() * placement.E, placement.r};
    case JointType::Planar: {
      const double c = std::cos(q[2]), s = std::sin(q[2]);
      Mat3 Rt;  // Rz(ψ)ᵀ
      Rt << c, s, 0, -s, c, 0, 0, 0, 1;
      return {Rt * placement.E, placement.r + placement.E.transpose() * Vec3(q[0], q[1], 0.0)};
    }
    case JointType::Free:
      return {rotationOfQuaternion(q[3], q[4], q[5], q[6]).transpose() * placement.E,
              placement.r + placement.E.transpose() * Vec3(q[0], q[1], q[2])};
  }
  return placement;
}

namespace {

std::string knownNames(const std::vector<std::string>& names) {
  std::ostringstream out;
  for (std::size_t k = 0; k < names.size(); ++k) out << (k ? ", " : "") << "'" << names[k] << "'";
  return out.str();
}

bool finite(const Transform& X) { return X.E.allFinite() && X.r.allFinite(); }

// Bit for bit the identity: then a placement changes nothing and is skipped, so
// what a user gives in the body frame stays exactly as given.
bool exactlyIdentity(const Transform& X) { return X.E.isIdentity(0.0) && X.r.isZero(0.0); }

}  // namespace

int Model::jointIndex(const std::string& name) const {
  for (std::size_t j = 0; j < joints_.size(); ++j)
    if (joints_[j].name == name) return static_cast<int>(j);
  std::vector<std::string> names;  // only on the error path: a lookup that succeeds allocates nothing
  for (const Joint& joint : joints_) names.push_back(joint.name);
  throw ModelError("model '" + name_ + "' has no moving joint '" + name + "' (joints: " + knownNames(names) + ")");
}

bool Model::hasJoint(const std::string& name) const {
  for (const Joint& j : joints_)
    if (j.name == name) return true;
  return false;
}

bool Model::hasFrame(const std::string& name) const {
  for (const Frame& f : frames_)
    if (f.name == name) return true;
  return false;
}

int Model::frameIndex(const std::string& name) const {
  for (std::size_t f = 0; f < frames_.size(); ++f)
    if (frames_[f].name == name) return static_cast<int>(f);
  std::vector<std::string> names;  // only on the error path
  for (const Frame& frame : frames_) names.push_back(frame.name);
  throw ModelError("model '" + name_ + "' has no frame '" + name + "' (frames: " + knownNames(names) + ")");
}

const char* toString(WarningCode code) {
  switch (code) {
    case WarningCode::PointMass: return "point_mass";
    case WarningCode::PlaceholderInertia: return "placeholder_inertia";
    case WarningCode::TriangleInequality: return "triangle_inequality";
    case WarningCode::PlaceholderLimits: return "placeholder_limits";
    case WarningCode::IgnoredLimits: return "ignored_limits";
    case WarningCode::MassBeyondTip: return "mass_beyond_tip";
    case WarningCode::MassOffChain: return "mass_off_chain";
    case WarningCode::PayloadAttached: return "payload_attached";
    case WarningCode::MimicLocked: return "mimic_locked";
    case WarningCode::Urdfdom: return "urdfdom";
    case WarningCode::FixedBaseContact: return "fixed_base_contact";
    case WarningCode::Unmapped: return "unmapped";
    case WarningCode::Mujoco: return "mujoco";
  }
  return "unknown";
}

namespace {

std::string number(double x) {
  std::ostringstream out;
  out << std::setprecision(6) << x;
  return out.str();
}

std::string momentsText(const Vec3& moments) {
  return number(moments(0)) + ", " + number(moments(1)) + ", " + number(moments(2));
}

// The densest element (osmium, 22 590 kg/m³): a body of mass m is at least a
// ball of radius R = (3m / 4πρ)^⅓, and a ball has the smallest Σ r² dm for its
// volume, (3/5) m R². Σ r² dm is half the trace of the COM inertia, so a
// smaller half-trace cannot belong to a real body of that mass.
constexpr double kDensestMatter = 22590.0;

double smallestHalfTrace(double mass) {
  const double radius = std::cbrt(3.0 * mass / (4.0 * 3.14159265358979323846 * kDensestMatter));
  return 0.6 * mass * radius * radius;
}

// What a physical but doubtful inertia gets (mass > 0, moments ≥ −tolerance).
std::vector<ModelWarning> doubts(const std::string& where, double mass, const Vec3& moments, double tolerance) {
  const std::string figures = " (mass " + number(mass) + " kg, principal moments " + momentsText(moments) + " kg·m²)";
  if (moments.maxCoeff() <= tolerance)
    return {{WarningCode::PointMass, where + ": a point mass: its rotational inertia is zero to rounding" + figures +
                                         "; it turns only through its distance from the joint axes"}};
  if (moments(0) + moments(1) < moments(2) - tolerance)
    return {{WarningCode::TriangleInequality,
             where + ": inertia violates the triangle inequality, " + number(moments(0)) + " + " + number(moments(1)) +
                 " < " + number(moments(2)) + figures + "; no real body has these moments, they are used as given"}};
  if (0.5 * moments.sum() < smallestHalfTrace(mass))
    return {{WarningCode::PlaceholderInertia,
             where + ": inertia too small for the mass: a body this compact would be denser than osmium" + figures +
                 "; a placeholder? it is used as given"}};
  return {};
}

}  // namespace

// Each step from URDF numbers to the COM inertia (rotation into the link frame,
// Ī = I_c − m·c×c×, merging through welded frames, back to I_c = Ī + m·c×c×,
// the eigen-solver) errs by a few ulps of the largest term it handles; 1024
// ulps of the whole scale covers hundreds of such steps and is still 2e-13 of
// it, far below the moments of any real link.
double validate::roundingTolerance(double scale) { return 1024.0 * std::numeric_limits<double>::epsilon() * scale; }

std::vector<ModelWarning> validate::rigidInertia(const std::string& where, double mass, const Vec3& com,
                                                 const Mat3& I_com, double rounding_scale) {
  if (!std::isfinite(mass)) throw ModelError(where + ": mass is not finite");
  if (!com.allFinite()) throw ModelError(where + ": centre of mass is not finite");
  if (!I_com.allFinite()) throw ModelError(where + ": inertia is not finite");
  if (mass < 0.0) throw ModelError(where + ": mass " + std::to_string(mass) + " is negative");
  // Beyond these a solve's products (m·|c|²·ω², sums over the chain) lose the
  // other links' figures in rounding or leave the range of double.
  if (mass > kMaxMass)
    throw ModelError(where + ": mass " + number(mass) + " kg is above " + number(kMaxMass) +
                     " kg, the heaviest link zwang accepts (a typo?)");
  if (I_com.cwiseAbs().maxCoeff() > kMaxMoment)
    throw ModelError(where + ": inertia entry " + number(I_com.cwiseAbs().maxCoeff()) + " kg·m² is above " +
                     number(kMaxMoment) + " kg·m², the largest zwang accepts (a typo?)");
  if ((I_com - I_com.transpose()).cwiseAbs().maxCoeff() > 1e-12 * (1.0 + I_com.cwiseAbs().maxCoeff()))
    throw ModelError(where + ": inertia is not symmetric");
  const Vec3 moments = Eigen::SelfAdjointEigenSolver<Mat3>(I_com, Eigen::EigenvaluesOnly).eigenvalues();
  const double tolerance = roundingTolerance(std::max(rounding_scale, I_com.cwiseAbs().sum()));
  if (moments.minCoeff() < -tolerance)
    throw ModelError(where + ": inertia is not positive semi-definite: principal moment " + number(moments.minCoeff()) +
                     " kg·m² is negative (principal moments " + momentsText(moments) + "; rounding allows ±" +
                     number(tolerance) + ")");
  if (mass == 0.0) return {};  // a massless link: any semi-definite inertia (e.g. a rotor) is fine
  return doubts(where, mass, moments, tolerance);
}

std::vector<ModelWarning> validate::rigidInertia(const std::string& where, const RigidInertia& inertia) {
  // Ī holds m·|c|² on its diagonal: the scale I_c was recovered from.
  const double scale = inertia.Ibar.allFinite() ? inertia.Ibar.cwiseAbs().sum() : 0.0;
  return rigidInertia(where, inertia.mass, inertia.com(), inertia.inertiaAboutCom(), scale);
}

ModelBuilder::ModelBuilder(std::string robot_name, std::string base_frame) {
  model_.name_ = std::move(robot_name);
  model_.frames_.push_back(Frame{std::move(base_frame), 0, Transform{}});
  model_.frame_links_.push_back(0);
  model_.link_frames_.push_back(0);
}

ModelBuilder::ModelBuilder(const Model& model) : model_(model) {}

namespace {
// The type-specific checks of a joint's data; `where` names it.
void checkJointType(const std::string& where, Joint& joint) {
  const bool one_dof = joint.nv() == 1;
  if (one_dof) {
    if (!joint.axis.allFinite() || joint.axis.norm() < 1e-9)
      throw ModelError(where + ": axis must be a finite non-zero vector");
    joint.axis.normalize();
    return;
  }
  // A multi-DOF joint has no axis and, in zwang, no position limits: a
  // spherical joint's cone limit is a later feature (docs/conventions.md, "Joint types").
  if (std::isfinite(joint.lower) || std::isfinite(joint.upper))
    throw ModelError(where + ": a " + toString(joint.type) + " joint takes no position limits (only one-DOF " +
                     "joints have them; a spherical joint's cone limit is not supported yet)");
  if (joint.mimic.active()) throw ModelError(where + ": only one-DOF joints can mimic another");
}
}  // namespace

ModelBuilder& ModelBuilder::addJoint(const Joint& joint_in, const std::string& child_frame,
                                     const RigidInertia& child_inertia, const std::string& parent_frame,
                                     const Transform& child_placement) {
  const std::string where = "joint '" + joint_in.name + "'";
  if (joint_in.name.empty()) throw ModelError("a moving joint needs a name");
  for (const Joint& j : model_.joints_)
    if (j.name == joint_in.name) throw ModelError(where + ": a joint of that name exists already");
  if (model_.hasFrame(child_frame)) throw ModelError(where + ": frame '" + child_frame + "' exists already");
  const int last_link = static_cast<int>(model_.link_parents_.size()) - 1;
  int parent_link = last_link;
  if (!parent_frame.empty()) {
    parent_link = model_.frame_links_[static_cast<std::size_t>(model_.frameIndex(parent_frame))];
    // Depth first: the parent is on the path from the last link to the root, so
    // that every subtree stays a contiguous range of bodies (model.hpp).
    int l = last_link;
    while (l > parent_link) l = model_.link_parents_[static_cast<std::size_t>(l)];
    if (l != parent_link)
      throw ModelError(where + ": parent frame '" + parent_frame + "' is on a branch that is already complete (add " +
                       "joints depth first: the parent must be the last body added or one of its ancestors)");
  }
  Joint joint = joint_in;
  checkJointType(where, joint);
  if (!finite(joint.placement)) throw ModelError(where + ": origin is not finite");
  if (!finite(child_placement)) throw ModelError(where + ": child link placement is not finite");
  const struct {
    const char* field;
    double value;
  } non_negative[] = {{"rotor inertia", joint.rotor_inertia},
                      {"friction", joint.breakaway_friction},
                      {"kinetic friction", joint.kinetic_friction},
                      {"viscous friction", joint.viscous_friction}};
  for (const auto& p : non_negative) {
    if (!std::isfinite(p.value)) throw ModelError(where + ": " + p.field + " is not finite");
    if (p.value < 0.0) throw ModelError(where + ": " + p.field + " " + std::to_string(p.value) + " is negative");
    if (p.value > validate::kMaxJointCoefficient)
      throw ModelError(where + ": " + p.field + " " + number(p.value) + " is above " +
                       number(validate::kMaxJointCoefficient) + ", the largest zwang accepts (a typo?)");
  }
  if (std::isnan(joint.lower) || std::isnan(joint.upper)) throw ModelError(where + ": limit is NaN");
  if (joint.lower > joint.upper) throw ModelError(where + ": lower limit exceeds upper limit");
  if (std::isnan(joint.effort_limit) || joint.effort_limit < 0.0)
    throw ModelError(where + ": effort limit must be non-negative");
  if (std::isnan(joint.velocity_limit) || joint.velocity_limit < 0.0)
    throw ModelError(where + ": velocity limit must be non-negative");
  const int link = last_link + 1;
  checkLinkInertia(child_frame, link, child_inertia);

  // The joint's placement is relative to the parent link's frame; rebase it on
  // the parent body's frame (they differ when the parent link was merged in).
  if (!parent_frame.empty())
    joint.placement = joint.placement * model_.frame(model_.frameIndex(parent_frame)).placement;

  model_.joints_.push_back(joint);
  model_.link_parents_.push_back(parent_link);
  // The link's inertia in the body frame (left bit for bit as given when the frames coincide).
  const bool same_frame = exactlyIdentity(child_placement);
  model_.link_inertias_.push_back(same_frame ? child_inertia
                                             : spatial::inverseTransformInertia(child_placement, child_inertia));
  model_.frames_.push_back(Frame{child_frame, 0, child_placement});
  model_.frame_links_.push_back(link);
  model_.link_frames_.push_back(static_cast<int>(model_.frames_.size()) - 1);
  return *this;
}

ModelBuilder& ModelBuilder::addFixedFrame(const std::string& name, const std::string& parent_frame,
                                          const Transform& placement, const RigidInertia& inertia) {
  const std::string where = "link '" + name + "'";
  if (model_.hasFrame(name)) throw ModelError(where + ": a frame of that name exists already");
  if (!finite(placement)) throw ModelError(where + ": origin of its fixed joint is not finite");
  const int parent = model_.frameIndex(parent_frame);
  const int link = model_.frame_links_[static_cast<std::size_t>(parent)];
  checkLinkInertia(name, link, inertia);
  // ᶠX_body = ᶠX_parent · ᵖX_body
  const Frame frame{name, 0, placement * model_.frame(parent).placement};
  model_.link_inertias_[static_cast<std::size_t>(link)] += spatial::inverseTransformInertia(frame.placement, inertia);
  model_.frames_.push_back(frame);
  model_.frame_links_.push_back(link);
  return *this;
}

void ModelBuilder::checkLinkInertia(const std::string& link_name, int link, const RigidInertia& inertia) {
  // The base never moves: what is welded to it does not enter the dynamics, so
  // its flaws cannot change an answer (and the verdict must not depend on
  // which link the user picks as the root).
  if (link == 0) return;
  for (const ModelWarning& w : validate::rigidInertia("link '" + link_name + "'", inertia))
    addWarning(w.code, w.message);
}

ModelBuilder& ModelBuilder::addWarning(WarningCode code, const std::string& message) {
  for (const ModelWarning& w : model_.warnings_)
    if (w.message == message) return *this;
  model_.warnings_.push_back({code, message});
  return *this;
}

ModelBuilder& ModelBuilder::prefixWarnings(const std::string& prefix) {
  for (ModelWarning& w : model_.warnings_) w.message = prefix + w.message;
  return *this;
}

Joint& ModelBuilder::jointNamed(const std::string& name) {
  return model_.joints_[static_cast<std::size_t>(model_.jointIndex(name))];
}

ModelBuilder& ModelBuilder::setRotorInertia(const std::string& joint, double value) {
  if (!std::isfinite(value) || value < 0.0)
    throw ModelError("joint '" + joint + "': rotor inertia must be finite and non-negative");
  if (value > validate::kMaxJointCoefficient)
    throw ModelError("joint '" + joint + "': rotor inertia " + number(value) + " is above " +
                     number(validate::kMaxJointCoefficient) + ", the largest zwang accepts (a typo?)");
  jointNamed(joint).rotor_inertia = value;
  return *this;
}

ModelBuilder& ModelBuilder::setFriction(const std::string& joint, double breakaway, double kinetic, double viscous) {
  for (double v : {breakaway, kinetic, viscous})
    if (!std::isfinite(v) || v < 0.0)
      throw ModelError("joint '" + joint +
                       "': breakaway, kinetic and viscous friction must be finite and non-negative");
  for (double v : {breakaway, kinetic, viscous})
    if (v > validate::kMaxJointCoefficient)
      throw ModelError("joint '" + joint + "': friction " + number(v) + " is above " +
                       number(validate::kMaxJointCoefficient) + ", the largest zwang accepts (a typo?)");
  Joint& j = jointNamed(joint);
  j.breakaway_friction = breakaway;
  j.kinetic_friction = kinetic;
  j.viscous_friction = viscous;
  return *this;
}

const char* toString(BaseType type) {
  switch (type) {
    case BaseType::Fixed: return "fixed";
    case BaseType::Free: return "free";
    case BaseType::Planar: return "planar";
  }
  return "unknown";
}

ModelBuilder& ModelBuilder::addBaseLinkInertia(const RigidInertia& inertia) {
  // Throws on an impossible inertia; its warnings come with build(), when the base floats.
  (void)validate::rigidInertia("link '" + model_.frames_[0].name + "'", inertia);
  const Transform& link = model_.frames_[0].placement;  // the root link on its body (setBase)
  const bool same_frame = exactlyIdentity(link);
  model_.link_inertias_[0] += same_frame ? inertia : spatial::inverseTransformInertia(link, inertia);
  return *this;
}

ModelBuilder& ModelBuilder::setBase(BaseType type, const Transform& placement, const Transform& root_link_placement) {
  if (model_.base_type_ != BaseType::Fixed)
    throw ModelError(std::string("the base already floats (a ") + toString(model_.base_type_) +
                     " joint under the root link '" + model_.frames_[0].name + "'): it cannot get a " + toString(type) +
                     " base as well");
  if (!finite(placement)) throw ModelError("base placement is not finite");
  if (type == BaseType::Free && !exactlyIdentity(placement))
    throw ModelError("a free base takes no placement (its pose is its configuration)");
  if (!finite(root_link_placement)) throw ModelError("root link placement is not finite");
  if (!exactlyIdentity(root_link_placement)) {
    if (type != BaseType::Planar)
      throw ModelError(std::string("a ") + toString(type) + " base takes no root link placement (only a planar one)");
    // What is attached already was placed on the root link's frame.
    const RigidInertia& own = model_.link_inertias_[0];
    if (model_.frames_.size() > 1 || own.mass != 0.0 || !own.h.isZero(0.0) || !own.Ibar.isZero(0.0))
      throw ModelError("setBase with a root link placement must come before anything is attached to the root link '" +
                       model_.frames_[0].name + "'");
  }
  model_.base_type_ = type;
  model_.base_placement_ = placement;
  model_.frames_[0].placement = root_link_placement;
  return *this;
}

ModelBuilder& ModelBuilder::setMimic(const std::string& joint, const std::string& leader, double multiplier,
                                     double offset) {
  const std::string where = "joint '" + joint + "' (mimic of '" + leader + "')";
  if (!model_.hasJoint(joint)) throw ModelError(where + ": the model has no joint '" + joint + "'");
  if (!model_.hasJoint(leader))
    throw ModelError(where + ": it mimics joint '" + leader + "', which is not a moving joint of the model");
  if (joint == leader) throw ModelError(where + ": a joint cannot mimic itself");
  if (!std::isfinite(multiplier) || !std::isfinite(offset))
    throw ModelError(where + ": multiplier and offset must be finite");
  if (jointNamed(joint).nv() != 1 || jointNamed(leader).nv() != 1)
    throw ModelError(where + ": only one-DOF joints can mimic or be mimicked");
  Mimic& mimic = jointNamed(joint).mimic;
  mimic.leader = model_.jointIndex(leader);
  mimic.multiplier = multiplier;
  mimic.offset = offset;
  return *this;
}

namespace {
// Follow each mimic joint's leaders to the first independent joint,
// composing the laws: q_m = a·(a'·q_l + b') + b. A cycle is refused, naming it.
void resolveMimicChains(std::vector<Joint>& joints, std::vector<int>& mimic_joints) {
  const std::vector<Joint> direct = joints;
  mimic_joints.clear();
  for (std::size_t m = 0; m < joints.size(); ++m) {
    if (!direct[m].mimic.active()) continue;
    Mimic law = direct[m].mimic;
    std::string path = "'" + direct[m].name + "'";
    for (std::size_t steps = 0; direct[static_cast<std::size_t>(law.leader)].mimic.active(); ++steps) {
      const Joint& next = direct[static_cast<std::size_t>(law.leader)];
      path += " → '" + next.name + "'";
      if (steps == joints.size() || law.leader == static_cast<int>(m))
        throw ModelError("mimic joints " + path + " form a cycle: no joint in it has an independent leader");
      law.offset += law.multiplier * next.mimic.offset;
      law.multiplier *= next.mimic.multiplier;
      law.leader = next.mimic.leader;
    }
    joints[m].mimic = law;
    mimic_joints.push_back(static_cast<int>(m));
  }
}
}  // namespace

void Model::followLeaders(Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> qd) const {
  for (const int m : mimic_joints_) {
    const Joint& joint = joints_[static_cast<std::size_t>(m)];
    const Joint& leader = joints_[static_cast<std::size_t>(joint.mimic.leader)];
    if (q.size() == nq()) q[joint.q_index] = joint.mimic.multiplier * q[leader.q_index] + joint.mimic.offset;
    if (qd.size() == nv()) qd[joint.v_index] = joint.mimic.multiplier * qd[leader.v_index];
  }
}

namespace {
// A joint's DOFs as the sweeps see them (model.hpp, Dof): each a rotation about
// or a translation along one axis. What a new joint type adds here, with its
// transform and its configuration operations (configuration.cpp).
void appendDofs(const Joint& joint, int index, std::vector<Dof>& dofs) {
  struct Axis {
    bool rotation, in_joint_frame;
    Vec3 axis;
    const char* coordinate;
  };
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  std::vector<Axis> axes;
  switch (joint.type) {
    case JointType::Revolute:
    case JointType::Continuous: axes = {{true, false, joint.axis, ""}}; break;
    case JointType::Prismatic: axes = {{false, false, joint.axis, ""}}; break;
    case JointType::Spherical: axes = {{true, false, x, "wx"}, {true, false, y, "wy"}, {true, false, z, "wz"}}; break;
    case JointType::Planar: axes = {{false, true, x, "x"}, {false, true, y, "y"}, {true, false, z, "yaw"}}; break;
    case JointType::Free:
      axes = {{false, false, x, "vx"}, {false, false, y, "vy"}, {false, false, z, "vz"},
              {true, false, x, "wx"},  {true, false, y, "wy"},  {true, false, z, "wz"}};
      break;
  }
  for (std::size_t k = 0; k < axes.size(); ++k) {
    Dof d;
    d.joint = index;
    d.index_in_joint = static_cast<int>(k);
    d.rotation = axes[k].rotation;
    d.in_joint_frame = axes[k].in_joint_frame;
    d.axis = axes[k].axis;
    d.rotor_inertia = joint.rotor_inertia;
    d.breakaway_friction = joint.breakaway_friction;
    d.kinetic_friction = joint.kinetic_friction;
    d.viscous_friction = joint.viscous_friction;
    d.lower = joint.lower;
    d.upper = joint.upper;
    d.name = axes.size() == 1 ? joint.name : joint.name + "." + axes[k].coordinate;
    dofs.push_back(d);
  }
}
}  // namespace

namespace {
// The products of Joint::transform(double) that depend on the placement alone (Model::OneDofTransform).
Model::OneDofTransform oneDofTransform(const Joint& joint) {
  Model::OneDofTransform form;
  if (!joint.isRevolute()) return form;
  for (int k = 0; k < 3; ++k) {
    const Vec3 e = joint.placement.E.col(k);
    form.axis_cross.col(k) = joint.axis.cross(e);
    form.axis_dot[k] = joint.axis.dot(e);
  }
  return form;
}
}  // namespace

void ModelBuilder::layOutBodies(Model& model) {
  // The root joint of a floating base: unactuated, frictionless, no limits.
  model.root_.clear();
  if (model.base_type_ != BaseType::Fixed) {
    Joint root;
    root.name = "root_joint";
    root.type = model.base_type_ == BaseType::Free ? JointType::Free : JointType::Planar;
    root.placement = model.base_placement_;
    model.root_.push_back(root);
  }
  model.all_joints_ = model.root_;
  model.all_joints_.insert(model.all_joints_.end(), model.joints_.begin(), model.joints_.end());
  // Coordinates and bodies in joint order: DOF k moves body k + 1.
  const std::size_t links = model.link_parents_.size();
  std::vector<int> link_body(links, 0);
  model.dofs_.clear();
  model.joint_start_.assign(1, 0);
  model.parents_.assign(1, -1);
  model.inertias_.assign(1, RigidInertia{});
  model.body_frames_.assign(1, model.link_frames_[0]);
  int nq = 0, nv = 0;
  const int first_link = model.root_.empty() ? 1 : 0;  // the root joint moves link 0
  for (std::size_t j = 0; j < model.all_joints_.size(); ++j) {
    Joint& joint = model.all_joints_[j];
    const auto link = static_cast<std::size_t>(static_cast<int>(j) + first_link);
    const int parent_body = link == 0 ? 0 : link_body[static_cast<std::size_t>(model.link_parents_[link])];
    joint.q_index = nq;
    joint.v_index = nv;
    appendDofs(joint, static_cast<int>(j) - static_cast<int>(model.root_.size()), model.dofs_);
    for (int k = 0; k < joint.nv(); ++k) {
      model.joint_start_.push_back(nv + 1);
      model.parents_.push_back(k == 0 ? parent_body : nv + k);
      model.inertias_.push_back(RigidInertia{});
      model.body_frames_.push_back(model.link_frames_[link]);
    }
    nq += joint.nq();
    nv += joint.nv();
    link_body[link] = nv;
    model.inertias_.back() = model.link_inertias_[link];
  }
  if (model.root_.empty()) model.inertias_[0] = model.link_inertias_[0];
  model.nq_ = nq;
  model.nv_ = nv;
  model.one_dof_transforms_.clear();
  for (const Joint& joint : model.all_joints_) model.one_dof_transforms_.push_back(oneDofTransform(joint));
  model.rotor_inertia_.resize(nv);
  for (int k = 0; k < nv; ++k) model.rotor_inertia_[k] = model.dofs_[static_cast<std::size_t>(k)].rotor_inertia;
  std::copy(model.all_joints_.begin() + static_cast<std::ptrdiff_t>(model.root_.size()), model.all_joints_.end(),
            model.joints_.begin());
  for (std::size_t f = 0; f < model.frames_.size(); ++f)
    model.frames_[f].body = link_body[static_cast<std::size_t>(model.frame_links_[f])];
  model.position_limits_.clear();
  for (std::size_t j = 0; j < model.joints_.size(); ++j) {
    const Joint& joint = model.joints_[j];
    if (std::isfinite(joint.lower) || std::isfinite(joint.upper))
      model.position_limits_.push_back({static_cast<int>(j), joint.q_index, joint.lower, joint.upper});
  }
  // Subtrees: bodies are in depth-first order, so each body's subtree ends
  // where the next body not below it starts.
  const int bodies = nv + 1;
  model.subtree_end_.assign(static_cast<std::size_t>(bodies), 0);
  model.is_chain_ = true;
  for (int b = bodies - 1; b >= 0; --b) {
    auto& end = model.subtree_end_[static_cast<std::size_t>(b)];
    end = std::max(end, b + 1);
    const int p = model.parents_[static_cast<std::size_t>(b)];
    if (p >= 0) {
      auto& parent_end = model.subtree_end_[static_cast<std::size_t>(p)];
      parent_end = std::max(parent_end, end);
      model.is_chain_ = model.is_chain_ && p == b - 1;
    }
  }
}

Model ModelBuilder::build() const {
  // Each link passed on its own; their sum is checked too, to rounding of the
  // merged figures, so no moving body reaches a solve with a negative moment.
  const auto links = static_cast<int>(model_.link_parents_.size());
  for (int l = 1; l < links; ++l) {
    const std::string link =
        model_.frames_[static_cast<std::size_t>(model_.link_frames_[static_cast<std::size_t>(l)])].name;
    validate::rigidInertia("body of link '" + link + "' (with the links welded to it)",
                           model_.link_inertias_[static_cast<std::size_t>(l)]);
  }
  // A moving body must carry inertia somewhere in its subtree (or its joint a
  // rotor inertia), or its acceleration is undetermined. The leaves are the
  // bodies left bare most often, so check from the leaves inward.
  std::vector<double> mass_beyond(static_cast<std::size_t>(links), 0.0);
  for (int l = links - 1; l >= 1; --l) {
    const auto link = static_cast<std::size_t>(l);
    const RigidInertia& I = model_.link_inertias_[link];
    mass_beyond[link] += I.mass + I.Ibar.trace();
    mass_beyond[static_cast<std::size_t>(model_.link_parents_[link])] += mass_beyond[link];
    const Joint& joint = model_.joints_[link - 1];
    if (mass_beyond[link] <= 0.0 && joint.rotor_inertia <= 0.0) {
      const std::string name = model_.frames_[static_cast<std::size_t>(model_.link_frames_[link])].name;
      throw ModelError("link '" + name + "': zero mass on a moving body with nothing beyond it (joint '" + joint.name +
                       "' would have no inertia to move)");
    }
  }
  if (model_.hasFloatingBase()) {
    // The root link moves: its inertia (and what is welded to it) now enters
    // the dynamics, so it gets the checks the other bodies got.
    const std::string link = model_.frames_[0].name;
    if (mass_beyond[0] + model_.link_inertias_[0].mass + model_.link_inertias_[0].Ibar.trace() <= 0.0)
      throw ModelError("link '" + link + "': a floating base with no mass anywhere in the robot");
  }
  Model model = model_;
  if (model.hasFloatingBase())
    for (const ModelWarning& w :
         validate::rigidInertia("base body of link '" + model.frames_[0].name + "' (with the links welded to it)",
                                model.link_inertias_[0]))
      model.warnings_.push_back(w);
  resolveMimicChains(model.joints_, model.mimic_joints_);
  layOutBodies(model);
  return model;
}

}  // namespace zwang
