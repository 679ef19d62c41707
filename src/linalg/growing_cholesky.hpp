// Cholesky factors of principal submatrices of a symmetric positive
// semi-definite matrix, for the friction maximiser (no allocation: storage is
// sized once).
#pragma once

#include <Eigen/Core>

namespace zwang::internal {

// L Lᵀ = P_FF for a free set F of indices into P, grown and shrunk one index
// at a time in O(|F|²) instead of refactored in O(|F|³): the primal
// active-set method changes F by one index per iteration.
class GrowingCholesky {
 public:
  explicit GrowingCholesky(int capacity = 0);

  void clear() { size_ = 0; }
  int size() const { return size_; }
  int index(int position) const { return index_[position]; }
  // Position of P's index j in F, or −1.
  int positionOf(int j) const;

  // The Schur pivot s = P_jj − ‖L⁻¹ P_Fj‖² of adding j: the curvature of P
  // along the direction that moves j by 1 and F so that P_FF's gradient stays
  // unchanged. It keeps L⁻¹ P_Fj for append() and nullDirection().
  double schurPivot(const Eigen::Ref<const Eigen::MatrixXd>& P, int j);
  // Appends j, whose schurPivot (the last one computed) was `pivot` > 0.
  void append(int j, double pivot);
  // d_F = −P_FF⁻¹ P_Fj for the j of the last schurPivot: with d_j = 1 it is a
  // direction of curvature `pivot` (zero when j depends on F).
  void nullDirection(Eigen::Ref<Eigen::VectorXd> d_F) const;
  // Removes the index at `position` (Givens rotations restore the triangle).
  void remove(int position);
  // x ← P_FF⁻¹ x (x has size() entries, in F's order).
  void solveInPlace(Eigen::Ref<Eigen::VectorXd> x) const;

 private:
  Eigen::MatrixXd U_;      // capacity², Lᵀ: upper triangle of the top-left size_² block
  Eigen::VectorXi index_;  // F in factor order
  Eigen::VectorXd w_;      // L⁻¹ P_Fj of the last schurPivot
  int size_ = 0;
};

// Near null space of a symmetric positive semi-definite A (n × n) by
// diagonally pivoted (rank-revealing) Cholesky, stopped when every remaining
// Schur-complement diagonal is at most `floor`. Writes an orthonormal basis of
// the remaining directions into the first columns of N (n × n capacity) and
// returns their number n − r: the orthogonal complement of the r factored
// columns (Householder QR of them, or a triangular solve with them then
// Gram–Schmidt twice, whichever costs less for r and n − r). Each has
// curvature dᵀ A d ≤ (n − r)·floor:
// for d ⟂ range(L), dᵀAd = d₂ᵀ S d₂ with the Schur complement S positive
// semi-definite and trace S ≤ (n − r)·floor. Only A's lower triangle is read;
// A is overwritten; `pivot_row` (n) is scratch. O(n³/6).
Eigen::Index nearNullSpace(Eigen::Ref<Eigen::MatrixXd> A, double floor, Eigen::Ref<Eigen::MatrixXd> N,
                           Eigen::Ref<Eigen::VectorXi> pivot_row);

}  // namespace zwang::internal
