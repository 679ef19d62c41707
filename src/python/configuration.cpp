// Python: the configuration helpers of include/zwang/configuration.hpp
// (docs/python.md, "Configuration helpers"). Each returns a new array and
// raises SolveError with the C++ Status (SizeMismatch, NonFinite,
// BadConfiguration) for bad input, as a solve does.
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

}  // namespace

void bindConfiguration(py::module_& m) {
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
