// MuJoCo (Debian's libmujoco-dev 2.2.2) as an oracle, the part every test that
// uses it shares (test_mujoco, test_floating_reference, test_mujoco_floating):
// an mjModel and mjData compiled from MJCF text in memory (mjcf_writer.hpp
// writes it), our coordinates mapped to MuJoCo's by joint name, and the change
// of velocity coordinates between our floating base and MuJoCo's. No zwang
// solver code is in it: the tests hand zwang the same spec through the
// ModelBuilder (random_problem.hpp) and compare. Compiled into its own small
// library (test/CMakeLists.txt, zwang_mujoco_bridge) linked only by those
// tests: zwang_test_support is built without MuJoCo.
//
// The conventions, which the tests check rather than assume:
//  * MuJoCo's world is ours (links[0] sits on the world or on the base joint at
//    the identity or at the plane pose; mjcf_writer.hpp);
//  * joints are mapped by name (mj_name2id), never by position: MuJoCo numbers
//    its dofs depth first through the MJCF body tree;
//  * hinge and slide joints: qpos, qvel, qacc, qfrc_* are our q, q̇, q̈, τ;
//  * ball joints (our spherical): the same: qpos = the child's quaternion in the joint frame, w x y z, as ours;
//    qvel = ω in the child (body) frame, as ours; qfrc = the moment in the child frame;
//  * free joints in the spec (on top-level bodies: the child's pose in the world) as the free base below;
//  * Planar base (slide x, slide y, hinge z in the plane's axes): the same;
//  * Free base: qpos = [p; w x y z] is our q, but MuJoCo's free joint has
//      u = qvel = [ṗ in WORLD axes; ω in BODY axes],  u̇ = qacc = [p̈ world; ω̇ body],
//    where ours is v = [Rᵀṗ; ω] (both in base axes, Pinocchio's free-flyer). With
//    T = blockdiag(R, 1₃, 1 (joints)), u = T v and u̇ = T v̇ + Ṫ v, Ṫ v = [R (ω × v_lin); 0], so
//      v = [Rᵀ u_lin; u_ang],   v̇ = [Rᵀ p̈ − ω × Rᵀ ṗ; ω̇]  (= [Rᵀ u̇_lin − ω × v_lin; u̇_ang]);
//    generalized forces are dual (the same power τᵀv = fᵀu): f_mj = T⁻ᵀ τ = [R τ_lin; τ_ang] (a force at the base
//    origin in world axes, a moment about it in base axes), τ = Tᵀ f_mj; the mass matrices H = Tᵀ M_mj T (the same
//    kinetic energy);
//  * an external wrench [f; n] at a link origin p (world axes) reaches MuJoCo's forward dynamics as
//    xfrc_applied = [f; n + (p − c) × f] at the body's COM c; mj_inverse's qfrc_inverse does not include applied
//    forces, so the wrenches' generalized forces (mj_applyFT at p) are taken out of it.
#pragma once

#include <string>
#include <vector>

#include <mujoco/mujoco.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "support/chain_spec.hpp"
#include "support/dense_reference.hpp"
#include "support/floating_reference.hpp"

namespace zwang::testing {

// An mjModel and its mjData, compiled from MJCF text handed over in memory
// through MuJoCo's virtual file system (mj_defaultVFS, mj_makeEmptyFileVFS,
// mj_findFileVFS, mj_loadXML, mj_deleteVFS: mujoco.h of 2.2.2; the VFS holds
// the file's bytes in a buffer it allocates and frees itself). Throws
// std::runtime_error with MuJoCo's message and the document when it refuses it.
class Mujoco {
 public:
  explicit Mujoco(const std::string& xml);
  ~Mujoco();
  Mujoco(const Mujoco&) = delete;
  Mujoco& operator=(const Mujoco&) = delete;

  const mjModel* m() const { return model_; }
  mjData* d() const { return data_; }

 private:
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
};

// For each of our q entries MuJoCo's qpos address, for each of our v entries its dof address (base coordinates
// first, then the spec's moving joints in order).
struct MujocoCoordinates {
  std::vector<int> qpos, dof;
};

// The map for `spec` on `base` as toMjcf(spec, gravity, base) writes it. Throws std::runtime_error naming the joint
// when one is missing or of another type, or when MuJoCo's nq, nv are not ours.
MujocoCoordinates mapCoordinates(const ChainSpec& spec, const FloatingBase& base, const mjModel* m);

// x (our order) into MuJoCo's array at the mapped addresses, and back.
void scatter(const Eigen::VectorXd& x, const std::vector<int>& address, mjtNum* to);
Eigen::VectorXd gather(const mjtNum* from, const std::vector<int>& address);

// T with u_mujoco = T v (our order, nv × nv): the identity but for R = ⁰R_child on the linear velocity of a free
// base and of each free spec joint (which hangs from the world: mjcf_writer.hpp).
Eigen::MatrixXd mujocoVelocityMap(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q);
// Ṫ v: [R (ω × v_lin); 0] on each free joint's entries (the base's and the spec's), 0 elsewhere.
Eigen::VectorXd mujocoVelocityMapRate(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q,
                                      const Eigen::VectorXd& v);

// ⁰T_link of every spec link (index as spec.links) as MuJoCo placed its body (xpos, xmat), after mj_kinematics (or
// mj_forward) on the qpos in d.
std::vector<Eigen::Isometry3d> mujocoLinkPoses(const ChainSpec& spec, const mjModel* m, const mjData* d);

// A wrench input as [f; n] at its link's origin in world axes, the link at `pose`.
Vector6d worldWrench(const WrenchInput& w, const Eigen::Isometry3d& pose);

// Adds the wrenches (each at the origin of the link of its name, pose poses[spec.linkIndex(link)]) to MuJoCo's
// xfrc_applied as [f; n + (p − c) × f] at the body's COM c (world axes).
void addWrenchesToXfrc(const ChainSpec& spec, const std::vector<Eigen::Isometry3d>& poses,
                       const std::vector<WrenchInput>& wrenches, const mjModel* m, mjData* d);

// The generalized forces (MuJoCo's nv dofs, its order) of the same wrenches, by mj_applyFT at each link origin; d must
// hold the positions (mj_kinematics and mj_comPos, or a whole mj_forward).
std::vector<mjtNum> wrenchGeneralizedForces(const ChainSpec& spec, const std::vector<Eigen::Isometry3d>& poses,
                                            const std::vector<WrenchInput>& wrenches, const mjModel* m, mjData* d);

}  // namespace zwang::testing
