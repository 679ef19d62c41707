// Static friction: the exact maximum-dissipation motion (docs/friction.md; the
// report's chapter 5). One pass of the Popov–Vereshchagin sweeps with μ = 0,
// plus one extra right-hand side per stuck joint through the same sweeps,
// gives the characteristic equation q̈(μ) = q̈(0) − K_Θ μ (eq. 5.10); the dual
// g(μ) = g(0) + μᵀ q̈_Θ(0) − ½ μᵀ K_ΘΘ μ is then maximised over the box Λ.
#include "zwang/friction.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "internal/box_qp.hpp"
#include "internal/checks.hpp"
#include "internal/friction_scratch.hpp"
#include "internal/growing_cholesky.hpp"
#include "internal/popov_vereshchagin.hpp"

namespace zwang {

const char* toString(JointState state) {
  switch (state) {
    case JointState::Moving: return "moving";
    case JointState::Stick: return "stick";
    case JointState::SlipPositive: return "slip+";
    case JointState::SlipNegative: return "slip-";
    case JointState::AtLimit: return "at-limit";
  }
  return "unknown";
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using internal::FrictionScratch;

Status checkOptions(const Model& model, const FrictionOptions& o) {
  const int n = model.dof();
  const struct {
    const char* name;
    const Eigen::VectorXd& v;
  } overrides[] = {{"breakaway", o.breakaway}, {"kinetic", o.kinetic}, {"damping", o.damping}};
  for (const auto& ov : overrides) {
    if (ov.v.size() != 0 && ov.v.size() != n)
      return Status::error(StatusCode::BadOption, "friction override '%s' has %ld entries, the model has %d joints",
                           ov.name, static_cast<long>(ov.v.size()), n);
    for (Eigen::Index j = 0; j < ov.v.size(); ++j)
      if (!std::isfinite(ov.v[j]) || ov.v[j] < 0.0)
        return Status::error(StatusCode::BadOption, "friction override '%s' for joint '%s' is %g (must be finite and >= 0)",
                             ov.name, model.joint(static_cast<int>(j)).name.c_str(), ov.v[j]);
  }
  if (!(o.velocity_tolerance >= 0.0) || !std::isfinite(o.velocity_tolerance))
    return Status::error(StatusCode::BadOption, "velocity_tolerance %g must be finite and >= 0", o.velocity_tolerance);
  if (!(o.limit_tolerance >= 0.0) || !std::isfinite(o.limit_tolerance))
    return Status::error(StatusCode::BadOption, "limit_tolerance %g must be finite and >= 0", o.limit_tolerance);
  if (!(o.margin >= 0.0 && o.margin <= 1.0))
    return Status::error(StatusCode::BadOption, "margin %g must be in [0, 1]", o.margin);
  if (o.max_iterations < 1) return Status::error(StatusCode::BadOption, "max_iterations must be at least 1");
  if (!(o.kkt_tolerance > 0.0)) return Status::error(StatusCode::BadOption, "kkt_tolerance must be positive");
  return {};
}

// Largest t ≥ 0 with lo ≤ x + t·d ≤ hi.
double roomAlong(const Eigen::Ref<const Eigen::VectorXd>& x, const Eigen::Ref<const Eigen::VectorXd>& d,
                 const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi) {
  double t = kInf;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    if (d[j] > 0) t = std::min(t, (hi[j] - x[j]) / d[j]);
    if (d[j] < 0) t = std::min(t, (lo[j] - x[j]) / d[j]);
  }
  return std::max(0.0, t);
}

}  // namespace

Status solveWithFriction(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& q,
                         const Eigen::Ref<const Eigen::VectorXd>& qd, const Eigen::Ref<const Eigen::VectorXd>& tau,
                         Workspace& ws, const FrictionOptions& options) noexcept {
  using namespace internal;
  if (Status s = checkSolveInputs(model, task, q, qd, tau, ws); !s) return s;
  if (Status s = checkOptions(model, options); !s) return s;
  const int n = model.dof();
  const int m = task.constraintRows();
  FrictionScratch& fs = ws.frictionScratch();
  FrictionResult& fr = ws.friction;
  Solution& out = ws.solution;

  // ---- Friction parameters, the stuck set Θ₀ and kinetic friction (docs/friction.md, "The model of friction")
  for (int j = 0; j < n; ++j) {
    const Joint& joint = model.joint(j);
    fs.f[j] = options.breakaway.size() ? options.breakaway[j] : joint.breakaway_friction;
    fs.fc[j] = options.kinetic.size() ? options.kinetic[j] : joint.kinetic_friction;
    fs.b[j] = options.damping.size() ? options.damping[j] : joint.damping;
  }
  fr.stuck.clear();
  fr.limit_impact = false;
  fr.impact_joint = -1;
  fr.indeterminate = false;
  fr.iterations = 0;
  fr.kkt_residual = 0.0;
  fs.tau_eff = tau;
  fr.tau_friction.setZero();
  for (int j = 0; j < n; ++j) {
    const Joint& joint = model.joint(j);
    const bool at_lower = options.joint_limits && q[j] <= joint.lower + options.limit_tolerance;
    const bool at_upper = options.joint_limits && q[j] >= joint.upper - options.limit_tolerance;
    if (std::abs(qd[j]) <= options.velocity_tolerance) {
      const auto k = static_cast<Eigen::Index>(fr.stuck.size());
      fr.stuck.push_back(j);
      fs.lo[k] = at_lower ? -kInf : -fs.f[j];  // the stop pushes positively without bound
      fs.hi[k] = at_upper ? kInf : fs.f[j];
      fr.state[static_cast<std::size_t>(j)] = JointState::Stick;
    } else {
      fr.tau_friction[j] = -fs.fc[j] * (qd[j] > 0 ? 1.0 : -1.0) - fs.b[j] * qd[j];
      fs.tau_eff[j] += fr.tau_friction[j];
      fr.state[static_cast<std::size_t>(j)] = JointState::Moving;
      if ((at_lower && qd[j] < 0) || (at_upper && qd[j] > 0)) {
        fr.limit_impact = true;  // it needs an impulse to stop: reported, not modelled
        if (fr.impact_joint < 0) fr.impact_joint = j;
      }
    }
  }
  const auto k = static_cast<Eigen::Index>(fr.stuck.size());

  // ---- The sweeps at μ = 0, and one extra right-hand side per stuck joint
  outwardSweep(model, task, q, qd, ws);
  if (Status s = inwardSweep(model, task, fs.tau_eff, ws); !s) return s;
  balance(task, ws);
  outwardAccelerations(model, task, ws, fs.qdd0);
  fs.nu0.head(m) = ws.nu.head(m);
  fr.dqdd_dmu.setZero();
  if (k > 0) {
    unitTorqueColumns(model, task, ws, fr.stuck, fs.du.leftCols(k), fs.dU.topLeftCorner(m, k),
                      fs.dnu.topLeftCorner(m, k), fs.dqdd.leftCols(k), fs.dF.leftCols(k), fs.da.leftCols(k));
    for (Eigen::Index col = 0; col < k; ++col)  // μ_j enters as the torque −μ_j
      fr.dqdd_dmu.col(fr.stuck[static_cast<std::size_t>(col)]) = -fs.dqdd.col(col);
  }

  // ---- max g(μ) over Λ  ⇔  min ½ μᵀ K_ΘΘ μ − μᵀ q̈_Θ(0)
  auto P = fs.P.topLeftCorner(k, k);
  for (Eigen::Index a = 0; a < k; ++a) fs.c[a] = fs.qdd0[fr.stuck[static_cast<std::size_t>(a)]];
  {  // K_ΘΘ = rows Θ of −∂q̈/∂μ, column by column (raw gathers: k² of them)
    const int* rows = fr.stuck.data();
    const double* dqdd = fs.dqdd.data();
    const Eigen::Index dqdd_stride = fs.dqdd.outerStride();
    double* p = P.data();
    const Eigen::Index p_stride = P.outerStride();
    for (Eigen::Index b = 0; b < k; ++b)
      for (Eigen::Index a = 0; a < k; ++a) p[a + b * p_stride] = dqdd[rows[a] + b * dqdd_stride];
    for (Eigen::Index b = 0; b < k; ++b)  // symmetric in exact arithmetic (K is)
      for (Eigen::Index a = b + 1; a < k; ++a)
        p[a + b * p_stride] = p[b + a * p_stride] = 0.5 * (p[a + b * p_stride] + p[b + a * p_stride]);
  }
  // The size of the terms K_ΘΘ is computed from (1/D_j, and the columns'
  // entries): where the task pins the stuck joints, K_ΘΘ is that times
  // rounding, and a stop the task pushes into must come out unbounded
  // rather than as a 1e16 N·m torque (the maximiser's reach rule).
  double curvature_scale = 0.0;
  if (k > 0) {
    double min_D = kInf;
    for (Eigen::Index a = 0; a < k; ++a)
      min_D = std::min(min_D, ws.D[static_cast<std::size_t>(fr.stuck[static_cast<std::size_t>(a)] + 1)]);
    curvature_scale = std::max(1.0 / min_D, fs.dqdd.leftCols(k).cwiseAbs().maxCoeff());
  }
  // The acceleration scale, of the stuck joints only (a light, fast joint
  // elsewhere in the chain must not set it): their accelerations q̈_Θ(0).
  double acc_max = 0.0;
  for (Eigen::Index a = 0; a < k; ++a) acc_max = std::max(acc_max, std::abs(fs.qdd0[fr.stuck[static_cast<std::size_t>(a)]]));
  const double acc_scale = 1.0 + acc_max;
  const double tolerance = options.kkt_tolerance * acc_scale;
  auto mu = fs.mu.head(k);
  mu.setZero();  // feasible: 0 ∈ Λ
  QpReport report;
  if (k > 0) {
    report = options.method == FrictionMethod::ActiveSet
                 ? boxQpActiveSet(P, fs.c.head(k), fs.lo.head(k), fs.hi.head(k), mu, fs.qp, options.max_iterations,
                                  tolerance, curvature_scale)
                 : boxQpProjectedGradient(P, fs.c.head(k), fs.lo.head(k), fs.hi.head(k), mu, fs.qp,
                                          options.max_iterations, tolerance, curvature_scale);
  }
  fr.iterations = report.iterations;
  fr.converged = k == 0 || report.converged;

  // ---- Several maximisers? They all give the same q̈* (docs/theory.md §5), so they
  // differ only along null(K_ΘΘ); and g is linear there with slope q̈*_Θ, so a
  // slipping joint (q̈_j ≠ 0) cannot move. The maximisers are μ* + d with d on
  // the sticking joints Σ, K_ΣΣ d = 0, inside the box. Among them pick the one
  // that minimises ‖τ_control‖² using at most margin·f_j (where it can).
  if (k > 0 && !report.unbounded) {
    const double acc_tol = 1e-9 * acc_scale;
    Eigen::Index ns = 0;
    auto qdd_star = fs.qdd_star.head(k);  // q̈*_Θ = q̈_Θ(0) − K_ΘΘ μ*
    qdd_star = fs.c.head(k);
    qdd_star.noalias() -= P * mu;
    for (Eigen::Index a = 0; a < k; ++a)
      if (std::abs(fs.qdd_star[a]) <= acc_tol) fs.sub_index[ns++] = static_cast<int>(a);
    // Directions along which g is flat to within the acceleration tolerance
    // over the whole box: a curvature λ moves q̈ by at most λ·W across a box
    // of width W. (None when every stuck joint slips: μ* is then unique.)
    Eigen::Index nullity = 0;
    if (ns > 0) {
      double width = 0.0;
      for (Eigen::Index a = 0; a < ns; ++a) {
        const Eigen::Index t = fs.sub_index[a];
        width = std::max(width, std::abs(mu[t]));
        if (std::isfinite(fs.lo[t])) width = std::max(width, std::abs(fs.lo[t]));
        if (std::isfinite(fs.hi[t])) width = std::max(width, std::abs(fs.hi[t]));
      }
      width *= 2.0;
      auto Pss = fs.V.topLeftCorner(ns, ns);
      const int* sub = fs.sub_index.data();
      for (Eigen::Index b = 0; b < ns; ++b) {
        const double* p_column = P.data() + sub[b] * P.outerStride();
        double* pss_column = Pss.data() + b * Pss.outerStride();
        for (Eigen::Index a = 0; a < ns; ++a) pss_column[a] = p_column[sub[a]];
      }
      const double floor = width > 0.0 ? acc_tol / (static_cast<double>(ns) * width) : 0.0;
      nullity = nearNullSpace(Pss, floor, fs.null_basis.topLeftCorner(ns, ns), fs.perm.head(ns));
    }
    if (nullity > 0) {
      const auto N = fs.null_basis.topLeftCorner(ns, nullity);
      auto x = fs.sub_mu.head(ns), lo = fs.sub_lo.head(ns), hi = fs.sub_hi.head(ns);
      for (Eigen::Index a = 0; a < ns; ++a) {
        x[a] = mu[fs.sub_index[a]];
        lo[a] = fs.lo[fs.sub_index[a]];
        hi[a] = fs.hi[fs.sub_index[a]];
      }
      // Both choices below are least-distance problems on the set of
      // maximisers x + N z inside a box. With one curvature direction v
      // (ns − nullity = 1: a 7-joint arm holding a 6-D pose, say) that set is
      // the hyperplane vᵀμ = vᵀx, and the dual is one scalar equation.
      const bool hyperplane = ns - nullity == 1;
      auto v = fs.v.head(ns);
      double plane = 0.0;
      if (hyperplane) {  // v ⟂ N: (1 − N Nᵀ) e_p for the row p of N with the least weight
        Eigen::Index p = 0;
        for (Eigen::Index a = 1; a < ns; ++a)
          if (N.row(a).squaredNorm() < N.row(p).squaredNorm()) p = a;
        v.noalias() = -N * N.row(p).transpose();
        v[p] += 1.0;
        v.normalize();
        plane = v.dot(x);
      }
      auto x_ref = fs.mu_alt.head(ns);
      auto t = fs.h.head(ns);
      // x_ref ← the point of the set closest to t, inside [lo, hi] (which
      // holds x_ref on entry).
      const auto moveClosestTo = [&] {
        if (hyperplane && leastDistanceOnHyperplane(v, plane, t, lo, hi, x_ref, fs.qp)) return;
        auto z = fs.z.head(nullity);
        auto a_target = fs.za.head(nullity);
        z.setZero();
        a_target.noalias() = N.transpose() * t;  // Nᵀ(t − x_ref), without a temporary
        a_target.noalias() -= N.transpose() * x_ref;
        leastDistanceQp(N, a_target, x_ref, lo, hi, z, fs.qp, options.max_iterations);
        x_ref.noalias() += N * z;
      };
      // (a) the smallest maximiser, as a reference point inside the set;
      x_ref = x;
      t.setZero();
      moveClosestTo();
      // (b) on the set, τ_control restricted to Σ is h + μ (H q̈* + C is fixed):
      //     minimise ‖h + μ‖² within the margin box.
      ws.nu.head(m) = fs.nu0.head(m);
      ws.nu.head(m).noalias() -= fs.dnu.topLeftCorner(m, k) * mu;
      constraintTorques(model, task, ws, ws.nu.head(m), fs.tau_total);
      for (Eigen::Index a = 0; a < ns; ++a) {
        const Eigen::Index ta = fs.sub_index[a];
        const int j = fr.stuck[static_cast<std::size_t>(ta)];
        t[a] = -(tau[j] + fs.tau_total[j] - mu[ta]);  // −h
        const double f_margin = options.margin * fs.f[j];
        if (std::isfinite(lo[a])) lo[a] = std::max(lo[a], std::min(-f_margin, x_ref[a]));  // a limit stop
        if (std::isfinite(hi[a])) hi[a] = std::min(hi[a], std::max(f_margin, x_ref[a]));   // carries any load
      }
      moveClosestTo();
      // Indeterminate: the maximisers form more than a point.
      const double mu_scale = 1e-9 * (1.0 + fs.f.cwiseAbs().maxCoeff());
      for (Eigen::Index a = 0; a < ns; ++a) {
        lo[a] = fs.lo[fs.sub_index[a]];
        hi[a] = fs.hi[fs.sub_index[a]];
      }
      fr.indeterminate = (x_ref - x).cwiseAbs().maxCoeff() > mu_scale;
      for (Eigen::Index e = 0; e < nullity && !fr.indeterminate; ++e)
        fr.indeterminate = roomAlong(x, N.col(e), lo, hi) > mu_scale || roomAlong(x, -N.col(e), lo, hi) > mu_scale;
      for (Eigen::Index a = 0; a < ns; ++a) mu[fs.sub_index[a]] = x_ref[a];
    }
  }

  // ---- The motion at μ*: the sweeps are linear in the torques, so
  // q̈(μ*) = q̈(0) + (∂q̈/∂τ_Θ)(−μ*) and ν(μ*) likewise (lines 26–30 by
  // superposition), then Ẍ from q̈ (line 29). With nothing stuck, μ* is
  // empty and the μ = 0 sweep already gave it.
  out.qdd = fs.qdd0;
  if (k > 0) {
    out.qdd.noalias() -= fs.dqdd.leftCols(k) * mu;
    ws.nu.head(m) = fs.nu0.head(m);
    ws.nu.head(m).noalias() -= fs.dnu.topLeftCorner(m, k) * mu;
    bodyAccelerations(model, task, ws, out.qdd);
  }
  taskResidual(task, ws);
  publishNu(task, ws);
  constraintTorques(model, task, ws, ws.nu.head(m), out.tau_constraint);
  out.tau_control = tau + out.tau_constraint;

  fr.mu.setZero();
  fs.tau_total = fs.tau_eff;  // the torques the joints feel: τ − kinetic − Wᵀμ
  const double acc_tol = 1e-9 * acc_scale;
  double mu_dot_qdd = 0.0;
  for (Eigen::Index a = 0; a < k; ++a) {
    const int j = fr.stuck[static_cast<std::size_t>(a)];
    fr.mu[j] = mu[a];
    fr.tau_friction[j] = -mu[a];
    fs.tau_total[j] -= mu[a];
    mu_dot_qdd += mu[a] * out.qdd[j];
    JointState& state = fr.state[static_cast<std::size_t>(j)];
    if (mu[a] < -fs.f[j] - 1e-12 * (1.0 + fs.f[j]) || mu[a] > fs.f[j] + 1e-12 * (1.0 + fs.f[j]))
      state = JointState::AtLimit;  // beyond what friction can give: the stop pushes
    else if (out.qdd[j] > acc_tol)
      state = JointState::SlipPositive;
    else if (out.qdd[j] < -acc_tol)
      state = JointState::SlipNegative;
    else
      state = JointState::Stick;
  }
  // g(μ*) = Z₀(q̈*) + μ*ᵀ W q̈* = Z with the joint torques τ − kinetic − Wᵀμ (eq. 5.7).
  fr.gauss_dual = gaussFunction(model, task, out.qdd, fs.tau_total, ws);
  out.gauss = fr.gauss_dual - mu_dot_qdd;
  fr.kkt_residual = k > 0 ? boxQpKktResidual(P, fs.c.head(k), fs.lo.head(k), fs.hi.head(k), mu) : 0.0;

  if (report.unbounded) {
    const int j = fr.stuck[static_cast<std::size_t>(report.unbounded_index)];
    const Joint& joint = model.joint(j);
    const bool lower = !std::isfinite(fs.lo[report.unbounded_index]);
    return Status::error(StatusCode::Infeasible, "the task drives joint '%s' into its %s limit (%g)",
                         joint.name.c_str(), lower ? "lower" : "upper", lower ? joint.lower : joint.upper);
  }
  return {};
}

}  // namespace zwang
