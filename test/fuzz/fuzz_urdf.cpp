// libFuzzer target: URDF text → loadUrdfString (whole trees, since no tip is
// given; mimic joints modelled, and again with MimicJoints::Lock when the
// text has a <mimic>). The only exception allowed out of the loader is
// ModelError; a model that loads must then solve (the zero state with each
// mimic joint where its leader puts it, gravity) with finite outputs or a
// documented error status.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_common.hpp"
#include "zwang/zwang.hpp"

namespace {

// Load and solve once; `options` as given.
void loadAndSolve(const std::string& xml, const zwang::UrdfOptions& options) {
  using namespace zwang;
  Model model;
  try {
    model = loadUrdfString(xml, options);
  } catch (const ModelError& e) {
    if (e.what()[0] == '\0') fuzz::failure("ModelError without a message", "loadUrdfString");
    return;
  }
  if (model.dof() < 1 || model.dof() > 64) return;
  Task task(model);
  Workspace ws(model, task);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.dof());
  Eigen::VectorXd q = zero, qd = zero;
  model.followLeaders(q, qd);  // a mimic joint's offset
  const Status status = solveHybridDynamics(model, ws, q, qd, zero, task);
  if (status.ok()) {
    fuzz::requireFinite(ws.solution.qdd, "qdd", "solveHybridDynamics on a loaded URDF");
    fuzz::requireFinite(ws.solution.tau_control, "tau_control", "solveHybridDynamics on a loaded URDF");
  } else if (status.code != StatusCode::Degenerate) {
    fuzz::failure("unexpected status on a loaded model", status.message);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 1 << 16) return -1;  // the loader is not meant for megabytes; keeps the fuzzer fast
  const std::string xml(reinterpret_cast<const char*>(data), size);
  loadAndSolve(xml, {});
  if (xml.find("<mimic") != std::string::npos) {  // the same with the mimic joints locked
    zwang::UrdfOptions lock;
    lock.mimic = zwang::MimicJoints::Lock;
    loadAndSolve(xml, lock);
  }
  return 0;
}
