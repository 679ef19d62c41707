#include "support/friction_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "support/random_problem.hpp"

namespace zwang::testing {

namespace {

bool allFinite(const Eigen::MatrixXd& x) { return x.allFinite(); }

}  // namespace

FrictionExpectation expectFriction(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                   const Eigen::VectorXd& tau, const FrictionOptions& options) {
  const int n = model.dof();
  FrictionExpectation e;
  e.breakaway.resize(n);
  e.kinetic.resize(n);
  e.viscous.resize(n);
  e.tau_kinetic = Eigen::VectorXd::Zero(n);
  e.limit_side = Eigen::VectorXi::Zero(n);
  e.tau = tau;
  for (int j = 0; j < n; ++j) {
    const Joint& joint = model.joint(j);
    e.breakaway(j) = options.breakaway.size() == n ? options.breakaway(j) : joint.breakaway_friction;
    e.kinetic(j) = options.kinetic.size() == n ? options.kinetic(j) : joint.kinetic_friction;
    e.viscous(j) = options.viscous.size() == n ? options.viscous(j) : joint.viscous_friction;
    if (std::abs(qd(j)) <= options.velocity_tolerance) {
      e.stuck.push_back(j);
      if (options.joint_limits) {
        if (std::isfinite(joint.lower) && q(j) <= joint.lower + options.limit_tolerance)
          e.limit_side(j) = -1;
        else if (std::isfinite(joint.upper) && q(j) >= joint.upper - options.limit_tolerance)
          e.limit_side(j) = 1;
      }
    } else {
      const double sign = qd(j) > 0.0 ? 1.0 : -1.0;
      e.tau_kinetic(j) = -e.kinetic(j) * sign - e.viscous(j) * qd(j);
    }
  }
  return e;
}

std::string checkMaximumDissipation(const FrictionResult& r, const Solution& s, const FrictionExpectation& e,
                                    const DissipationTolerances& tol) {
  std::ostringstream why;
  const auto n = e.breakaway.size();
  if (r.mu.size() != n || r.tau_friction.size() != n || static_cast<Eigen::Index>(r.state.size()) != n ||
      s.qdd.size() != n || r.dqdd_dmu.rows() != n || r.dqdd_dmu.cols() != n) {
    why << "sizes: mu " << r.mu.size() << ", tau_friction " << r.tau_friction.size() << ", state " << r.state.size()
        << ", qdd " << s.qdd.size() << ", dqdd_dmu " << r.dqdd_dmu.rows() << "x" << r.dqdd_dmu.cols() << " (dof " << n
        << ")";
    return why.str();
  }
  if (!allFinite(r.mu) || !allFinite(r.tau_friction) || !allFinite(s.qdd) || !allFinite(r.dqdd_dmu) ||
      !allFinite(s.tau_control) || !allFinite(s.tau_constraint) || !std::isfinite(r.gauss_dual) ||
      !std::isfinite(r.kkt_residual))
    return "non-finite output";
  if (r.stuck != e.stuck) {
    why << "stuck set {";
    for (int j : r.stuck) why << ' ' << j;
    why << " } but expected {";
    for (int j : e.stuck) why << ' ' << j;
    why << " }";
    return why.str();
  }

  const double a_scale = std::max(1.0, s.qdd.cwiseAbs().maxCoeff());
  const double a_tol = tol.acceleration * a_scale;
  const double t_tol = tol.torque * std::max({1.0, n > 0 ? e.breakaway.maxCoeff() : 0.0, r.mu.cwiseAbs().maxCoeff()});
  for (Eigen::Index j = 0; j < n; ++j) {
    const bool stuck = std::find(e.stuck.begin(), e.stuck.end(), static_cast<int>(j)) != e.stuck.end();
    const JointState state = r.state[static_cast<std::size_t>(j)];
    const double mu = r.mu(j), qdd = s.qdd(j), f = e.breakaway(j);
    const int side = e.limit_side(j);
    why << "joint " << j << " (" << toString(state) << ", mu " << mu << ", f " << f << ", qdd " << qdd
        << ", tau_friction " << r.tau_friction(j) << ", limit side " << side << "): ";
    if (!stuck) {
      if (state != JointState::Moving) return why.str() + "moving joint not in state Moving";
      if (std::abs(mu) > t_tol) return why.str() + "moving joint with mu != 0";
      if (std::abs(r.tau_friction(j) - e.tau_kinetic(j)) > t_tol)
        return why.str() + "tau_friction != kinetic " + std::to_string(e.tau_kinetic(j));
      if (r.dqdd_dmu.col(j).cwiseAbs().maxCoeff() != 0.0) return why.str() + "dqdd_dmu column of a moving joint not 0";
      why.str("");
      continue;
    }
    if (std::abs(r.tau_friction(j) + mu) > t_tol) return why.str() + "tau_friction != -mu";
    if (side < 0 && qdd < -a_tol) return why.str() + "accelerates into its lower limit";
    if (side > 0 && qdd > a_tol) return why.str() + "accelerates into its upper limit";
    switch (state) {
      case JointState::Moving: return why.str() + "stuck joint in state Moving";
      case JointState::Prescribed: return why.str() + "stuck joint in state Prescribed";
      case JointState::Stick:
        if (std::abs(qdd) > a_tol) return why.str() + "sticks but qdd != 0";
        if (std::abs(mu) > f + t_tol) return why.str() + "sticks but |mu| > f";
        break;
      case JointState::SlipPositive:
        if (std::abs(mu - f) > t_tol) return why.str() + "slips + but mu != f";
        if (qdd < -a_tol) return why.str() + "slips + but qdd < 0";
        break;
      case JointState::SlipNegative:
        if (std::abs(mu + f) > t_tol) return why.str() + "slips - but mu != -f";
        if (qdd > a_tol) return why.str() + "slips - but qdd > 0";
        break;
      case JointState::AtLimit:
        if (side == 0) return why.str() + "AtLimit but not on a limit";
        if (std::abs(qdd) > a_tol) return why.str() + "AtLimit but qdd != 0";
        if (side < 0 && mu > -f + t_tol) return why.str() + "AtLimit (lower) but mu > -f";
        if (side > 0 && mu < f - t_tol) return why.str() + "AtLimit (upper) but mu < f";
        break;
    }
    why.str("");
  }
  if (r.kkt_residual > tol.kkt * a_scale) {
    why << "kkt_residual " << r.kkt_residual << " above " << tol.kkt * a_scale;
    return why.str();
  }
  if (e.tau.size() == n && relativeError(s.tau_control, e.tau + s.tau_constraint) > 1e-12) {
    why << "tau_control != tau + tau_constraint (rel. error " << relativeError(s.tau_control, e.tau + s.tau_constraint)
        << ")";
    return why.str();
  }
  return "";
}

double frictionClosureError(const Model& model, const Task& task, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                            const FrictionResult& result, const Solution& solution) {
  Task free_task(model);
  free_task.gravity = task.gravity;
  for (const Task::AppliedWrench& w : task.wrenches())
    free_task.wrench(free_task.addWrench(w.frame, w.expressed)) = w.value;
  const Eigen::VectorXd qdd = solution.qdd;
  const Eigen::VectorXd drive = solution.tau_control + result.tau_friction;
  Workspace ws(model, free_task);
  if (!solveHybridDynamics(model, ws, q, qd, drive, free_task)) return std::numeric_limits<double>::infinity();
  return relativeError(ws.solution.qdd, qdd);
}

}  // namespace zwang::testing
