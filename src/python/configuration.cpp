// Python: the configuration helpers of include/zwang/configuration.hpp
// (docs/python.md, "Configuration helpers"), the orientation helpers of
// orientation.hpp and the placement of placement.hpp. Each returns a new
// array and raises SolveError with the C++ Status (SizeMismatch, NonFinite,
// BadConfiguration) for bad input, as a solve does.
#include <pybind11/stl.h>

#include "bindings.hpp"

namespace zwang::python {

namespace {

py::array integrateBinding(const Model& model, py::handle q, py::handle v, double dt) {
  Eigen::VectorXd q_buffer, v_buffer;
  const auto q_in = vectorArg("q", q, q_buffer);
  const auto v_in = vectorArg("v", v, v_buffer);
  Eigen::VectorXd q_out(model.nq());
  if (const Status s = integrate(model, q_in, v_in, dt, q_out); !s) raiseStatus(s, "integrate");
  return vectorCopy(q_out);
}

py::array differenceBinding(const Model& model, py::handle q0, py::handle q1) {
  Eigen::VectorXd q0_buffer, q1_buffer;
  const auto q0_in = vectorArg("q0", q0, q0_buffer);
  const auto q1_in = vectorArg("q1", q1, q1_buffer);
  Eigen::VectorXd v_out(model.nv());
  if (const Status s = difference(model, q0_in, q1_in, v_out); !s) raiseStatus(s, "difference");
  return vectorCopy(v_out);
}

py::array neutralBinding(const Model& model) {
  Eigen::VectorXd q_out(model.nq());
  if (const Status s = neutralConfiguration(model, q_out); !s) raiseStatus(s, "neutral_configuration");
  return vectorCopy(q_out);
}

// The C++ generator's state is the seed: the same seed draws the same q in C++
// and Python. Returns q and the advanced state, so draws can be chained.
py::tuple randomBinding(const Model& model, std::uint64_t seed) {
  std::uint64_t state = seed;
  Eigen::VectorXd q_out(model.nq());
  if (const Status s = randomConfiguration(model, state, q_out); !s) raiseStatus(s, "random_configuration");
  return py::make_tuple(vectorCopy(q_out), state);
}

py::array normalizeBinding(const Model& model, py::handle q) {
  Eigen::VectorXd q_buffer;
  Eigen::VectorXd q_out = vectorArg("q", q, q_buffer);
  if (const Status s = normalizeConfiguration(model, q_out); !s) raiseStatus(s, "normalize_configuration");
  return vectorCopy(q_out);
}

void checkBinding(const Model& model, py::handle q) {
  Eigen::VectorXd q_buffer;
  if (const Status s = checkConfiguration(model, vectorArg("q", q, q_buffer)); !s)
    raiseStatus(s, "check_configuration");
}

Eigen::Vector4d vec4Arg(const char* name, py::handle value) {
  Eigen::VectorXd buffer;
  const auto v = vectorArg(name, value, buffer);
  if (v.size() != 4)
    raise(PyExc_ValueError, std::string(name) + ": expected 4 numbers, got " + std::to_string(v.size()));
  return v;
}

// placeOnPlane: (q, distance).
py::tuple placeBinding(std::shared_ptr<Model> model, py::handle q, const std::vector<py::object>& frames, double height,
                       bool all) {
  Eigen::VectorXd q_buffer;
  const auto q_in = vectorArg("q", q, q_buffer);
  std::vector<int> indices;
  for (const py::object& f : frames)
    indices.push_back(py::isinstance<py::str>(f) ? model->frameIndex(f.cast<std::string>()) : f.cast<int>());
  Workspace ws(*model, 0);
  Eigen::VectorXd q_out(model->nq());
  double distance = 0.0;
  if (const Status s = placeOnPlane(*model, ws, q_in, indices, height, all ? PlaneContact::All : PlaneContact::Lowest,
                                    q_out, distance);
      !s)
    raiseStatus(s, "place_on_plane");
  return py::make_tuple(vectorCopy(q_out), distance);
}

// The orientation helpers (orientation.hpp), each a new array.
void bindOrientation(py::module_& m) {
  m.def(
      "quaternion_wxyz_from_xyzw", [](py::handle q) { return vectorCopy(quaternionWxyzFromXyzw(vec4Arg("q", q))); },
      py::arg("xyzw"),
      "[w, x, y, z] (zwang's, MuJoCo's order) from [x, y, z, w] (SciPy's Rotation.as_quat(), ROS's, Pinocchio's,\n"
      "Eigen's coeffs())");
  m.def(
      "quaternion_xyzw_from_wxyz", [](py::handle q) { return vectorCopy(quaternionXyzwFromWxyz(vec4Arg("q", q))); },
      py::arg("wxyz"), "[x, y, z, w] (SciPy's, ROS's, Pinocchio's order) from [w, x, y, z] (zwang's)");
  m.def(
      "rotation_log", [](py::handle R) { return vectorCopy(rotationLog(matrixArg("R", R, 3, 3))); }, py::arg("R"),
      "the rotation vector (axis·angle, |φ| ≤ π) of a 3×3 rotation matrix, accurate near 0 and π");
  m.def(
      "rotation_exp", [](py::handle phi) { return matrixCopy(rotationExp(vec3Arg("phi", phi))); }, py::arg("phi"),
      "the 3×3 rotation matrix exp([φ]×) of a rotation vector");
  m.def(
      "quaternion_log", [](py::handle q) { return vectorCopy(quaternionLog(vec4Arg("q", q))); }, py::arg("wxyz"),
      "the rotation vector of a quaternion [w, x, y, z] (normalised first; q and -q alike)");
  m.def(
      "quaternion_exp", [](py::handle phi) { return vectorCopy(quaternionExp(vec3Arg("phi", phi))); }, py::arg("phi"),
      "the unit quaternion [w, x, y, z] of a rotation vector");
  m.def(
      "orientation_error",
      [](py::handle current, py::handle desired) {
    return vectorCopy(orientationError(matrixArg("R_current", current, 3, 3), matrixArg("R_desired", desired, 3, 3)));
      },
      py::arg("R_current"), py::arg("R_desired"),
      "log(R_desired R_currentᵀ), world axes: the rotation vector that turns the current orientation into the\n"
      "desired one (rotation_exp(e) @ R_current == R_desired)");
}

}  // namespace

void bindConfiguration(py::module_& m) {
  bindOrientation(m);
  m.def("place_on_plane", &placeBinding, py::arg("model"), py::arg("q"), py::arg("frames"), py::arg("height") = 0.0,
        py::kw_only(), py::arg("all") = false,
        "(q, distance): q with the free base moved so that the frames (names or indices) touch the plane\n"
        "z = height: translated up or down until the lowest frame origin is on it (all=False), or first turned\n"
        "rigidly about the frames' centroid so that their best-fit plane is level (all=True: every frame on the\n"
        "plane when they are coplanar). distance: the largest distance of a frame origin from the plane after.");
  m.attr("QUATERNION_NORM_TOLERANCE") = kQuaternionNormTolerance;
  m.def("integrate", &integrateBinding, py::arg("model"), py::arg("q"), py::arg("v"), py::arg("dt") = 1.0,
        "q ⊕ v·dt, a new array of model.nq entries: the configuration reached from q moving with the constant\n"
        "velocity v (model.nv entries) for dt. Free base: the exact motion under the constant base-frame twist\n"
        "(the SE(3) exponential, quaternion renormalised); planar: x, y, ψ += rates·dt; joints: q += qd·dt, mimic\n"
        "joints set from their leaders.");
  m.def("difference", &differenceBinding, py::arg("model"), py::arg("q0"), py::arg("q1"),
        "q1 ⊖ q0, a new array of model.nv entries: the velocity v with integrate(model, q0, v, 1) == q1\n"
        "(free base: the SE(3) logarithm, the shortest rotation; planar: the yaw difference wrapped into (-π, π]).");
  m.def("neutral_configuration", &neutralBinding, py::arg("model"),
        "the base at the origin with the identity orientation, each joint at 0 clamped into its limits, mimic\n"
        "joints on their laws (model.nq entries)");
  m.def("random_configuration", &randomBinding, py::arg("model"), py::arg("seed"),
        "(q, state): a random configuration drawn with SplitMix64 from the 64-bit seed (the same q as the C++\n"
        "randomConfiguration with that state, on every platform), and the advanced state to draw the next one.\n"
        "Free base: position in [-1, 1]³ m, a uniform unit quaternion; planar: x, y in [-1, 1] m, ψ in [-π, π];\n"
        "joints: uniform within their limits ([-π, π] or [-1, 1] m where a limit is missing).");
  m.def("normalize_configuration", &normalizeBinding, py::arg("model"), py::arg("q"),
        "a copy of q with a free base's quaternion (entries 3-6) scaled to unit norm; SolveError\n"
        "(BadConfiguration) for a zero quaternion");
  m.def("check_configuration", &checkBinding, py::arg("model"), py::arg("q"),
        "None when q is a configuration of the model (model.nq finite entries; a free base's quaternion within\n"
        "QUATERNION_NORM_TOLERANCE of unit norm), else SolveError naming the entry at fault (code SizeMismatch,\n"
        "NonFinite or BadConfiguration)");
}

}  // namespace zwang::python
