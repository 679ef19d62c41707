/// \file
/// MuJoCo's soft joint friction against zwang's exact friction (docs/mujoco.md, "Soft friction against exact
/// friction"): part of the optional component zwang_mujoco, built only when MuJoCo is found.
///
/// The robot of an MJCF file rests (q̇ = 0) in a posture under its gravity, with joint torques τ and its
/// frictionloss. zwang: solveWithFriction gives each DOF's state (stick, slip…), μ* and q̈ (exactly 0 where it
/// sticks). MuJoCo, in three settings of its solver (MujocoSetting): mj_forward gives qacc and the friction
/// torque (the efc rows of type mjCNSTR_FRICTION_DOF), and mj_step from rest gives the drift |q(t) − q(0)| per DOF
/// after the requested times. Both sides compile the same text: MuJoCo's contacts and actuators are disabled
/// (zwang takes joint torques and has no contacts) and its joint springs zeroed (zwang has none); a floating base
/// (a free joint on the world's only child) is fixed by deleting the free joint from the text before both
/// compile, with the keyframes (their qpos would no longer fit).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "zwang/friction_result.hpp"
#include "zwang/model.hpp"

namespace zwang {

/// One of MuJoCo's solver settings compared: the name and what it changes.
struct MujocoSetting {
  std::string name;         ///< "default", "noslip" or "tight"
  std::string description;  ///< what it changes, for tables and docs
};

/// A posture to compare: the robot at rest in q with joint torques τ + s·G(q) (G: the torques that hold it
/// against gravity, s = gravity_compensation).
struct ComparePosture {
  std::string name;                 ///< shown in tables ("home", "random 1", a state file's name)
  Eigen::VectorXd q;                ///< Model::nq() entries, MuJoCo's qpos of the (base-fixed) model
  Eigen::VectorXd tau;              ///< Model::nv() entries; empty: zero
  double gravity_compensation = 0;  ///< s: τ += s·G(q); 0.95 leaves 5 % of the gravity load to friction
};

/// How to compare.
struct MujocoCompareOptions {
  int random_postures = 3;          ///< drawn by randomConfiguration after the home posture (generated postures only)
  std::uint64_t seed = 1;           ///< randomConfiguration's state
  double gravity_compensation = 0;  ///< s of the generated postures
  std::vector<double> seconds = {1, 10};  ///< the drift is reported after each of these simulated times [s]
  double sample_interval = 0.01;          ///< the drift's time series is sampled this often [s]
  double frictionloss = -1;               ///< ≥ 0: every DOF's frictionloss in both (overrides the file's)
  int noslip_iterations = 10;             ///< of the "noslip" setting
};

/// One MuJoCo setting on one posture; vectors per DOF (Model::dof() entries, zwang's order).
struct MujocoSettingResult {
  Eigen::VectorXd qacc;          ///< mj_forward's qacc at rest
  Eigen::VectorXd tau_friction;  ///< the frictionloss rows' force on each DOF (MuJoCo's sign: what acts on it)
  Eigen::MatrixXd drift;         ///< row r: |q(seconds[r]) − q(0)| per DOF after mj_step from rest
  Eigen::VectorXd times;         ///< the sample times of drift_series [s], 0 first
  Eigen::MatrixXd drift_series;  ///< row r: |q(times[r]) − q(0)| per DOF
  /// The warnings MuJoCo raised while simulating (mjData::warning, by name: "bad qacc" means it reset the
  /// state), empty when none; the comparison silences MuJoCo's handler, which would print them on stdout.
  std::vector<std::string> mujoco_warnings;
};

/// One posture: zwang's exact solve and MuJoCo's settings (in MujocoComparison::settings' order).
struct PostureComparison {
  std::string name;                         ///< ComparePosture::name
  Eigen::VectorXd q;                        ///< the posture
  Eigen::VectorXd tau;                      ///< the torques applied (τ + s·G(q))
  Eigen::VectorXd qdd;                      ///< zwang's q̈ per DOF
  Eigen::VectorXd mu;                       ///< μ* per DOF (the joint feels τ − μ)
  Eigen::VectorXd tau_friction;             ///< zwang's friction torque per DOF (−μ*), comparable with MuJoCo's
  std::vector<JointState> state;            ///< per DOF
  std::vector<MujocoSettingResult> mujoco;  ///< per MuJoCo setting
};

/// The whole comparison of one model.
struct MujocoComparison {
  std::string model_name;                   ///< `<mujoco model>`
  bool base_fixed = false;                  ///< the file's floating base was fixed (its free joint deleted)
  double timestep = 0;                      ///< MuJoCo's `<option timestep>` [s]
  std::string integrator;                   ///< MuJoCo's integrator ("Euler", "RK4", "implicit")
  std::vector<std::string> dof_names;       ///< per DOF
  Eigen::VectorXd frictionloss;             ///< per DOF, as both used it
  std::vector<double> seconds;              ///< as asked, ascending
  std::vector<MujocoSetting> settings;      ///< default, noslip, tight
  std::vector<PostureComparison> postures;  ///< as given or generated
  std::vector<std::string> warnings;        ///< the loader's warnings on the compared model
};

/// Per row of `drift` (a setting's drift or drift_series on `posture`): the largest entry over the DOFs zwang
/// holds (state Stick), or over all DOFs when none sticks.
Eigen::VectorXd heldDriftMax(const PostureComparison& posture, const Eigen::MatrixXd& drift);

/// The model the comparison compiles from `path` (base fixed, as MujocoComparison says): for a state file's q.
Model mujocoCompareModel(const std::string& path);

/// Compare at `postures`, or (empty) at the generated ones: "home" (the file's first keyframe, else the neutral
/// configuration) and options.random_postures drawn within the limits. Throws ModelError naming the file for a
/// model MuJoCo or zwang refuses (a free joint that is not the floating base among them), std::invalid_argument
/// naming the posture or option for bad input (sizes, non-finite values, times beyond an hour). It replaces
/// MuJoCo's global warning handler while it runs: one comparison at a time (a mutex serialises them), and no
/// other MuJoCo user on another thread meanwhile.
MujocoComparison compareWithMujoco(const std::string& path, const std::vector<ComparePosture>& postures,
                                   const MujocoCompareOptions& options = {});

}  // namespace zwang
