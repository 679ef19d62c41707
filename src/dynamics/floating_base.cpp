// A floating base as the joint of body 0 to the world: Algorithm 1's lines
// for a joint of k = 6 (free) or 3 (planar) coordinates, the last step of the
// inward sweep and the first of the outward ones. Read next to the report's
// Algorithm 1 and src/dynamics/popov_vereshchagin.cpp. Differences from the
// 1-DOF joints:
//  * D₀ = S₀ᵀ I^A₀ S₀ is a k × k matrix (factorised once, Cholesky) and u₀ a
//    k-vector; the base has no motor and no rotor inertia, but takes a
//    generalized force τ_base (normally 0);
//  * the coordinates the sweep uses for the base are not the user's
//    (docs/conventions.md, "Floating base"). Free: S₀ = 1 in base
//    coordinates (the sweep's q̇₀ is the base's spatial velocity Ẋ₀ itself
//    and Ẍ_bias,0 = 0), so P^A₀ = 1 − I^A₀ S₀ D₀⁻¹ S₀ᵀ = 0: nothing passes
//    past a free base and the world's acceleration drops out. The user's
//    v_B = ᴮX₀ Ẋ₀ and v̇_B = ᴮX₀ Ẍ₀ (the derivative of a motion vector's body
//    coordinates is its spatial derivative, since v × v = 0).
//    Planar: S₀ = [e_x 0; e_y 0; p × e_z e_z] (plane axes e, base origin p),
//    the user's coordinates; S₀ changes with p, so Ẍ_bias,0 = Ṡ₀ q̇₀ =
//    [ṗ × e_z ψ̇; 0];
//  * gravity stays the world's acceleration [−g; 0] (the report's line 2),
//    now under a moving base.
#include "dynamics/floating_base.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "dynamics/sweeps.hpp"

namespace zwang::internal {

namespace {

// The base's pose ⁰X₀ from its coordinates.
Transform basePose(const Model& model, const VectorRef& q_base) {
  if (model.baseType() == BaseType::Free) {
    // The solve has checked the quaternion is unit to 1e-6 (checkSolveInputs);
    // it is used normalised, so that R is a rotation to rounding.
    Eigen::Quaterniond quat(q_base[3], q_base[4], q_base[5], q_base[6]);
    quat.normalize();
    return Transform::fromPose(quat.toRotationMatrix(), q_base.head<3>());
  }
  // Planar: plane ∘ translate(x, y, 0) ∘ rot_z(ψ).
  const Transform& plane = model.basePlacement();  // ᴾX_world
  const Mat3 R_plane = plane.E.transpose();
  const Vec3 p = plane.r + R_plane * Vec3(q_base[0], q_base[1], 0.0);
  const Mat3 R = R_plane * Eigen::AngleAxisd(q_base[2], Vec3::UnitZ()).toRotationMatrix();
  return Transform::fromPose(R, p);
}

// A free base's D₀ = I^A₀ is always 6 × 6: its Cholesky factor L seen as a
// fixed-size matrix (the storage of a 6 × 6 MatrixXmax6 is a plain
// column-major 6 × 6 array). Through the dynamic-size (at most 6) types Eigen
// takes its general triangular-solve and product kernels: the base's step took
// 8,200 of the 62,300 instructions of the humanoid's plain solve, 2,900 this
// way (callgrind, inclusive counts under solveHybridDynamics, zwang_bench's
// floating_hd_m0/humanoid). The substitutions multiply by the reciprocals of
// L's diagonal, found once: a division inside them would sit on each
// right-hand side's chain of dependent operations.
struct FreeBaseFactor {
  explicit FreeBaseFactor(const Workspace& ws)
      : L(ws.D_base.matrixLLT().data()), inverse_diagonal(L.diagonal().cwiseInverse()) {}
  // X ← D₀⁻¹ X for a 6-row X (its columns in lock step): a Vec6 or a Mat6.
  template <typename Rhs>
  void solveInPlace(Rhs&& X) const {
    for (int i = 0; i < 6; ++i) {  // L Y = X
      for (int j = 0; j < i; ++j) X.row(i) -= L(i, j) * X.row(j);
      X.row(i) *= inverse_diagonal[i];
    }
    for (int i = 5; i >= 0; --i) {  // Lᵀ X = Y
      for (int j = i + 1; j < 6; ++j) X.row(i) -= L(j, i) * X.row(j);
      X.row(i) *= inverse_diagonal[i];
    }
  }
  Eigen::Map<const Mat6> L;
  Vec6 inverse_diagonal;
};

// Lines 13–21 for a free base, S₀ = 1: I^A₀ S₀ = I^A₀, D₀ = I^A₀ and S₀ᵀ A₀ =
// A₀, with fixed-size arithmetic. The same quantities as the general path
// (baseInward below), without its products with the identity.
void freeBaseInward(const Task& task, const Vec6& pA, Workspace& ws) {
  const int m = task.solverColumns();
  const FreeBaseFactor factor(ws);
  ws.IAS_base = ws.IA[0];
  ws.u_base -= pA;
  // ‖D₀⁻¹‖₁ is the scale rounding in 𝓛 is judged against (L_scale): only
  // for it is the inverse formed. D₀⁻¹ A₀ below comes from solves with the
  // factor, backward stable where the explicit inverse is not: I^A₀ is taken
  // about the world origin, ill-conditioned for a base far from it.
  Mat6 D_inverse = Mat6::Identity();
  factor.solveInPlace(D_inverse);
  ws.base_D_inverse_norm = D_inverse.cwiseAbs().colwise().sum().maxCoeff();
  Vec6 u_D = ws.u_base;
  factor.solveInPlace(u_D);

  ConstraintMatrix& A = ws.Ahat;
  ws.SA_base.leftCols(m) = A.leftCols(m);  // S₀ᵀ A₀
  for (int col = 0; col < m; ++col) {
    const Vec6 a = A.col(col);
    Vec6 a_D = a;  // D₀⁻¹ S₀ᵀ A₀, a column at a time: fixed sizes throughout
    factor.solveInPlace(a_D);
    ws.SA_base_D.col(col) = a_D;
    ws.L_scale[col] += a.squaredNorm() * ws.base_D_inverse_norm;
    ws.U[col] += a.dot(ws.c[0]) + a.dot(u_D);                                            // line 20
    for (int r = col; r < m; ++r) ws.L(r, col) += ws.SA_base.col(r).head<6>().dot(a_D);  // line 21, lower triangle
  }
  A.leftCols(m).setZero();  // line 19: P^A₀ = 0 exactly, I^A₀ (I^A₀)⁻¹ = 1
}

}  // namespace

void baseSolveInPlace(const Model& model, const Workspace& ws, VectorXmax6& x) {
  if (model.baseType() == BaseType::Free) {
    Vec6 y = x;
    FreeBaseFactor(ws).solveInPlace(y);
    x = y;
  } else {
    x = ws.D_base.solve(x);
  }
}

template <int W>
void baseSolveLanesInPlace(const Model& model, const Workspace& ws, double* lanes) {
  if (model.baseType() == BaseType::Free) {
    Eigen::Map<Eigen::Matrix<double, 6, W, W == 1 ? Eigen::ColMajor : Eigen::RowMajor>> X(lanes);
    FreeBaseFactor(ws).solveInPlace(X);  // the right-hand sides in lock step, a row at a time
    return;
  }
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, W, W == 1 ? Eigen::ColMajor : Eigen::RowMajor>> X(
      lanes, model.baseVelocitySize(), W);
  for (int c = 0; c < W; ++c) {
    const VectorXmax6 x = X.col(c);
    X.col(c) = ws.D_base.solve(x);
  }
}
template void baseSolveLanesInPlace<1>(const Model&, const Workspace&, double*);
template void baseSolveLanesInPlace<2>(const Model&, const Workspace&, double*);
template void baseSolveLanesInPlace<4>(const Model&, const Workspace&, double*);
template void baseSolveLanesInPlace<8>(const Model&, const Workspace&, double*);

void baseKinematics(const Model& model, const VectorRef& q_base, const VectorRef& v_base, Workspace& ws,
                    bool with_inertia) {
  const Transform X = ws.Xworld[0] = basePose(model, q_base);
  const Vec3 p = X.r;
  const bool moving = v_base.size() == model.baseVelocitySize();
  Vec6& v0 = ws.v[0];
  Vec6& c0 = ws.c[0];
  c0.setZero();
  if (model.baseType() == BaseType::Free) {
    ws.S_base.setIdentity(6, 6);
    if (moving) {
      Vec6 vB;
      vB << v_base.head<3>(), v_base.tail<3>();
      v0 = X.inverseApplyMotion(vB);  // ⁰X_B v_B
    } else {
      v0.setZero();
    }
  } else {
    const Mat3 R_plane = model.basePlacement().E.transpose();
    const Vec3 ex = R_plane.col(0), ey = R_plane.col(1), ez = R_plane.col(2);
    ws.S_base.resize(6, 3);
    ws.S_base.col(0) << ex, Vec3::Zero();
    ws.S_base.col(1) << ey, Vec3::Zero();
    ws.S_base.col(2) << p.cross(ez), ez;
    if (moving) {
      v0 = ws.S_base * v_base;
      const Vec3 p_dot = ex * v_base[0] + ey * v_base[1];
      c0.head<3>() = p_dot.cross(ez) * v_base[2];  // Ṡ₀ q̇₀: only S₀'s third column moves with p
    } else {
      v0.setZero();
    }
  }
  if (with_inertia) ws.I[0] = spatial::inverseTransformInertia(X, model.inertia(0));
}

Status baseInward(const Model& model, const Task& task, const VectorRef& tau_base, Workspace& ws) {
  const int k = model.baseVelocitySize();
  const int m = task.solverColumns();
  if (model.dof() == 0) {  // no child summed into body 0: lines 8–9 here
    ws.IA[0] = ws.I[0].matrix();
    ws.FA[0] = ws.Fbias[0];
  }
  const Mat6& IA = ws.IA[0];
  Vec6 pA = ws.FA[0];
  pA.noalias() += IA * ws.c[0];  // F^A₀ + I^A₀ Ẍ_bias,0
  const Matrix6Xmax& S = ws.S_base;
  const bool free = model.baseType() == BaseType::Free;
  if (free) {
    ws.D_base.compute(IA);  // line 13: D₀ = I^A₀ (S₀ = 1, no rotor inertia at the base)
  } else {
    ws.IAS_base.noalias() = IA * S;
    ws.D_base.compute(S.transpose() * ws.IAS_base);  // line 13 (no rotor inertia at the base)
  }
  if (ws.D_base.info() != Eigen::Success || !(ws.D_base.matrixLLT().diagonal().minCoeff() > 1e-150))
    return Status::error(StatusCode::Degenerate,
                         "the %s base has no inertia to move here (D₀ is not positive definite): the robot "
                         "needs mass whose motion the base coordinates reach",
                         toString(model.baseType()));
  // u₀ = τ₀ − S₀ᵀ(F^A₀ + I^A₀ Ẍ_bias,0), τ₀ in the sweep's coordinates: for a
  // free base the wrench ⁰X_B* τ_B whose power with Ẋ₀ is τ_Bᵀ v_B.
  if (free) {
    Vec6 tauB;
    tauB << tau_base.head<3>(), tau_base.tail<3>();
    ws.u_base = ws.Xworld[0].inverseApplyForce(tauB);
    freeBaseInward(task, pA, ws);
    return {};
  }
  ws.u_base = tau_base;  // in two steps: `tau_base − Sᵀ pA` made a heap temporary for the product
  ws.u_base.noalias() -= S.transpose() * pA;
  const MatrixXmax6 D_inverse = ws.D_base.solve(MatrixXmax6::Identity(k, k));
  ws.base_D_inverse_norm = D_inverse.cwiseAbs().colwise().sum().maxCoeff();
  const VectorXmax6 u_D = ws.D_base.solve(ws.u_base);

  // Lines 19–21 for every column (all act on body 0's subtree, the whole tree).
  ConstraintMatrix& A = ws.Ahat;
  auto sA = ws.SA_base.topLeftCorner(k, m);
  sA.noalias() = S.transpose() * A.leftCols(m);  // (S₀ᵀ A₀)
  auto sA_D = ws.SA_base_D.topLeftCorner(k, m);
  sA_D.noalias() = D_inverse * sA;
  for (int col = 0; col < m; ++col) {
    ws.L_scale[col] += sA.col(col).squaredNorm() * ws.base_D_inverse_norm;
    ws.U[col] += A.col(col).dot(ws.c[0]) + sA.col(col).dot(u_D);                 // line 20
    for (int r = col; r < m; ++r) ws.L(r, col) += sA.col(r).dot(sA_D.col(col));  // line 21, lower triangle
  }
  A.leftCols(m).noalias() -= ws.IAS_base * sA_D;  // line 19 (a free base took freeBaseInward)
  return {};
}

void baseAcceleration(const Model& model, const Task& task, Workspace& ws) {
  const int m = task.solverColumns();
  const Vec6 a_world = gravityAcceleration(task.gravity);
  if (model.baseType() == BaseType::Free) {  // S₀ = 1, I^A₀ S₀ = I^A₀: the same lines in fixed sizes
    Vec6 rhs = ws.u_base;
    rhs.noalias() -= ws.IA[0].transpose() * a_world;
    rhs.noalias() += ws.SA_base.leftCols(m) * ws.nu.head(m);  // A₀ ν
    FreeBaseFactor(ws).solveInPlace(rhs);                     // line 28
    ws.qdd_base = rhs;
    ws.a[0] = a_world + rhs + ws.c[0];  // line 29
    return;
  }
  VectorXmax6 rhs = ws.u_base;
  rhs.noalias() -= ws.IAS_base.transpose() * a_world;
  rhs.noalias() += ws.SA_base.topLeftCorner(model.baseVelocitySize(), m) * ws.nu.head(m);  // S₀ᵀ A₀ ν
  ws.qdd_base = ws.D_base.solve(rhs);                                                      // line 28
  ws.a[0] = a_world + ws.S_base * ws.qdd_base + ws.c[0];                                   // line 29
}

void publishBaseAcceleration(const Model& model, const Workspace& ws, const VectorXmax6& qdd_sweep,
                             Eigen::Ref<Eigen::VectorXd> qdd_base) {
  if (model.baseType() == BaseType::Free) {
    const Vec6 a = qdd_sweep;                // S₀ = 1 and Ẍ_bias,0 = 0: the true Ẍ₀ itself
    qdd_base = ws.Xworld[0].applyMotion(a);  // v̇_B = ᴮX₀ Ẍ₀
  } else {
    qdd_base = qdd_sweep;
  }
}

Vec6 baseTrueAcceleration(const Model& model, const Workspace& ws, const VectorRef& qdd_base) {
  if (model.baseType() == BaseType::Free) {
    Vec6 vB_dot;
    vB_dot << qdd_base.head<3>(), qdd_base.tail<3>();
    return ws.Xworld[0].inverseApplyMotion(vB_dot);  // ⁰X_B v̇_B
  }
  return ws.S_base * qdd_base + ws.c[0];
}

Vec6 baseClassicalAcceleration(const Task& task, const Workspace& ws) {
  return classicalAtPoint(ws.a[0] - gravityAcceleration(task.gravity), ws.v[0], ws.Xworld[0].r);
}

void baseGeneralizedForce(const Model& model, const Workspace& ws, const Vec6& F0, Eigen::Ref<Eigen::VectorXd> out) {
  if (model.baseType() == BaseType::Free)
    out = ws.Xworld[0].applyForce(F0);  // τ_B = ⁰X_Bᵀ F₀ = ᴮX₀* F₀
  else
    out = ws.S_base.transpose() * F0;
}

void baseMotionColumns(const Model& model, const Workspace& ws, Matrix6Xmax& S_user) {
  if (model.baseType() != BaseType::Free) {
    S_user = ws.S_base;  // planar: the sweep's coordinates are the user's
    return;
  }
  // ⁰X_B = [R  p×R; 0  R] (R = ⁰R_B, p the base origin): v_B's unit twists
  // seen from the world origin.
  const Transform& X = ws.Xworld[0];  // ᴮX₀
  S_user.resize(6, 6);
  for (int k = 0; k < 6; ++k) S_user.col(k) = X.inverseApplyMotion(Vec6::Unit(k));
}

Status checkFloatingVelocityVector(const Model& model, const char* name, const VectorRef& x) {
  if (x.size() != model.nv())
    return Status::error(StatusCode::SizeMismatch,
                         "%s has %ld entries, the model has nv = %d (%d base velocity coordinates + %d joints)", name,
                         static_cast<long>(x.size()), model.nv(), model.baseVelocitySize(), model.dof());
  return checkVector(name, x, model.nv());  // the size holds: only the finiteness message can come back
}

Status workspaceBaseMismatch(const Model& model, const Workspace& ws) {
  // One of the two of the right size: the workspace fits, the other was resized since.
  if (ws.tau.size() == model.nv())
    return Status::error(StatusCode::SizeMismatch,
                         "workspace result H is %ldx%ld, expected %dx%d (a workspace's results must keep their sizes)",
                         static_cast<long>(ws.H.rows()), static_cast<long>(ws.H.cols()), model.nv(), model.nv());
  if (ws.H.rows() == model.nv() && ws.H.cols() == model.nv())
    return Status::error(StatusCode::SizeMismatch,
                         "workspace result tau has %ld entries, expected nv = %d (a workspace's results must keep "
                         "their sizes)",
                         static_cast<long>(ws.tau.size()), model.nv());
  return Status::error(StatusCode::ModelMismatch,
                       "workspace was made for a model with nv = %ld, this one has nv = %d (a %s base and %d joints)",
                       static_cast<long>(ws.tau.size()), model.nv(), toString(model.baseType()), model.dof());
}

}  // namespace zwang::internal
