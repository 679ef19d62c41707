// The spatial-algebra core against explicit 6×6 matrix formulas
// (Featherstone, "Rigid Body Dynamics Algorithms", ch. 2, rewritten for the
// linear-first ordering of docs/conventions.md).
#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <random>

#include "zwang/spatial/cross.hpp"
#include "zwang/spatial/inertia.hpp"

using namespace zwang;
using namespace zwang::spatial;

namespace {

std::mt19937_64 rng(7);

Vec6 randomVec6() {
  std::normal_distribution<double> n;
  Vec6 x;
  for (int k = 0; k < 6; ++k) x[k] = n(rng);
  return x;
}

Mat3 randomRotation() {
  std::normal_distribution<double> n;
  Eigen::Quaterniond qt(n(rng), n(rng), n(rng), n(rng));
  return qt.normalized().toRotationMatrix();
}

Transform randomTransform() {
  std::normal_distribution<double> n;
  return Transform::fromPose(randomRotation(), Vec3(n(rng), n(rng), n(rng)));
}

RigidInertia randomInertia() {
  std::uniform_real_distribution<double> u(0.1, 2.0);
  const Mat3 R = randomRotation();
  const double a = u(rng), b = u(rng);
  const Vec3 moments(a, b, 0.5 * (a + b));  // satisfies the triangle inequality
  return RigidInertia::fromMassComInertia(u(rng), Vec3(u(rng), -u(rng), u(rng)),
                                          R * moments.asDiagonal() * R.transpose());
}

// Explicit 6×6 motion transform from (rotation, translation), linear first:
// [v_B; ω_B] = [E  −E r×; 0  E] [v_A; ω_A].
Mat6 motionMatrix(const Mat3& E, const Vec3& r) {
  Mat6 X = Mat6::Zero();
  X.topLeftCorner<3, 3>() = E;
  X.topRightCorner<3, 3>() = -E * skew(r);
  X.bottomRightCorner<3, 3>() = E;
  return X;
}

constexpr double tol = 1e-12;

}  // namespace

TEST_CASE("cross operators match their 6x6 matrices and the duality v×* = −(v×)ᵀ") {
  for (int trial = 0; trial < 50; ++trial) {
    const Vec6 v = randomVec6(), m = randomVec6(), f = randomVec6();
    Mat6 vx = Mat6::Zero();  // [ω× v×; 0 ω×]
    vx.topLeftCorner<3, 3>() = skew(v.tail<3>());
    vx.topRightCorner<3, 3>() = skew(v.head<3>());
    vx.bottomRightCorner<3, 3>() = skew(v.tail<3>());
    CHECK((crossMotion(v, m) - vx * m).norm() < tol);
    CHECK((crossForce(v, f) - (-vx.transpose()) * f).norm() < tol);
    // Power is conserved: (v × m)·f + m·(v ×* f) = 0
    CHECK(std::abs(crossMotion(v, m).dot(f) + m.dot(crossForce(v, f))) < 1e-11);
  }
}

TEST_CASE("Plücker transforms act on motion and force as the explicit matrices do") {
  for (int trial = 0; trial < 50; ++trial) {
    const Transform X = randomTransform();
    const Mat6 M = motionMatrix(X.E, X.r);
    const Mat6 Mf = M.inverse().transpose();  // force transform X* = X⁻ᵀ
    const Vec6 m = randomVec6(), f = randomVec6();
    CHECK((X.applyMotion(m) - M * m).norm() < tol);
    CHECK((X.applyForce(f) - Mf * f).norm() < 1e-11);
    CHECK((X.inverseApplyMotion(m) - M.inverse() * m).norm() < 1e-11);
    CHECK((X.inverseApplyForce(f) - M.transpose() * f).norm() < tol);
    CHECK((X.motionMatrix() - M).norm() < tol);
    // Power is invariant: (X m)·(X* f) = m·f
    CHECK(std::abs(X.applyMotion(m).dot(X.applyForce(f)) - m.dot(f)) < 1e-11);
  }
}

TEST_CASE("composition and inverse of transforms are the matrix product and inverse") {
  for (int trial = 0; trial < 50; ++trial) {
    const Transform A = randomTransform(), B = randomTransform();
    CHECK(((A * B).motionMatrix() - A.motionMatrix() * B.motionMatrix()).norm() < 1e-11);
    CHECK((A.inverse().motionMatrix() - A.motionMatrix().inverse()).norm() < 1e-11);
  }
}

TEST_CASE("a translation moves the reference point: the velocity of the new origin") {
  // Body spinning about z at 1 rad/s through the old origin; the point at x = 2
  // moves with v = ω × p = (0, 2, 0).
  const Transform X = Transform::translation(Vec3(2, 0, 0));
  const Vec6 twist = stack(Vec3::Zero(), Vec3::UnitZ());
  CHECK((X.applyMotion(twist).head<3>() - Vec3(0, 2, 0)).norm() < tol);
  // A force along y at the old origin has moment −(r × f) = (0,0,−2) about the new one.
  const Vec6 force = stack(Vec3::UnitY(), Vec3::Zero());
  CHECK((X.applyForce(force).tail<3>() - Vec3(0, 0, -2)).norm() < tol);
}

TEST_CASE("rigid-body inertia matches [m1 −m c×; m c× I_c − m c×c×] and transforms as X⁻ᵀ I X⁻¹") {
  for (int trial = 0; trial < 50; ++trial) {
    std::uniform_real_distribution<double> u(0.1, 2.0);
    const double mass = u(rng);
    const Vec3 c(u(rng), -u(rng), u(rng));
    const Mat3 R = randomRotation();
    const Mat3 Ic = R * Vec3(1.0, 1.5, 2.0).asDiagonal() * R.transpose();
    const RigidInertia I = RigidInertia::fromMassComInertia(mass, c, Ic);
    Mat6 expected;
    expected << mass * Mat3::Identity(), -mass * skew(c), mass * skew(c), Ic - mass * skew(c) * skew(c);
    CHECK((I.matrix() - expected).norm() < tol);
    CHECK((I.com() - c).norm() < tol);
    CHECK((I.inertiaAboutCom() - Ic).norm() < 1e-11);
    const Vec6 m = randomVec6();
    CHECK((I * m - expected * m).norm() < 1e-11);

    const Transform X = randomTransform();
    const Mat6 Xm = X.motionMatrix();
    const Mat6 IB = Xm.inverse().transpose() * expected * Xm.inverse();
    CHECK((transformInertia(X, I).matrix() - IB).norm() < 1e-10);
    CHECK((inverseTransformInertia(X, transformInertia(X, I)).matrix() - expected).norm() < 1e-10);
    // Articulated (general symmetric) inertia: Xᵀ I X.
    const Mat6 sym = expected + 0.1 * Mat6::Identity();
    CHECK((X.inverseApplyInertia(sym) - Xm.transpose() * sym * Xm).norm() < 1e-10);
  }
}

TEST_CASE("inertias add and the sum keeps total mass and the combined centre of mass") {
  const RigidInertia a = randomInertia(), b = randomInertia();
  const RigidInertia s = a + b;
  CHECK(s.mass == Approx(a.mass + b.mass));
  CHECK((s.com() - (a.mass * a.com() + b.mass * b.com()) / (a.mass + b.mass)).norm() < tol);
  CHECK((s.matrix() - a.matrix() - b.matrix()).norm() < tol);
}
