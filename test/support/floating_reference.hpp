// Dense reference for FLOATING-BASE trees (docs/solver.md, "The dense
// reference", extended to a moving body 0), computed straight from the world
// pose of every link: no recursive algorithm, no code shared with the library
// (only the small spatial helpers and the input types of dense_reference.hpp).
// test_floating_reference.cpp checks it against MuJoCo (mj_forward, mj_inverse,
// mj_fullM) and against physics in closed form.
//
// Body 0 (links[0] and the links welded to it) is attached to the world by
//  * Free:   q = [x, y, z, q_w, q_x, q_y, q_z, joints…]: the base origin p in the
//            world and the unit quaternion of R = ⁰R_base (w first, as MuJoCo's
//            qpos); v = [v; ω; q̇ joints…] with v = Rᵀṗ the velocity of the base
//            origin and ω the angular velocity, BOTH in base axes (Pinocchio's
//            free-flyer): ṗ = R v, Ṙ = R[ω]×. v̇ = d/dt of that vector, the
//            spatial acceleration of the base in base coordinates:
//            [Rᵀp̈ − ω × v; Rᵀω̇_world];
//  * Planar: q = [x, y, ψ, joints…], v = [ẋ, ẏ, ψ̇, …] in the plane's axes, the
//            plane frame P a pose in the world (⁰T_P, default identity: the
//            world's XY plane at height 0), base pose = P ∘ translate(x, y, 0)
//            ∘ rot_z(ψ); v̇ = [ẍ, ÿ, ψ̈, …];
//  * Fixed:  no base coordinates (the dense reference of dense_reference.hpp,
//            for cross-checks).
// τ has nv entries; the base entries are the generalized force dual to the
// base velocity coordinates (normally 0: unactuated): for Free, a wrench
// [f; n] at the base origin in BASE axes; for Planar, the forces along the
// plane's x, y and the moment about the plane normal through the base origin.
//
// Formulation (world-frame Plücker coordinates at the world origin, linear part
// first, as dense_reference.hpp): J_i is 6×nv; its base columns are
//   Free:   ⁰X_B, the base unit twists in world coordinates at the origin:
//           [R e_k; 0] (k = x, y, z), [p × R e_k; R e_k];
//   Planar: [u_x; 0], [u_y; 0], [p × u_z; u_z], u = the plane's axes in the
//           world, p the base origin;
// and its joint columns s_j = ⁰X_j S_j as in the fixed-base reference. J̇ v:
// every column moves with its body, d/dt s = v_body × s (Free: the base's six
// with the base, so J̇_B v = v_B × v_B = 0; Planar: the two translations are
// constant, d/dt [p × u_z; u_z] = [ṗ × u_z; 0]). Then
//   H = Σ_i J_iᵀ I_i J_i + diag(0 (base), d (joints)),
//   C = Σ_i J_iᵀ (I_i J̇_i v + v_i ×* I_i v_i − f_ext,i − I_i [g; 0]),
//   KKT [H −Gᵀ; G 0][v̇; ν] = [τ − C; γ], constraint rows and mimic rows exactly
//   as denseDynamics (ConstraintInput; +A ν acts on the constrained link).
#pragma once

#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "support/chain_spec.hpp"
#include "support/dense_reference.hpp"
#include "support/random_chain.hpp"

namespace zwang::testing {

// How links[0] is attached to the world.
enum class BaseKind { Fixed, Free, Planar };
// "fixed", "free", "planar".
const char* toString(BaseKind kind);

struct FloatingBase {
  BaseKind kind = BaseKind::Free;
  // Planar: ⁰T_P, the plane frame's pose in the world (x, y span the plane, z
  // is the yaw axis). Must be identity otherwise (std::invalid_argument).
  // (zwang's ModelBuilder::setBase takes ᴾX_world, the Plücker transform from
  // world to plane coordinates: Transform::fromPose(plane.linear(), plane.translation()).)
  Eigen::Isometry3d plane = Eigen::Isometry3d::Identity();

  int baseConfigurationSize() const { return kind == BaseKind::Free ? 7 : kind == BaseKind::Planar ? 3 : 0; }
  int baseVelocitySize() const { return kind == BaseKind::Free ? 6 : kind == BaseKind::Planar ? 3 : 0; }
  int nq(const ChainSpec& spec) const { return baseConfigurationSize() + spec.nq(); }
  int nv(const ChainSpec& spec) const { return baseVelocitySize() + spec.dof(); }
};

struct FloatingInput {
  Eigen::VectorXd q;    // nq (Free: the quaternion within 1e-6 of unit length; it is normalised)
  Eigen::VectorXd v;    // nv
  Eigen::VectorXd tau;  // nv (base entries: generalized force on the base coordinates, normally 0)
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};
  std::vector<WrenchInput> wrenches;         // as DynamicsInput (any link, the base too)
  std::vector<ConstraintInput> constraints;  // as DynamicsInput (any link, absolute or relative)
  int constraintRows() const;
};

// The base pose ⁰T_B for q (nq entries or just the base's): Free → translate(p)·R(quat), Planar →
// plane·translate(x, y, 0)·rot_z(ψ), Fixed → identity.
Eigen::Isometry3d basePose(const FloatingBase& base, const Eigen::VectorXd& q);

// q̇ (nq entries) for the velocity v (nv): Free ṗ = R v_lin, quaternion rate ½ q ⊗ (0, ω) (w first),
// Planar and joints q̇ = v.
Eigen::VectorXd configurationRate(const FloatingBase& base, const Eigen::VectorXd& q, const Eigen::VectorXd& v);

// q after moving for time dt with the generalized velocity v held constant (classical RK4 in `steps`
// steps on q̇ = configurationRate(q, v), the quaternion normalised at the end). For finite differences.
Eigen::VectorXd integrateConfiguration(const FloatingBase& base, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                       double dt, int steps = 4);

// Everything that depends only on (q, v), for every link (index as spec.links).
// The dense reference's kinematics (dense_reference.hpp), over the whole
// velocity vector: poses[0] is the base pose, J_i is 6×nv with the base
// columns first, dof_of_joint indexes v (base entries first), and reflected is
// 0 on the base entries.
using FloatingKinematics = DenseKinematics;

FloatingKinematics floatingKinematics(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q,
                                      const Eigen::VectorXd& v);

struct FloatingResult {
  Eigen::MatrixXd H;      // nv×nv
  Eigen::VectorXd C;      // nv: Coriolis, centrifugal, gravity, −external
  Eigen::VectorXd qdd;    // v̇ (nv), base entries first (Free: [Rᵀp̈ − ω × v; Rᵀω̇_world])
  Eigen::VectorXd nu;     // ν: the input's rows (constraint by constraint), then one per mimic joint
  Eigen::VectorXd tau_c;  // Gᵀ ν (nv)
  // τ + Gᵀν with each mimic joint's entry carried by its resolved leader (as DenseResult::tau_control).
  Eigen::VectorXd tau_control;
  int user_rows = 0, mimic_rows = 0;
  double gauss = 0.0;  // Z(v̇) at the solution (floatingGaussFunction)
  Eigen::MatrixXd G;   // m×nv: G v̇ = gamma
  Eigen::VectorXd gamma;
  std::vector<Eigen::Isometry3d> poses;        // ⁰T_link
  std::vector<Vector6d> acc_world;             // classical [p̈; ω̇] of every link origin, world axes
  std::vector<Vector6d> acc_local;             // the same in the link's own axes
  Vector6d base_acc_world = Vector6d::Zero();  // classical [p̈; ω̇] of the base origin, world axes (= acc_world[0])
  double h_condition = 0.0;                    // cond₂(H)
  int constraint_rank = 0;                     // rank of G (relative threshold 1e-10)
  double coupling_condition = 1.0;             // cond₂(G H⁻¹ Gᵀ) (1 without rows)
  double kkt_condition = 0.0;                  // cond₂ of the KKT matrix
  bool wellConditioned(double max_condition = 1e6) const {
    return h_condition < max_condition && coupling_condition < max_condition;
  }
};

// Forward dynamics: the KKT system in long double (full-pivot LU, one refinement step).
// Joint rows and contacts (ConstraintInput::joint, ::contact) are read here: a
// joint row is the row e_jᵀ of its joint's coordinate; a contact is in G and
// ν like any row, and out of tau_c and tau_control (τ_c = Gᵀ diag(motorRows) ν).
FloatingResult floatingDynamics(const ChainSpec& spec, const FloatingBase& base, const FloatingInput& input);

// A draw the tests keep: the KKT system well conditioned (H and the coupling matrix below 1e6) and every row
// reachable (G of full row rank, its smallest singular value at least 1e-6).
bool wellPosed(const FloatingResult& dense);

// Per row of G (the input's rows, then `rows` − constraintRows() mimic rows):
// 1 when the motors carry its force, 0 for a contact's.
Eigen::VectorXd motorRows(const FloatingInput& input, int rows);

// Z(v̇) = Σ_i ½ a_iᵀ I_i a_i + (v_i ×* I_i v_i − f_ext,i − f_grav,i)ᵀ a_i + Σ_j ½ d_j v̇_j² − τ_j v̇_j
// (base entries included in the τ sum), a_i = J_i v̇ + J̇_i v, for any v̇ (constraints not applied).
double floatingGaussFunction(const ChainSpec& spec, const FloatingBase& base, const FloatingInput& input,
                             const Eigen::VectorXd& qdd);

// Inverse dynamics τ = H v̇ + C (nv; the base entries are the generalized force the base would need).
Eigen::VectorXd floatingInverseDynamics(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q,
                                        const Eigen::VectorXd& v, const Eigen::VectorXd& qdd,
                                        const Eigen::Vector3d& gravity, const std::vector<WrenchInput>& wrenches = {});

// H alone (nv×nv, the CRBA's answer): Σ_i J_iᵀ I_i J_i + diag(d).
Eigen::MatrixXd floatingMassMatrix(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q);

// Classical acceleration [p̈; ω̇] of `link`'s origin for any (q, v, v̇), world or link axes.
Vector6d floatingLinkAcceleration(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q,
                                  const Eigen::VectorXd& v, const Eigen::VectorXd& qdd, const std::string& link,
                                  Axes axes);

// Total spatial momentum Σ_i I_i J_i v at the world origin, [linear; angular about the origin].
Vector6d floatingMomentum(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q,
                          const Eigen::VectorXd& v);

// ---- Random floating problems ----------------------------------------------------------------

struct RandomFloatingOptions {
  double free_probability = 0.5;   // else Planar (never Fixed)
  double chain_probability = 0.2;  // randomChain(chain) instead of randomTree(tree)
  RandomChainOptions chain{};      // defaults: 1–12 moving joints
  RandomTreeOptions tree = [] {
    RandomTreeOptions t;
    t.min_moving_joints = 1;
    t.max_moving_joints = 30;
    return t;
  }();
  double identity_plane_probability = 0.3;  // Planar: P = identity, else a random pose (offset ≤ 1 m)
  double base_position_scale = 2.0;         // base coordinates x, y, z uniform in ±scale
  double base_speed_scale = 2.0;            // base velocity entries uniform in ±scale
  double base_tau_probability = 0.0;        // that the base gets a random generalized force (else 0)
  // Joint state, τ, gravity, wrenches and constraints as randomProblem (random_problem.hpp):
  int max_constraint_rows = 6;
  int max_constraint_frames = 3;
  int max_wrenches = 2;
  double gravity_probability = 0.8;
  double relative_probability = 0.0;
  double base_link_probability = 0.2;  // that each wrench or constraint is moved onto the base link
};

// A random floating base (kind, plane) and input for `spec` (a spec with the base link only gets no wrenches or
// constraints).
FloatingBase randomFloatingBase(std::mt19937_64& rng, const RandomFloatingOptions& options = {});
FloatingInput randomFloatingInput(std::mt19937_64& rng, const ChainSpec& spec, const FloatingBase& base,
                                  const RandomFloatingOptions& options = {});

struct FloatingProblem {
  ChainSpec spec;
  FloatingBase base;
  FloatingInput input;
};
// The spec, then the base, then the input (draws in that order).
FloatingProblem randomFloatingProblem(std::mt19937_64& rng, const RandomFloatingOptions& options = {});

}  // namespace zwang::testing
