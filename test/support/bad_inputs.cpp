#include "support/bad_inputs.hpp"

#include <limits>

namespace zwang::testing {

Model pandaModel() { return loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf"); }

Model oneDofArmModel() { return loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.urdf"); }

std::vector<BadFrictionOption> badFrictionOptions() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<BadFrictionOption> table;
  const auto add = [&](const char* message, auto&& set) {
    BadFrictionOption row{FrictionOptions{}, message};
    set(row.options);
    table.push_back(std::move(row));
  };
  add("friction override 'kinetic' has 3 entries, the model has 7 joints",
      [](FrictionOptions& o) { o.kinetic = Eigen::VectorXd::Zero(3); });
  add("friction override 'breakaway' for joint 'panda_joint1' is -1 (must be finite and >= 0)",
      [](FrictionOptions& o) { o.breakaway = Eigen::VectorXd::Constant(7, -1.0); });
  add("friction override 'viscous' for joint 'panda_joint2' is -2 (must be finite and >= 0)", [](FrictionOptions& o) {
    o.viscous = Eigen::VectorXd::Zero(7);
    o.viscous[1] = -2.0;
  });
  add("velocity_tolerance nan must be finite and >= 0", [&](FrictionOptions& o) { o.velocity_tolerance = nan; });
  add("velocity_tolerance -1 must be finite and >= 0", [](FrictionOptions& o) { o.velocity_tolerance = -1.0; });
  add("limit_tolerance -1 must be finite and >= 0", [](FrictionOptions& o) { o.limit_tolerance = -1.0; });
  add("margin 1.5 must be in [0, 1]", [](FrictionOptions& o) { o.margin = 1.5; });
  add("margin 2 must be in [0, 1]", [](FrictionOptions& o) { o.margin = 2.0; });
  add("max_iterations must be at least 1", [](FrictionOptions& o) { o.max_iterations = 0; });
  add("kkt_tolerance must be positive", [](FrictionOptions& o) { o.kkt_tolerance = 0.0; });
  add("kkt_tolerance must be positive", [](FrictionOptions& o) { o.kkt_tolerance = -1e-9; });
  return table;
}

namespace {
Task intoUpperLimitTask(const Model& arm) {
  Task task(arm);
  task.gravity.setZero();
  ConstraintMatrix spin = ConstraintMatrix::Zero(6, 1);
  spin(5, 0) = 1.0;
  task.addConstraint("link1", spin);
  task.targets()[0] = 5.0;
  return task;
}
}  // namespace

IntoUpperLimit::IntoUpperLimit()
    : arm(oneDofArmModel()),
      task(intoUpperLimitTask(arm)),
      ws(arm, task),
      q(Eigen::VectorXd::Constant(1, arm.joint(0).upper)),
      zero(Eigen::VectorXd::Zero(1)),
      message("the task drives joint 'joint1' into its upper limit (3.14159)") {}

}  // namespace zwang::testing
