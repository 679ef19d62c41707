#include "zwang/model.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
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

void validate::rigidInertia(const std::string& where, double mass, const Vec3& com, const Mat3& I_com) {
  if (!std::isfinite(mass)) throw ModelError(where + ": mass is not finite");
  if (!com.allFinite()) throw ModelError(where + ": centre of mass is not finite");
  if (!I_com.allFinite()) throw ModelError(where + ": inertia is not finite");
  if (mass < 0.0) throw ModelError(where + ": mass " + std::to_string(mass) + " is negative");
  if ((I_com - I_com.transpose()).cwiseAbs().maxCoeff() > 1e-12 * (1.0 + I_com.cwiseAbs().maxCoeff()))
    throw ModelError(where + ": inertia is not symmetric");
  const Eigen::Vector3d moments = Eigen::SelfAdjointEigenSolver<Mat3>(I_com, Eigen::EigenvaluesOnly).eigenvalues();
  const double scale = std::max(1e-300, moments.cwiseAbs().maxCoeff());
  const bool all_zero = moments.cwiseAbs().maxCoeff() == 0.0;
  if (mass > 0.0 || !all_zero) {
    if (moments.minCoeff() <= 1e-12 * scale) {
      std::ostringstream out;
      out << where << ": inertia is not positive definite (principal moments " << moments.transpose() << ")";
      throw ModelError(out.str());
    }
    // Principal moments of a real body: each is at most the sum of the other two.
    const double slack = 1e-9 * scale;
    if (moments(0) + moments(1) < moments(2) - slack) {
      std::ostringstream out;
      out << where << ": inertia violates the triangle inequality (principal moments " << moments.transpose()
          << ", " << moments(0) << " + " << moments(1) << " < " << moments(2) << ")";
      throw ModelError(out.str());
    }
  }
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
  if (!parent_frame.empty()) {
    const int parent_body = model_.frame(model_.frameIndex(parent_frame)).body;
    if (parent_body != last_body)
      throw ModelError(where + ": parent frame '" + parent_frame + "' is not on the last body of the chain");
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
                      {"damping", joint.damping}};
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
  validate::rigidInertia("link '" + child_frame + "'", child_inertia.mass, child_inertia.com(),
                         child_inertia.inertiaAboutCom());

  // The joint's placement is relative to the parent link's frame; rebase it on
  // the parent body's frame (they differ when the parent link was merged in).
  if (!parent_frame.empty()) joint.placement = joint.placement * model_.frame(model_.frameIndex(parent_frame)).placement;

  model_.joints_.push_back(joint);
  model_.inertias_.push_back(child_inertia);
  const int body = model_.bodyCount() - 1;
  model_.frames_.push_back(Frame{child_frame, body, Transform{}});
  model_.body_frames_.push_back(static_cast<int>(model_.frames_.size()) - 1);
  return *this;
}

ModelBuilder& ModelBuilder::addFixedFrame(const std::string& name, const std::string& parent_frame,
                                          const Transform& placement, const RigidInertia& inertia) {
  const std::string where = "link '" + name + "'";
  if (model_.hasFrame(name)) throw ModelError(where + ": a frame of that name exists already");
  if (!finite(placement)) throw ModelError(where + ": origin of its fixed joint is not finite");
  validate::rigidInertia(where, inertia.mass, inertia.com(), inertia.inertiaAboutCom());
  const Frame& parent = model_.frame(model_.frameIndex(parent_frame));
  // ᶠX_body = ᶠX_parent · ᵖX_body
  const Frame frame{name, parent.body, placement * parent.placement};
  model_.inertias_[static_cast<std::size_t>(frame.body)] += spatial::inverseTransformInertia(frame.placement, inertia);
  model_.frames_.push_back(frame);
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

ModelBuilder& ModelBuilder::setFriction(const std::string& joint, double breakaway, double kinetic, double damping) {
  for (double v : {breakaway, kinetic, damping})
    if (!std::isfinite(v) || v < 0.0)
      throw ModelError("joint '" + joint + "': friction and damping must be finite and non-negative");
  Joint& j = jointNamed(joint);
  j.breakaway_friction = breakaway;
  j.kinetic_friction = kinetic;
  j.damping = damping;
  return *this;
}

Model ModelBuilder::build() const {
  // A moving body must carry inertia somewhere at or beyond it (or its joint a
  // rotor inertia), or its acceleration is undetermined. The last body is the
  // one the chain leaves bare most often, so check from the tip inward.
  double mass_beyond = 0.0;
  for (int j = model_.dof() - 1; j >= 0; --j) {
    const RigidInertia& I = model_.inertias_[static_cast<std::size_t>(j + 1)];
    mass_beyond += I.mass + I.Ibar.trace();
    const Joint& joint = model_.joints_[static_cast<std::size_t>(j)];
    if (mass_beyond <= 0.0 && joint.rotor_inertia <= 0.0) {
      const std::string link = model_.frames_[static_cast<std::size_t>(model_.body_frames_[static_cast<std::size_t>(j + 1)])].name;
      throw ModelError("link '" + link + "': zero mass on a moving body with nothing beyond it (joint '" +
                       joint.name + "' would have no inertia to move)");
    }
  }
  return model_;
}

}  // namespace zwang
