// Dense reference for constrained dynamics (docs/solver.md, "The dense
// reference"), computed straight from a ChainSpec with the world pose of every link
// — no recursive algorithm, no code shared with the library.
//
// Formulation: world-frame Plücker coordinates at the world origin, linear part
// first (docs/conventions.md): motion [v; ω], force [f; n].
//   J_i       6×n spatial Jacobian of link i, columns s_j = ⁰X_j S_j for the
//             moving joints between the base and link i (zero otherwise);
//   v_i       = J_i q̇ (spatial velocity);
//   J̇_i q̇     = Σ_j (v_child(j) × s_j) q̇_j   (d/dt s_j = v × s_j, closed form);
//   a_i       = J_i q̈ + J̇_i q̇  (the TRUE spatial acceleration; gravity is a force);
//   I_i       world-frame spatial inertia of link i (every link, also those
//             behind fixed joints, at its own pose);
//   H         = Σ_i J_iᵀ I_i J_i + diag(d),  d = reflected rotor inertias;
//   C         = Σ_i J_iᵀ (I_i J̇_i q̇ + v_i ×* I_i v_i − f_ext,i − f_grav,i),
//               f_grav,i = I_i [g; 0];
//   KKT       [H −Gᵀ; G 0] [q̈; ν] = [τ − C; γ]  (H q̈ + C = τ + Σ Jᵀ A ν).
// Mimic joints (JointSpec::mimic, q_m = a·q_k + b with k its DIRECT leader):
// one row e_mᵀ − a·e_kᵀ each (γ = 0), after the user's rows, in dof order.
// Chains of mimics are not resolved for the rows (the direct rows span the
// same constraint as the resolved ones); only the folded control torque uses
// the resolved laws (ChainSpec::mimicLaws).
// A constraint column [l; r] (unit force l and moment r acting at the link
// origin) constrains lᵀ p̈ + rᵀ ω̇ = b, p̈ the classical acceleration of the link
// origin; the wrench A ν is applied to the link at its origin (docs/solver.md, "Sign of ν").
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "support/chain_spec.hpp"

namespace zwang::testing {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix6Xd = Eigen::Matrix<double, 6, Eigen::Dynamic>;

// Which axes the components of a link-attached quantity use. Either way it
// refers to the link ORIGIN (a wrench acts there, an acceleration is that of the
// origin); `World` is what docs/conventions.md also calls "aligned".
// Reference: for a relative constraint, the reference link's axes.
enum class Axes { Local, World, Reference };

// A wrench [f; n] applied to `link` at its origin.
struct WrenchInput {
  std::string link;
  Vector6d wrench = Vector6d::Zero();
  Axes axes = Axes::Local;
};

// Aᵀ Ẍ = b on `link`: A is 6×m (columns [l; r]), b the m set points in terms of
// the true classical acceleration of the link origin.
//
// With `relative_to` (another link r): the acceleration of link's origin and
// angular velocity as seen riding on r, in world axes
//   p̈_rel = d̈ − α_r × d − 2 ω_r × ḋ + ω_r × (ω_r × d),   d = p − p_r,
//   ω̇_rel = α − α_r − ω_r × (ω − ω_r),
// (the derivatives in r's frame of R_rᵀ d and R_rᵀ(ω − ω_r), turned back to
// world axes), dotted with the columns; the wrench A ν acts on link and −A ν
// on r, both at link's origin.
//
// Two kinds of row only floatingDynamics reads (denseDynamics refuses them;
// a fixed base is BaseKind::Fixed there):
//  * a joint row (Task::addJointConstraint), `joint` ≥ 0: q̈ of that moving
//    joint (dof index) = b(0); A has one column, unused, and link is unused.
//    Its force is a generalized force on the joint's own coordinate (its motor);
//  * a contact (Task::addContact), `contact`: an absolute frame constraint
//    whose force the environment supplies, so it moves the robot like any
//    row but is left out of τ_c and τ_control.
struct ConstraintInput {
  std::string link;
  Matrix6Xd A;
  Eigen::VectorXd b;
  Axes axes = Axes::Local;
  std::string relative_to;  // empty: absolute (relative to the world)
  int joint = -1;           // ≥ 0: a joint row (see above)
  int base_dof = -1;        // ≥ 0: the same on entry base_dof of a floating base's velocity (floatingDynamics only)
  bool contact = false;     // the environment's force (see above)
};

struct DynamicsInput {
  Eigen::VectorXd q, qd, tau;  // each of length spec.dof()
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};
  std::vector<WrenchInput> wrenches;
  std::vector<ConstraintInput> constraints;
  int constraintRows() const;
};

// Everything that depends only on (q, q̇), for every link (index as spec.links).
struct DenseKinematics {
  std::vector<Eigen::Isometry3d> poses;  // ⁰T_link
  std::vector<Eigen::MatrixXd> J;        // 6×n spatial Jacobian at the world origin
  std::vector<Vector6d> v;               // spatial velocity J q̇
  std::vector<Vector6d> bias;            // J̇ q̇
  std::vector<Matrix6d> inertia;         // world-frame spatial inertia
  std::vector<int> dof_of_joint;         // joints[k] → index in q, or −1 when fixed
  Eigen::VectorXd reflected;             // d_j, one per dof
};

DenseKinematics denseKinematics(const ChainSpec& spec, const Eigen::VectorXd& q, const Eigen::VectorXd& qd);

struct DenseResult {
  Eigen::MatrixXd H;      // n×n joint-space inertia
  Eigen::VectorXd C;      // bias (Coriolis, centrifugal, gravity, −external)
  Eigen::VectorXd qdd;    // q̈
  Eigen::VectorXd nu;     // ν, rows in input order (constraint by constraint), then one per mimic joint
  Eigen::VectorXd tau_c;  // Σ J_iᵀ A_i ν_i = Gᵀ ν (physical constraint torques, mimic couplings included)
  // τ + Gᵀν with every mimic joint's entry carried by its resolved leader:
  // τ_ctrl[l] += a·τ_ctrl[m], τ_ctrl[m] = 0 (power equivalence, q̇_m = a·q̇_l);
  // τ + tau_c without mimic joints.
  Eigen::VectorXd tau_control;
  int user_rows = 0;   // the input's constraint rows (the first rows of G and ν)
  int mimic_rows = 0;  // one per mimic joint (the last rows of G and ν)
  double gauss = 0.0;  // Z(q̈) of docs/theory.md §1 at the solution
  Eigen::MatrixXd G;   // m×n constraint rows: G q̈ = gamma
  Eigen::VectorXd gamma;
  std::vector<Eigen::Isometry3d> poses;  // ⁰T_link for every link
  std::vector<Vector6d> acc_world;       // classical [p̈; ω̇] of every link origin, world axes
  std::vector<Vector6d> acc_local;       // the same in the link's own axes
  // Conditioning, so that tests can skip ill-posed draws:
  double h_condition = 0.0;         // cond₂(H)
  int constraint_rank = 0;          // rank of G (relative threshold 1e-10)
  double coupling_condition = 1.0;  // cond₂(G H⁻¹ Gᵀ) (1 without constraints)
  double kkt_condition = 0.0;       // cond₂ of the KKT matrix
  bool wellConditioned(double max_condition = 1e6) const {
    return h_condition < max_condition && coupling_condition < max_condition;
  }
};

// Solves the KKT system (full-pivot LU in long double, one refinement step).
DenseResult denseDynamics(const ChainSpec& spec, const DynamicsInput& input);

// Z(q̈) = Σ_i ½ a_iᵀ I_i a_i + (v_i ×* I_i v_i − f_ext,i − f_grav,i)ᵀ a_i
//        + Σ_j ½ d_j q̈_j² − τ_j q̈_j    (docs/solver.md, "The Gauss function value"; a_i true spatial accelerations),
// for any q̈ (constraints are not applied). Frame-invariant.
double gaussFunction(const ChainSpec& spec, const DynamicsInput& input, const Eigen::VectorXd& qdd);

// τ = H q̈ + C for the given wrenches and gravity (inverse dynamics).
Eigen::VectorXd denseInverseDynamics(const ChainSpec& spec, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                     const Eigen::VectorXd& qdd, const Eigen::Vector3d& gravity,
                                     const std::vector<WrenchInput>& wrenches = {});

// Classical 6×n Jacobian of `link`: maps q̇ to [ṗ; ω] of the link origin, with
// components in world or link axes.
Eigen::MatrixXd linkJacobian(const ChainSpec& spec, const Eigen::VectorXd& q, const std::string& link, Axes axes);

// Classical acceleration [p̈; ω̇] of `link`'s origin for any (q, q̇, q̈).
Vector6d linkAcceleration(const ChainSpec& spec, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                          const Eigen::VectorXd& qdd, const std::string& link, Axes axes);

// Small spatial-algebra helpers of the reference (linear part first).
Eigen::Matrix3d skew3(const Eigen::Vector3d& a);  // skew3(a) b = a × b
Matrix6d motionCross(const Vector6d& v);          // v× = [ω× v×; 0 ω×]
Matrix6d forceCross(const Vector6d& v);           // v×* = −(v×)ᵀ
// Spatial inertia at the world origin of a body with mass m, COM c and
// rotational inertia Ic about the COM (all world components).
Matrix6d spatialInertia(double m, const Eigen::Vector3d& c, const Eigen::Matrix3d& Ic);

}  // namespace zwang::testing
