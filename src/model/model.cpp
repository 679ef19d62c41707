#include "zwang/model.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace zwang {

const char* toString(JointType type) {
  switch (type) {
    case JointType::Revolute: return "revolute";
    case JointType::Continuous: return "continuous";
    case JointType::Prismatic: return "prismatic";
  }
  return "unknown";
}

namespace {

std::string knownNames(const std::vector<std::string>& names) {
  std::ostringstream out;
  for (std::size_t k = 0; k < names.size(); ++k) out << (k ? ", " : "") << "'" << names[k] << "'";
  return out.str();
}

bool finite(const Transform& X) { return X.E.allFinite() && X.r.allFinite(); }

}  // namespace

int Model::jointIndex(const std::string& name) const {
  for (int j = 0; j < dof(); ++j)
    if (joints_[static_cast<std::size_t>(j)].name == name) return j;
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
    case WarningCode::MassBeyondTip: return "mass_beyond_tip";
    case WarningCode::MassOffChain: return "mass_off_chain";
    case WarningCode::PayloadAttached: return "payload_attached";
    case WarningCode::MimicLocked: return "mimic_locked";
    case WarningCode::Urdfdom: return "urdfdom";
    case WarningCode::FixedBaseContact: return "fixed_base_contact";
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
  model_.inertias_.push_back(RigidInertia{});
  model_.frames_.push_back(Frame{std::move(base_frame), 0, Transform{}});
  model_.body_frames_.push_back(0);
}

ModelBuilder::ModelBuilder(const Model& model) : model_(model) {}

ModelBuilder& ModelBuilder::addJoint(const Joint& joint_in, const std::string& child_frame,
                                     const RigidInertia& child_inertia, const std::string& parent_frame) {
  const std::string where = "joint '" + joint_in.name + "'";
  if (joint_in.name.empty()) throw ModelError("a moving joint needs a name");
  for (const Joint& j : model_.joints_)
    if (j.name == joint_in.name) throw ModelError(where + ": a joint of that name exists already");
  if (model_.hasFrame(child_frame)) throw ModelError(where + ": frame '" + child_frame + "' exists already");
  const int last_body = model_.bodyCount() - 1;
  int parent_body = last_body;
  if (!parent_frame.empty()) {
    parent_body = model_.frame(model_.frameIndex(parent_frame)).body;
    // Depth first: the parent is on the path from the last body to the base, so
    // that every subtree stays a contiguous range of bodies (model.hpp).
    int b = last_body;
    while (b > parent_body) b = model_.parent(b);
    if (b != parent_body)
      throw ModelError(where + ": parent frame '" + parent_frame + "' is on a branch that is already complete (add " +
                       "joints depth first: the parent must be the last body added or one of its ancestors)");
  }
  Joint joint = joint_in;
  if (!joint.axis.allFinite() || joint.axis.norm() < 1e-9)
    throw ModelError(where + ": axis must be a finite non-zero vector");
  joint.axis.normalize();
  if (!finite(joint.placement)) throw ModelError(where + ": origin is not finite");
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
  }
  if (std::isnan(joint.lower) || std::isnan(joint.upper)) throw ModelError(where + ": limit is NaN");
  if (joint.lower > joint.upper) throw ModelError(where + ": lower limit exceeds upper limit");
  if (std::isnan(joint.effort_limit) || joint.effort_limit < 0.0)
    throw ModelError(where + ": effort limit must be non-negative");
  if (std::isnan(joint.velocity_limit) || joint.velocity_limit < 0.0)
    throw ModelError(where + ": velocity limit must be non-negative");
  checkLinkInertia(child_frame, model_.bodyCount(), child_inertia);

  // The joint's placement is relative to the parent link's frame; rebase it on
  // the parent body's frame (they differ when the parent link was merged in).
  if (!parent_frame.empty())
    joint.placement = joint.placement * model_.frame(model_.frameIndex(parent_frame)).placement;

  model_.joints_.push_back(joint);
  model_.inertias_.push_back(child_inertia);
  const int body = model_.bodyCount() - 1;
  model_.parents_.push_back(parent_body);
  model_.subtree_end_.push_back(body + 1);
  for (int a = parent_body; a >= 0; a = model_.parent(a)) model_.subtree_end_[static_cast<std::size_t>(a)] = body + 1;
  model_.is_chain_ = model_.is_chain_ && parent_body == body - 1;
  model_.frames_.push_back(Frame{child_frame, body, Transform{}});
  model_.body_frames_.push_back(static_cast<int>(model_.frames_.size()) - 1);
  return *this;
}

ModelBuilder& ModelBuilder::addFixedFrame(const std::string& name, const std::string& parent_frame,
                                          const Transform& placement, const RigidInertia& inertia) {
  const std::string where = "link '" + name + "'";
  if (model_.hasFrame(name)) throw ModelError(where + ": a frame of that name exists already");
  if (!finite(placement)) throw ModelError(where + ": origin of its fixed joint is not finite");
  const Frame& parent = model_.frame(model_.frameIndex(parent_frame));
  checkLinkInertia(name, parent.body, inertia);
  // ᶠX_body = ᶠX_parent · ᵖX_body
  const Frame frame{name, parent.body, placement * parent.placement};
  model_.inertias_[static_cast<std::size_t>(frame.body)] += spatial::inverseTransformInertia(frame.placement, inertia);
  model_.frames_.push_back(frame);
  return *this;
}

void ModelBuilder::checkLinkInertia(const std::string& link, int body, const RigidInertia& inertia) {
  // The base never moves: what is welded to it does not enter the dynamics, so
  // its flaws cannot change an answer (and the verdict must not depend on
  // which link the user picks as the root).
  if (body == 0) return;
  for (const ModelWarning& w : validate::rigidInertia("link '" + link + "'", inertia)) addWarning(w.code, w.message);
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
  jointNamed(joint).rotor_inertia = value;
  return *this;
}

ModelBuilder& ModelBuilder::setFriction(const std::string& joint, double breakaway, double kinetic, double viscous) {
  for (double v : {breakaway, kinetic, viscous})
    if (!std::isfinite(v) || v < 0.0)
      throw ModelError("joint '" + joint +
                       "': breakaway, kinetic and viscous friction must be finite and non-negative");
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
  model_.inertias_[0] += inertia;
  return *this;
}

ModelBuilder& ModelBuilder::setBase(BaseType type, const Transform& placement) {
  if (model_.base_type_ != BaseType::Fixed)
    throw ModelError(std::string("the base already floats (a ") + toString(model_.base_type_) +
                     " joint under the root link '" + model_.frames_[0].name + "'): it cannot get a " + toString(type) +
                     " base as well");
  if (!finite(placement)) throw ModelError("base placement is not finite");
  if (type == BaseType::Free && !(placement.E.isIdentity(0.0) && placement.r.isZero(0.0)))
    throw ModelError("a free base takes no placement (its pose is its configuration)");
  model_.base_type_ = type;
  model_.base_placement_ = placement;
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
  const int iq = baseConfigurationSize(), iv = baseVelocitySize();  // the joints' entries follow the base's
  for (const int m : mimic_joints_) {
    const Mimic& law = joints_[static_cast<std::size_t>(m)].mimic;
    if (q.size() == nq()) q[iq + m] = law.multiplier * q[iq + law.leader] + law.offset;
    if (qd.size() == nv()) qd[iv + m] = law.multiplier * qd[iv + law.leader];
  }
}

Model ModelBuilder::build() const {
  // Each link passed on its own; their sum is checked too, to rounding of the
  // merged figures, so no moving body reaches a solve with a negative moment.
  for (int b = 1; b < model_.bodyCount(); ++b) {
    const std::string link =
        model_.frames_[static_cast<std::size_t>(model_.body_frames_[static_cast<std::size_t>(b)])].name;
    validate::rigidInertia("body of link '" + link + "' (with the links welded to it)",
                           model_.inertias_[static_cast<std::size_t>(b)]);
  }
  // A moving body must carry inertia somewhere in its subtree (or its joint a
  // rotor inertia), or its acceleration is undetermined. The leaves are the
  // bodies left bare most often, so check from the leaves inward.
  std::vector<double> mass_beyond(static_cast<std::size_t>(model_.bodyCount()), 0.0);
  for (int j = model_.dof() - 1; j >= 0; --j) {
    const auto body = static_cast<std::size_t>(j + 1);
    const RigidInertia& I = model_.inertias_[body];
    mass_beyond[body] += I.mass + I.Ibar.trace();
    mass_beyond[static_cast<std::size_t>(model_.parent(j + 1))] += mass_beyond[body];
    const Joint& joint = model_.joints_[static_cast<std::size_t>(j)];
    if (mass_beyond[body] <= 0.0 && joint.rotor_inertia <= 0.0) {
      const std::string link =
          model_.frames_[static_cast<std::size_t>(model_.body_frames_[static_cast<std::size_t>(j + 1)])].name;
      throw ModelError("link '" + link + "': zero mass on a moving body with nothing beyond it (joint '" + joint.name +
                       "' would have no inertia to move)");
    }
  }
  if (model_.hasFloatingBase()) {
    // Body 0 moves: its inertia (the root link and what is welded to it) now
    // enters the dynamics, so it gets the checks the other bodies got.
    const std::string link = model_.frames_[0].name;
    if (mass_beyond[0] + model_.inertias_[0].mass + model_.inertias_[0].Ibar.trace() <= 0.0)
      throw ModelError("link '" + link + "': a floating base with no mass anywhere in the robot");
  }
  Model model = model_;
  if (model.hasFloatingBase())
    for (const ModelWarning& w : validate::rigidInertia(
             "base body of link '" + model.frames_[0].name + "' (with the links welded to it)", model.inertias_[0]))
      model.warnings_.push_back(w);
  resolveMimicChains(model.joints_, model.mimic_joints_);
  return model;
}

}  // namespace zwang
