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

BaseType baseArg(const std::string& base) {
  if (base == "fixed") return BaseType::Fixed;
  if (base == "free") return BaseType::Free;
  if (base == "planar") return BaseType::Planar;
  raise(PyExc_ValueError, "base: unknown value '" + base + "' (expected 'fixed', 'free' or 'planar')");
}

UrdfOptions urdfOptions(const std::string& root, const std::string& tip, const py::object& rotor_inertia, bool strict,
                        bool attach_beyond_tip, bool lock_mimic, const std::string& base) {
  UrdfOptions options;
  options.root = root;
  options.tip = tip;
  options.strict = strict;
  options.attach_beyond_tip = attach_beyond_tip;
  options.mimic = lock_mimic ? MimicJoints::Lock : MimicJoints::Model;
  options.base = baseArg(base);
  options.names = {"tip=", "rotor_inertia=", "attach_beyond_tip=True", "lock_mimic=True"};
  options.names.base = "base='" + base + "'";
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

std::string jointNames(const Model& model) {
  std::string s;
  for (const Joint& j : model.joints()) s += (s.empty() ? "" : ", ") + j.name;
  return s;
}

// A per-joint array of a Joint field.
template <class F>
py::array perJoint(const Model& model, F field) {
  Eigen::VectorXd v(model.dof());
  for (int j = 0; j < model.dof(); ++j) v[j] = field(model.joint(j));
  return vectorCopy(v);
}

// Per-joint values for the builder's setters; length checked against the model.
Eigen::VectorXd perJointArg(const Model& model, const char* name, py::handle value) {
  Eigen::VectorXd buffer;
  Eigen::VectorXd v = vectorArg(name, value, buffer);
  if (v.size() != model.dof())
    raise(exceptions().model_error, std::string(name) + ": has " + std::to_string(v.size()) +
                                        " entries, the model has " + std::to_string(model.dof()) + " joints (" +
                                        jointNames(model) + ")");
  return v;
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

}  // namespace

void bindModel(py::module_& m) {
  py::class_<Joint>(m, "Joint", "A moving joint of the model (read-only; SI units, radians).")
      .def_property_readonly("name", [](const Joint& j) { return j.name; })
      .def_property_readonly(
          "type", [](const Joint& j) { return std::string(toString(j.type)); },
          "'revolute', 'continuous' or 'prismatic'")
      .def_property_readonly(
          "axis", [](const Joint& j) { return vectorCopy(j.axis); }, "unit axis in the joint (child link) frame")
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

  py::class_<Frame>(m, "Frame", "A named frame (every URDF link), rigidly attached to a body.")
      .def_property_readonly("name", [](const Frame& f) { return f.name; })
      .def_property_readonly(
          "body", [](const Frame& f) { return f.body; }, "0 is the base; joint j moves body j+1")
      .def_property_readonly(
          "placement",
          [](const Frame& f) { return transformMatrix(f.placement.rotationOfTarget(), f.placement.originOfTarget()); },
          "4×4 pose of the frame in its body frame")
      .def("__repr__",
           [](const Frame& f) { return "<zwang.Frame '" + f.name + "' on body " + std::to_string(f.body) + ">"; });

  py::class_<Model, std::shared_ptr<Model>>(
      m, "Model", "An immutable kinematic tree or chain (zwang::Model). Make one with load_urdf().")
      .def_property_readonly("name", &Model::name)
      .def_property_readonly("dof", &Model::dof, "number of moving joints")
      .def_property_readonly(
          "base_type", [](const Model& model) { return std::string(toString(model.baseType())); },
          "'fixed', 'free' (a free-flyer) or 'planar' (x, y, yaw in a plane): how body 0 is attached to the world")
      .def_property_readonly("nq", &Model::nq,
                             "length of q: the base's coordinates (7 free, 3 planar, 0 fixed), then one per joint")
      .def_property_readonly("nv", &Model::nv,
                             "length of qd, tau, qdd: the base's velocity coordinates (6 free, 3 planar), then one "
                             "per joint")
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
          "joints", [](const Model& model) { return model.joints(); }, "list of Joint (copies)")
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
          "(q = a*q_leader + b, qd = a*qd_leader)")
      .def_property_readonly("body_count", &Model::bodyCount, "dof + 1: the base (body 0) and one body per joint")
      .def_property_readonly("is_chain", &Model::isChain, "True when every body's parent is the body before it")
      .def_property_readonly(
          "parents",
          [](const Model& model) {
    py::array_t<long> out(model.dof());
    auto v = out.mutable_unchecked<1>();
    for (int j = 0; j < model.dof(); ++j) v(j) = model.parentBodyOfJoint(j) - 1;
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
          py::arg("a"), py::arg("b"), "True when body a is body b or one of its ancestors")
      .def_property_readonly("lower",
                             [](const Model& model) { return perJoint(model, [](const Joint& j) { return j.lower; }); })
      .def_property_readonly("upper",
                             [](const Model& model) { return perJoint(model, [](const Joint& j) { return j.upper; }); })
      .def_property_readonly(
          "effort_limit",
          [](const Model& model) { return perJoint(model, [](const Joint& j) { return j.effort_limit; }); })
      .def_property_readonly(
          "velocity_limit",
          [](const Model& model) { return perJoint(model, [](const Joint& j) { return j.velocity_limit; }); })
      .def_property_readonly(
          "breakaway_friction",
          [](const Model& model) { return perJoint(model, [](const Joint& j) { return j.breakaway_friction; }); })
      .def_property_readonly(
          "kinetic_friction",
          [](const Model& model) { return perJoint(model, [](const Joint& j) { return j.kinetic_friction; }); })
      .def_property_readonly(
          "viscous_friction",
          [](const Model& model) { return perJoint(model, [](const Joint& j) { return j.viscous_friction; }); })
      .def_property_readonly(
          "rotor_inertia",
          [](const Model& model) { return perJoint(model, [](const Joint& j) { return j.rotor_inertia; }); })
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
          "total mass of the bodies beyond the base [kg] (base_mass is the base's)")
      .def(
          "with_rotor_inertia",
          [](const Model& model, py::handle values) {
    const Eigen::VectorXd v = perJointArg(model, "rotor_inertia", values);
    ModelBuilder builder(model);
    for (int j = 0; j < model.dof(); ++j) builder.setRotorInertia(model.joint(j).name, v[j]);
    return std::make_shared<Model>(builder.build());
          },
          py::arg("rotor_inertia"), "a copy with these reflected rotor inertias, one per joint")
      .def(
          "with_friction",
          [](const Model& model, py::handle breakaway, py::handle kinetic, py::handle viscous) {
    const Eigen::VectorXd f = perJointArg(model, "breakaway", breakaway);
    const Eigen::VectorXd fc = kinetic.is_none() ? f : perJointArg(model, "kinetic", kinetic);
    Eigen::VectorXd b(model.dof());
    for (int j = 0; j < model.dof(); ++j) b[j] = model.joint(j).viscous_friction;
    if (!viscous.is_none()) b = perJointArg(model, "viscous", viscous);
    ModelBuilder builder(model);
    for (int j = 0; j < model.dof(); ++j) builder.setFriction(model.joint(j).name, f[j], fc[j], b[j]);
    return std::make_shared<Model>(builder.build());
          },
          py::arg("breakaway"), py::arg("kinetic") = py::none(), py::arg("viscous") = py::none(),
          "a copy with these friction parameters, one per joint (kinetic defaults to breakaway, viscous to the\n"
          "model's)")
      .def("__repr__", [](const Model& model) {
        const std::string base = model.hasFloatingBase() ? std::string(toString(model.baseType())) +
                                                               " base, nq=" + std::to_string(model.nq()) +
                                                               ", nv=" + std::to_string(model.nv()) + ", "
                                                         : std::string();
        return "<zwang.Model '" + model.name() + "': " + base + std::to_string(model.dof()) + " joints (" +
               jointNames(model) + "), " + std::to_string(model.frames().size()) + " frames>";
      });

  m.def(
      "load_urdf",
      [](py::handle path, const std::string& root, const std::string& tip, const py::object& rotor, bool strict,
         bool attach_beyond_tip, bool lock_mimic, const std::string& base) {
    return issueWarnings(std::make_shared<Model>(
        loadUrdfFile(pathArg(path), urdfOptions(root, tip, rotor, strict, attach_beyond_tip, lock_mimic, base))));
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
        loadUrdfString(xml, urdfOptions(root, tip, rotor, strict, attach_beyond_tip, lock_mimic, base))));
      },
      py::arg("xml"), py::arg("root") = "", py::arg("tip") = "", py::arg("rotor_inertia") = py::none(), py::kw_only(),
      py::arg("strict") = false, py::arg("attach_beyond_tip") = false, py::arg("lock_mimic") = false,
      py::arg("base") = "fixed", "load_urdf from a string holding the URDF XML.");
}

}  // namespace zwang::python
