// Python: Model, Joint, Frame, URDF loading and introspection.
#include <pybind11/stl.h>

#include <limits>

#include "bindings.hpp"

namespace zwang::python {

namespace {

std::string pathArg(py::handle path) {
  // str, bytes or any os.PathLike.
  py::object fs = py::module_::import("os").attr("fsdecode")(py::module_::import("os").attr("fspath")(path));
  return fs.cast<std::string>();
}

internal::NamedUrdfOptions urdfOptions(const std::string& root, const std::string& tip, const py::object& rotor_inertia,
                                       bool strict, bool attach_beyond_tip, bool lock_mimic, const std::string& base) {
  problem::ModelRequest request{root, tip, strict, attach_beyond_tip, lock_mimic, BaseType::Fixed, {}};
  request.base = checked("base", [&] { return problem::parseBaseType(kPython, base); });
  request.names = {"tip=", "rotor_inertia=", "attach_beyond_tip=True", "lock_mimic=True"};
  request.names.base = "base='" + base + "'";
  internal::NamedUrdfOptions options = problem::urdfOptions(request);
  if (!rotor_inertia.is_none()) {
    if (!py::isinstance<py::dict>(rotor_inertia))
      raise(PyExc_TypeError, "rotor_inertia: expected a dict {joint name: inertia}");
    for (const auto& item : py::reinterpret_borrow<py::dict>(rotor_inertia)) {
      if (!py::isinstance<py::str>(item.first)) raise(PyExc_TypeError, "rotor_inertia: keys must be joint names (str)");
      options.rotor_inertia[item.first.cast<std::string>()] = py::cast<double>(item.second);
    }
  }
  return options;
}

int jointCount(const Model& model) { return static_cast<int>(model.joints().size()); }

// The joint of DOF k below the root (entry nv − dof + k of qd).
const Joint& jointOfDof(const Model& model, int k) {
  return model.joint(model.dofs()[static_cast<std::size_t>(model.nv() - model.dof() + k)].joint);
}

// A per-DOF array of a Joint field (model.dof entries, in qd order below the
// root: a multi-DOF joint's value once per DOF, as the solver's friction vectors).
template <class F>
py::array perDof(const Model& model, F field) {
  Eigen::VectorXd v(model.dof());
  for (int k = 0; k < model.dof(); ++k) v[k] = field(jointOfDof(model, k));
  return vectorCopy(v);
}

// Per-joint values for the builder's setters by the problem layer's rules
// (one per joint, or one per DOF as the getters give them; finite, >= 0).
Eigen::VectorXd perJointArg(const Model& model, const char* name, py::handle value) {
  Eigen::VectorXd buffer;
  const Eigen::Map<const Eigen::VectorXd> v = vectorArg(name, value, buffer);
  return checked("", [&] { return problem::perJoint(model, name, v); });
}

py::array transformMatrix(const Eigen::Matrix3d& R, const Vec3& p) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = p;
  return matrixCopy(T);
}

// A body index in [0, bodyCount()) (IndexError otherwise: the C++ accessors do not check).
int bodyArg(const Model& model, const char* name, int b) {
  if (b < 0 || b >= model.bodyCount())
    raise(PyExc_IndexError, std::string(name) + ": body " + std::to_string(b) + " out of range [0, " +
                                std::to_string(model.bodyCount()) + ")");
  return b;
}

std::string jointRepr(const Joint& j) { return "<zwang.Joint '" + j.name + "' " + toString(j.type) + ">"; }

// Each of the model's warnings through Python's warnings machinery (so filters
// apply: "error" turns one into an exception, "ignore" silences it).
std::shared_ptr<Model> issueWarnings(std::shared_ptr<Model> model) {
  for (const ModelWarning& w : model->warnings())
    if (PyErr_WarnEx(exceptions().model_warning.ptr(), w.message.c_str(), 2) != 0) throw py::error_already_set();
  return model;
}

JointType jointTypeArg(const std::string& type) {
  for (const JointType t : {JointType::Revolute, JointType::Continuous, JointType::Prismatic, JointType::Spherical,
                            JointType::Planar, JointType::Free})
    if (type == toString(t)) return t;
  raise(PyExc_ValueError, "type: unknown joint type '" + type +
                              "' (expected 'revolute', 'continuous', 'prismatic', 'spherical', 'planar' or 'free')");
}

// A 4×4 pose [R p; 0 0 0 1] of a frame in its parent (as Joint.placement and
// Frame.placement give it); None is the identity. R must be a rotation.
Transform poseArg(const char* name, py::handle value) {
  if (value.is_none()) return Transform{};
  const Eigen::Matrix4d T = matrixArg(name, value, 4, 4);
  const Mat3 R = T.topLeftCorner<3, 3>();
  // A rotation typed with 16 digits, or computed in float64, is orthonormal to
  // a few 1e-16; 1e-9 still lets a 10-digit printout through.
  const bool rotation =
      T.allFinite() && (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-9 && R.determinant() > 0.0;
  if (!rotation || T.row(3) != Eigen::RowVector4d(0, 0, 0, 1))
    raise(PyExc_ValueError, std::string(name) +
                                ": expected a finite 4×4 rigid transform [R p; 0 0 0 1] with R a rotation (orthonormal "
                                "to 1e-9, determinant +1)");
  return Transform::fromPose(R, T.topRightCorner<3, 1>());
}

// A link's inertia from its mass, centre of mass and 3×3 inertia about the
// centre of mass (None: zero), in the link's frame; checked by the builder.
RigidInertia inertiaArg(double mass, py::handle com, py::handle inertia) {
  const Mat3 I = inertia.is_none() ? Mat3::Zero() : Mat3(matrixArg("inertia", inertia, 3, 3));
  return RigidInertia::fromMassComInertia(mass, vec3Arg("com", com), I);
}

BaseType floatingBaseArg(const std::string& type) {
  return checked("set_base",
                 [&] { return problem::parseBaseType(kPython, type, "a fixed base is a builder without set_base"); });
}

using ModelClass = py::class_<Model, std::shared_ptr<Model>>;

// Joint: a moving joint, read-only.
void bindJoint(py::module_& m) {
  py::class_<Joint>(m, "Joint", "A moving joint of the model (read-only; SI units, radians).")
      .def_property_readonly("name", [](const Joint& j) { return j.name; })
      .def_property_readonly(
          "type", [](const Joint& j) { return std::string(toString(j.type)); },
          "'revolute', 'continuous', 'prismatic', 'spherical', 'planar' or 'free' (docs/conventions.md, "
          "\"Joint types\")")
      .def_property_readonly("nq", &Joint::nq,
                             "entries of q: 1 (revolute, continuous, prismatic), 4 (spherical), 3 (planar), 7 (free)")
      .def_property_readonly(
          "nv", &Joint::nv,
          "entries of qd, tau, qdd: 1 (revolute, continuous, prismatic), 3 (spherical), 3 (planar), 6 (free)")
      .def_property_readonly(
          "q_index", [](const Joint& j) { return j.q_index; }, "first entry of the joint's coordinates in q")
      .def_property_readonly(
          "v_index", [](const Joint& j) { return j.v_index; },
          "first entry of its velocity coordinates in qd, tau, qdd")
      .def_property_readonly(
          "axis", [](const Joint& j) { return vectorCopy(j.axis); },
          "unit axis in the joint (child link) frame (one-DOF joints)")
      .def_property_readonly("lower", [](const Joint& j) { return j.lower; })
      .def_property_readonly("upper", [](const Joint& j) { return j.upper; })
      .def_property_readonly("effort_limit", [](const Joint& j) { return j.effort_limit; })
      .def_property_readonly("velocity_limit", [](const Joint& j) { return j.velocity_limit; })
      .def_property_readonly(
          "breakaway_friction", [](const Joint& j) { return j.breakaway_friction; },
          "f_j >= 0, the static friction bound (URDF <dynamics friction>)")
      .def_property_readonly("kinetic_friction", [](const Joint& j) { return j.kinetic_friction; })
      .def_property_readonly("viscous_friction", [](const Joint& j) { return j.viscous_friction; })
      .def_property_readonly("rotor_inertia", [](const Joint& j) { return j.rotor_inertia; })
      .def_property_readonly(
          "placement",
          [](const Joint& j) { return transformMatrix(j.placement.rotationOfTarget(), j.placement.originOfTarget()); },
          "4×4 pose of the joint frame in the parent body frame at q = 0")
      .def_property_readonly(
          "mimic",
          [](const Joint& j) -> py::object {
            if (!j.mimic.active()) return py::none();
            return py::make_tuple(j.mimic.leader, j.mimic.multiplier, j.mimic.offset);
          },
          "None, or (leader joint index, multiplier, offset) when the joint follows q = multiplier*q_leader + offset")
      .def("__repr__", &jointRepr);
}

// Dof: one entry of qd.
void bindDof(py::module_& m) {
  py::class_<Dof>(m, "Dof",
                  "One degree of freedom, entry k of qd (Model.dofs): a rotation about or a translation along one axis "
                  "(read-only).")
      .def_property_readonly(
          "name", [](const Dof& d) { return d.name; }, "the joint's name, 'hip.wx' for a multi-DOF joint")
      .def_property_readonly(
          "joint", [](const Dof& d) { return d.joint; }, "index of its joint in Model.joints (-1: the root joint)")
      .def_property_readonly("index_in_joint", [](const Dof& d) { return d.index_in_joint; })
      .def_property_readonly(
          "rotation", [](const Dof& d) { return d.rotation; }, "True: a rotation about axis; False: a translation")
      .def_property_readonly(
          "in_joint_frame", [](const Dof& d) { return d.in_joint_frame; },
          "True: axis is fixed in the joint frame (a planar joint's x and y); False: in the child's")
      .def_property_readonly("axis", [](const Dof& d) { return vectorCopy(d.axis); })
      .def_property_readonly("rotor_inertia", [](const Dof& d) { return d.rotor_inertia; })
      .def_property_readonly("breakaway_friction", [](const Dof& d) { return d.breakaway_friction; })
      .def_property_readonly("kinetic_friction", [](const Dof& d) { return d.kinetic_friction; })
      .def_property_readonly("viscous_friction", [](const Dof& d) { return d.viscous_friction; })
      .def_property_readonly("lower", [](const Dof& d) { return d.lower; })
      .def_property_readonly("upper", [](const Dof& d) { return d.upper; })
      .def("__repr__", [](const Dof& d) { return "<zwang.Dof '" + d.name + "'>"; });
}

// Frame: a named frame on a body.
void bindFrame(py::module_& m) {
  py::class_<Frame>(m, "Frame", "A named frame (every URDF link), rigidly attached to a body.")
      .def_property_readonly("name", [](const Frame& f) { return f.name; })
      .def_property_readonly(
          "body", [](const Frame& f) { return f.body; },
          "the body it is attached to: 0 is the world (a fixed base), Model.base_body a floating base; DOF k moves "
          "body k+1")
      .def_property_readonly(
          "placement",
          [](const Frame& f) { return transformMatrix(f.placement.rotationOfTarget(), f.placement.originOfTarget()); },
          "4×4 pose of the frame in its body frame")
      .def("__repr__",
           [](const Frame& f) { return "<zwang.Frame '" + f.name + "' on body " + std::to_string(f.body) + ">"; });
}

// Model: its sizes, names, joints, frames and DOFs, and the look-ups.
void addSizesAndNames(ModelClass& cls) {
  cls.def_property_readonly("name", &Model::name)
      .def_property_readonly("dof", &Model::dof,
                             "degrees of freedom below the root: nv without a floating base's (the number of joints "
                             "when every joint has one DOF); the length of the per-DOF arrays (friction, limits)")
      .def_property_readonly(
          "base_type", [](const Model& model) { return std::string(toString(model.baseType())); },
          "'fixed', 'free' (a free-flyer) or 'planar' (x, y, yaw in a plane): how body 0 is attached to the world")
      .def_property_readonly("nq", &Model::nq,
                             "length of q: the base's coordinates (7 free, 3 planar, 0 fixed), then each joint's nq")
      .def_property_readonly("nv", &Model::nv,
                             "length of qd, tau, qdd: the base's velocity coordinates (6 free, 3 planar), then each "
                             "joint's nv")
      .def_property_readonly(
          "base_plane",
          [](const Model& model) -> py::object {
            if (model.baseType() != BaseType::Planar) return py::none();
            const Transform& X = model.basePlacement();
            return transformMatrix(X.rotationOfTarget(), X.originOfTarget());
          },
          "a planar base's plane: 4×4 pose of its frame in the world (x, y span the plane, z is the yaw axis); "
          "None for the other bases")
      .def_property_readonly(
          "joint_names",
          [](const Model& model) {
    py::list names;
    for (const Joint& j : model.joints()) names.append(j.name);
    return names;
          })
      .def_property_readonly(
          "frame_names",
          [](const Model& model) {
    py::list names;
    for (const Frame& f : model.frames()) names.append(f.name);
    return names;
          })
      .def_property_readonly(
          "joints", [](const Model& model) { return model.joints(); },
          "list of Joint (copies): the joints below the root, in q order")
      .def_property_readonly(
          "all_joints", [](const Model& model) { return model.allJoints(); },
          "list of Joint (copies): a floating base's root joint ('root_joint', free or planar) first, then joints")
      .def_property_readonly(
          "dofs", [](const Model& model) { return model.dofs(); },
          "list of Dof (copies), one per entry of qd (model.nv): the root joint's first")
      .def_property_readonly(
          "frames", [](const Model& model) { return model.frames(); }, "list of Frame (copies)")
      .def(
          "joint", [](const Model& model, const std::string& name) { return model.joint(model.jointIndex(name)); },
          py::arg("name"))
      .def("joint_index", &Model::jointIndex, py::arg("name"), "index of a moving joint; ModelError if unknown")
      .def("frame_index", &Model::frameIndex, py::arg("name"), "index of a frame; ModelError if unknown")
      .def("has_frame", &Model::hasFrame, py::arg("name"))
      .def_property_readonly(
          "mimic_joints", [](const Model& model) { return model.mimicJoints(); },
          "indices of the joints that follow a leader (Joint.mimic)")
      .def(
          "follow_leaders",
          [](const Model& model, const py::object& q, const py::object& qd) {
    Eigen::VectorXd q_buf, qd_buf;
    Eigen::VectorXd q_out = vectorArg("q", q, q_buf), qd_out = vectorArg("qd", qd, qd_buf);
    if (q_out.size() != model.nq() || qd_out.size() != model.nv())
      throw py::value_error("follow_leaders: q needs nq = " + std::to_string(model.nq()) +
                            " entries and qd nv = " + std::to_string(model.nv()) + " (a floating base's first)");
    model.followLeaders(q_out, qd_out);
    return py::make_tuple(vectorCopy(q_out), vectorCopy(qd_out));
          },
          py::arg("q"), py::arg("qd"),
          "copies of q (nq entries) and qd (nv) with each mimic joint's entries set from its leader's "
          "(q = a*q_leader + b, qd = a*qd_leader)");
}

// Model: the bodies' tree.
void addTree(ModelClass& cls) {
  cls.def_property_readonly("body_count", &Model::bodyCount,
                            "nv + 1: body 0 (the world, or a fixed base) and one body per DOF (DOF k moves body k+1)")
      .def_property_readonly("base_body", &Model::baseBody,
                             "the root link's body: 0 on a fixed base, 6 (free) or 3 (planar) on a floating one")
      .def_property_readonly("is_chain", &Model::isChain, "True when every body's parent is the body before it")
      .def_property_readonly(
          "parents",
          [](const Model& model) {
    py::array_t<long> out(jointCount(model));
    auto v = out.mutable_unchecked<1>();
    for (int j = 0; j < jointCount(model); ++j) {
      const int body = model.parentBodyOfJoint(j);  // body 0 or the root's: Dof::joint is −1
      v(j) = body == 0 ? -1 : model.dofs()[static_cast<std::size_t>(body - 1)].joint;
    }
    return out;
          },
          "per joint, the index of the joint that moves its parent body (-1: it hangs from the base)")
      .def(
          "parent", [](const Model& model, int b) { return model.parent(bodyArg(model, "parent", b)); },
          py::arg("body"), "the parent body of a body (-1 for the base, body 0); joint j moves body j+1")
      .def(
          "subtree_end", [](const Model& model, int b) { return model.subtreeEnd(bodyArg(model, "subtree_end", b)); },
          py::arg("body"),
          "one past the last body of the body's subtree: the subtree is range(body, subtree_end(body))")
      .def(
          "supports",
          [](const Model& model, int a, int b) {
    return model.supports(bodyArg(model, "supports", a), bodyArg(model, "supports", b));
          },
          py::arg("a"), py::arg("b"), "True when body a is body b or one of its ancestors");
}

// Model: the per-DOF arrays, warnings and masses.
void addPerDofArrays(ModelClass& cls) {
  cls.def_property_readonly("lower",
                            [](const Model& model) { return perDof(model, [](const Joint& j) { return j.lower; }); })
      .def_property_readonly("upper",
                             [](const Model& model) { return perDof(model, [](const Joint& j) { return j.upper; }); })
      .def_property_readonly(
          "effort_limit",
          [](const Model& model) { return perDof(model, [](const Joint& j) { return j.effort_limit; }); })
      .def_property_readonly(
          "velocity_limit",
          [](const Model& model) { return perDof(model, [](const Joint& j) { return j.velocity_limit; }); })
      .def_property_readonly(
          "breakaway_friction",
          [](const Model& model) { return perDof(model, [](const Joint& j) { return j.breakaway_friction; }); })
      .def_property_readonly(
          "kinetic_friction",
          [](const Model& model) { return perDof(model, [](const Joint& j) { return j.kinetic_friction; }); })
      .def_property_readonly(
          "viscous_friction",
          [](const Model& model) { return perDof(model, [](const Joint& j) { return j.viscous_friction; }); })
      .def_property_readonly(
          "rotor_inertia",
          [](const Model& model) { return perDof(model, [](const Joint& j) { return j.rotor_inertia; }); })
      .def_property_readonly(
          "warnings",
          [](const Model& model) {
    py::list out;
    for (const ModelWarning& w : model.warnings()) out.append(py::make_tuple(toString(w.code), w.message));
    return out;
          },
          "list of (code, message): what was doubtful in the data ('point_mass', 'placeholder_inertia', ...)")
      .def_property_readonly(
          "base_mass", [](const Model& model) { return model.inertia(model.baseBody()).mass; },
          "mass of body 0, the root link and the links welded to it [kg]: in the dynamics when the base floats, "
          "not on a fixed base")
      .def_property_readonly(
          "mass",
          [](const Model& model) {
    double mass = 0.0;
    for (int b = 1; b < model.bodyCount(); ++b)
      if (b != model.baseBody()) mass += model.inertia(b).mass;
    return mass;
          },
          "total mass of the bodies beyond the base [kg] (base_mass is the base's)");
}

// Model: copies with other rotor inertias or friction.
void addCopies(ModelClass& cls) {
  cls.def(
         "with_rotor_inertia",
         [](const Model& model, py::handle values) {
    Eigen::VectorXd buffer;
    const Eigen::Map<const Eigen::VectorXd> v = vectorArg("rotor_inertia", values, buffer);
    return std::make_shared<Model>(checked("", [&] { return problem::withRotorInertia(model, "rotor_inertia", v); }));
         },
         py::arg("rotor_inertia"),
         "a copy with these reflected rotor inertias, one per joint or one per DOF (model.dof entries; a joint's\n"
         "DOFs must agree)")
      .def(
          "with_friction",
          [](const Model& model, py::handle breakaway, py::handle kinetic, py::handle viscous) {
    const Eigen::VectorXd f = perJointArg(model, "breakaway", breakaway);
    const Eigen::VectorXd fc = kinetic.is_none() ? f : perJointArg(model, "kinetic", kinetic);
    Eigen::VectorXd b(jointCount(model));
    for (int j = 0; j < jointCount(model); ++j) b[j] = model.joint(j).viscous_friction;
    if (!viscous.is_none()) b = perJointArg(model, "viscous", viscous);
    ModelBuilder builder(model);
    for (int j = 0; j < jointCount(model); ++j) builder.setFriction(model.joint(j).name, f[j], fc[j], b[j]);
    return std::make_shared<Model>(builder.build());
          },
          py::arg("breakaway"), py::arg("kinetic") = py::none(), py::arg("viscous") = py::none(),
          "a copy with these friction parameters, one per joint or one per DOF (model.dof entries, as\n"
          "model.breakaway_friction gives them; a joint's DOFs must agree; a box per DOF of that size); kinetic\n"
          "defaults to breakaway, viscous to the model's")
      .def("__repr__", [](const Model& model) {
        const std::string base = model.hasFloatingBase() ? std::string(toString(model.baseType())) +
                                                               " base, nq=" + std::to_string(model.nq()) +
                                                               ", nv=" + std::to_string(model.nv()) + ", "
                                                         : std::string();
        return "<zwang.Model '" + model.name() + "': " + base + std::to_string(jointCount(model)) + " joints (" +
               problem::jointNames(model) + "), " + std::to_string(model.frames().size()) + " frames>";
      });
}

// ModelBuilder.add_joint: a Joint from the keyword arguments.
ModelBuilder& addJoint(ModelBuilder& b, const std::string& name, const std::string& type, const std::string& child,
                       const std::string& parent, py::handle axis, py::handle placement, double mass, py::handle com,
                       py::handle inertia, double lower, double upper, double effort_limit, double velocity_limit,
                       double rotor_inertia, double breakaway, double kinetic, double viscous) {
  Joint joint;
  joint.name = name;
  joint.type = jointTypeArg(type);
  joint.axis = vec3Arg("axis", axis);
  joint.placement = poseArg("placement", placement);
  joint.lower = lower;
  joint.upper = upper;
  joint.effort_limit = effort_limit;
  joint.velocity_limit = velocity_limit;
  joint.rotor_inertia = rotor_inertia;
  joint.breakaway_friction = breakaway;
  joint.kinetic_friction = kinetic;
  joint.viscous_friction = viscous;
  return b.addJoint(joint, child, inertiaArg(mass, com, inertia), parent);
}

// ModelBuilder: a Model joint by joint.
void bindModelBuilder(py::module_& m) {
  py::class_<ModelBuilder>(m, "ModelBuilder",
                           "Builds a Model joint by joint (zwang::ModelBuilder): any joint type anywhere in the tree,\n"
                           "depth first. Each method returns the builder; build() returns the Model. Bad values raise\n"
                           "ModelError naming the joint or link and the field.")
      .def(py::init<std::string, std::string>(), py::arg("robot_name") = "robot", py::arg("base_frame") = "base",
           "an empty tree: the fixed base alone, a frame called base_frame")
      .def(py::init([](const Model& model) { return ModelBuilder(model); }), py::arg("model"),
           "start from an existing model (to add joints below its last link)")
      .def("add_joint", &addJoint, py::arg("name"), py::arg("type"), py::arg("child"), py::kw_only(),
           py::arg("parent") = "", py::arg("axis") = py::make_tuple(0.0, 0.0, 1.0), py::arg("placement") = py::none(),
           py::arg("mass") = 0.0, py::arg("com") = py::make_tuple(0.0, 0.0, 0.0), py::arg("inertia") = py::none(),
           py::arg("lower") = -std::numeric_limits<double>::infinity(),
           py::arg("upper") = std::numeric_limits<double>::infinity(),
           py::arg("effort_limit") = std::numeric_limits<double>::infinity(),
           py::arg("velocity_limit") = std::numeric_limits<double>::infinity(), py::arg("rotor_inertia") = 0.0,
           py::arg("breakaway_friction") = 0.0, py::arg("kinetic_friction") = 0.0, py::arg("viscous_friction") = 0.0,
           py::return_value_policy::reference_internal,
           "Add a moving joint of any type ('revolute', 'continuous', 'prismatic', 'spherical', 'planar', 'free')\n"
           "whose child link is the new frame `child`, hanging from the frame `parent` (default: the last link\n"
           "added; depth first: the last link or one of its ancestors). placement: 4×4 pose of the joint frame in\n"
           "the parent link at q = 0 (None: identity); axis: one-DOF joints only. The child link's mass, com and\n"
           "3×3 inertia about the com (None: zero) are in its frame. Rotor inertia and friction apply to each DOF\n"
           "(a box per DOF); multi-DOF joints take no finite limits.")
      .def(
          "add_fixed_frame",
          [](ModelBuilder& b, const std::string& name, const std::string& parent, py::handle placement, double mass,
             py::handle com, py::handle inertia) -> ModelBuilder& {
            return b.addFixedFrame(name, parent, poseArg("placement", placement), inertiaArg(mass, com, inertia));
          },
          py::arg("name"), py::arg("parent"), py::arg("placement") = py::none(), py::kw_only(), py::arg("mass") = 0.0,
          py::arg("com") = py::make_tuple(0.0, 0.0, 0.0), py::arg("inertia") = py::none(),
          py::return_value_policy::reference_internal,
          "Weld a frame to `parent` (a fixed URDF joint) at `placement` (4×4); its inertia joins the parent's body.")
      .def(
          "add_base_link_inertia",
          [](ModelBuilder& b, double mass, py::handle com, py::handle inertia) -> ModelBuilder& {
            return b.addBaseLinkInertia(inertiaArg(mass, com, inertia));
          },
          py::arg("mass"), py::arg("com") = py::make_tuple(0.0, 0.0, 0.0), py::arg("inertia") = py::none(),
          py::return_value_policy::reference_internal,
          "Add the base link's own inertia (in the dynamics when the base floats).")
      .def(
          "set_base",
          [](ModelBuilder& b, const std::string& type, py::handle plane) -> ModelBuilder& {
            return b.setBase(floatingBaseArg(type), poseArg("plane", plane));
          },
          py::arg("type"), py::arg("plane") = py::none(), py::return_value_policy::reference_internal,
          "Let the base float: 'free' or 'planar' (the root joint 'root_joint', unactuated); plane: a planar\n"
          "base's plane, 4×4 pose in the world (None: the world's x-y plane).")
      .def(
          "set_mimic",
          [](ModelBuilder& b, const std::string& joint, const std::string& leader, double multiplier,
             double offset) -> ModelBuilder& { return b.setMimic(joint, leader, multiplier, offset); },
          py::arg("joint"), py::arg("leader"), py::arg("multiplier") = 1.0, py::arg("offset") = 0.0,
          py::return_value_policy::reference_internal,
          "Make a one-DOF joint follow another: q = multiplier*q_leader + offset.")
      .def(
          "build", [](const ModelBuilder& b) { return issueWarnings(std::make_shared<Model>(b.build())); },
          "the Model (ModelError when a moving body has no inertia to move); warnings as load_urdf issues them");
}

// load_mjcf, load_mjcf_string, read_mjcf: the problem layer's MJCF loader (a ModelError without MuJoCo).
void bindMjcfLoaders(py::module_& m) {
  m.def(
      "load_mjcf",
      [](py::handle path, bool strict) {
    return issueWarnings(std::make_shared<Model>(problem::loadMjcf(pathArg(path), false, strict).model));
      },
      py::arg("path"), py::kw_only(), py::arg("strict") = false,
      "Load an MJCF (MuJoCo XML) model through MuJoCo's compiler (docs/mujoco.md): hinge, slide, ball and\n"
      "free joints, armature, frictionloss, damping, limits; tendons, actuators, contacts and other\n"
      "equalities are not mapped (a zwang.ModelWarning names them; strict=True raises ModelError instead).\n"
      "A free joint's linear velocity is in the body frame (MuJoCo: world axes). The file's gravity:\n"
      "read_mjcf. Raises ModelError (also when zwang was built without MuJoCo).");
  m.def(
      "load_mjcf_string",
      [](const std::string& xml, bool strict) {
    return issueWarnings(std::make_shared<Model>(problem::loadMjcf(xml, true, strict).model));
      },
      py::arg("xml"), py::kw_only(), py::arg("strict") = false, "load_mjcf from a string holding the MJCF XML.");
  m.def(
      "read_mjcf",
      [](py::handle path, bool strict) {
    problem::LoadedModel loaded = problem::loadMjcf(pathArg(path), false, strict);
    const Vec3 g = loaded.gravity.value_or(Vec3::Zero());
    return py::make_tuple(issueWarnings(std::make_shared<Model>(std::move(loaded.model))),
                          py::array_t<double>(3, g.data()));
      },
      py::arg("path"), py::kw_only(), py::arg("strict") = false,
      "(model, gravity): load_mjcf's model and the file's <option gravity> (numpy array, m/s^2; zero when\n"
      "the file disables gravity), for Task.gravity.");
}

// load_urdf, load_urdf_string.
void bindLoaders(py::module_& m) {
  m.def(
      "load_urdf",
      [](py::handle path, const std::string& root, const std::string& tip, const py::object& rotor, bool strict,
         bool attach_beyond_tip, bool lock_mimic, const std::string& base) {
    return issueWarnings(std::make_shared<Model>(internal::loadUrdfFile(
        pathArg(path), urdfOptions(root, tip, rotor, strict, attach_beyond_tip, lock_mimic, base))));
      },
      py::arg("path"), py::arg("root") = "", py::arg("tip") = "", py::arg("rotor_inertia") = py::none(), py::kw_only(),
      py::arg("strict") = false, py::arg("attach_beyond_tip") = false, py::arg("lock_mimic") = false,
      py::arg("base") = "fixed",
      "Load the whole tree below link `root` (default: the URDF's root link; joints depth first, each link's\n"
      "children by joint name), or with `tip` the chain from `root` to `tip`.\n"
      "rotor_inertia: optional {joint name: reflected inertia} overriding the URDF.\n"
      "Doubtful data loads with a zwang.ModelWarning per warning (also in Model.warnings);\n"
      "strict=True raises ModelError instead. attach_beyond_tip=True welds links behind moving joints\n"
      "below the tip to the tip body (joints locked at 0). A <mimic> joint follows its leader (its q, qd\n"
      "must obey the law: Model.follow_leaders; its torque is carried by the leader); lock_mimic=True\n"
      "welds it instead, at its position when its leader is at 0.\n"
      "base='free' gives the root link a free-flyer, base='planar' x, y, yaw in the world's x-y plane (then q\n"
      "has model.nq entries, qd and tau model.nv, the base's first); 'fixed' (the default) adds none: a URDF\n"
      "whose root link's only joint is floating or planar floats without it (base='free' on it is a ModelError).\n"
      "Raises ModelError.");
  m.def(
      "load_urdf_string",
      [](const std::string& xml, const std::string& root, const std::string& tip, const py::object& rotor, bool strict,
         bool attach_beyond_tip, bool lock_mimic, const std::string& base) {
    return issueWarnings(std::make_shared<Model>(
        internal::loadUrdfString(xml, urdfOptions(root, tip, rotor, strict, attach_beyond_tip, lock_mimic, base))));
      },
      py::arg("xml"), py::arg("root") = "", py::arg("tip") = "", py::arg("rotor_inertia") = py::none(), py::kw_only(),
      py::arg("strict") = false, py::arg("attach_beyond_tip") = false, py::arg("lock_mimic") = false,
      py::arg("base") = "fixed", "load_urdf from a string holding the URDF XML.");
  bindMjcfLoaders(m);
}

}  // namespace

void bindModel(py::module_& m) {
  bindJoint(m);
  bindDof(m);
  bindFrame(m);
  ModelClass cls(m, "Model", "An immutable kinematic tree or chain (zwang::Model). Make one with load_urdf().");
  addSizesAndNames(cls);
  addTree(cls);
  addPerDofArrays(cls);
  addCopies(cls);
  bindModelBuilder(m);
  bindLoaders(m);
}

}  // namespace zwang::python
