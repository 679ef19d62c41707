// Scratch memory of the friction extension, sized once per workspace.
#pragma once

#include "internal/box_qp.hpp"
#include "internal/popov_vereshchagin.hpp"
#include "zwang/workspace.hpp"

namespace zwang::internal {

struct FrictionScratch {
  FrictionScratch(int dof, int bodies, int capacity)
      : f(dof), fc(dof), b(dof), tau_eff(dof), qdd0(dof), lo(dof), hi(dof),
        c(dof), qdd_star(dof), v(dof), mu(dof), mu_alt(dof), h(dof), z(dof), za(dof), tau_total(dof), sub_mu(dof),
        sub_lo(dof), sub_hi(dof), sub_index(dof), perm(dof),
        nu0(capacity), dU(capacity, dof), du(bodies, dof), dnu(capacity, dof), dqdd(dof, dof), dF(6, dof),
        da(6, dof), P(dof, dof),
        null_basis(dof, dof), V(dof, dof), qp(dof) {}
  Eigen::VectorXd f, fc, b;         // breakaway, kinetic, viscous per joint
  Eigen::VectorXd tau_eff;          // τ − kinetic friction of the moving joints
  Eigen::VectorXd qdd0;             // q̈(μ = 0)
  Eigen::VectorXd lo, hi;           // Λ on Θ₀ (k entries)
  Eigen::VectorXd c;                // q̈_Θ(0)
  Eigen::VectorXd qdd_star;         // q̈*_Θ at the maximiser
  Eigen::VectorXd v;                // the one curvature direction of K_ΣΣ (when its rank is 1)
  Eigen::VectorXd mu, mu_alt, h, z, za, tau_total;
  Eigen::VectorXd sub_mu, sub_lo, sub_hi;  // restricted to the sticking joints
  Eigen::VectorXi sub_index;               // positions in Θ₀ of the sticking joints
  Eigen::VectorXi perm;                    // pivot order (near null space)
  Eigen::VectorXd nu0;              // ν of the μ = 0 pass (solver order)
  Eigen::MatrixXd dU;               // capacity × k: δU₀ per unit torque
  Eigen::MatrixXd du;               // bodies × k: δu_i per unit torque at each stuck joint (sweep scratch)
  Eigen::MatrixXd dnu;              // capacity × k: δν per unit torque
  Eigen::MatrixXd dqdd;             // dof × k: δq̈ per unit torque
  Matrix6X dF, da;                  // 6 × k: δF^A and δẌ per unit torque (sweep scratch)
  Eigen::MatrixXd P;                // K_ΘΘ
  Eigen::MatrixXd null_basis, V;    // near null space of K_ΣΣ, and its working copy
  QpScratch qp;
};

}  // namespace zwang::internal
