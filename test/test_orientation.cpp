// The orientation helpers (orientation.hpp, issue #27 item 6) against Eigen's own rotations: the logarithm of
// AngleAxisd(θ, axis) must be θ·axis, the exponential of θ·axis must be AngleAxisd's matrix, for angles spread over
// [0, π] and crowded near 0 and near π, where the textbook formulas (acos of the trace, the axis from R − Rᵀ) lose
// digits; the quaternion orders against Eigen's coeffs(), which put w last.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/Geometry>

#include "support/random_chain.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using zwang::testing::randomRotation;
using zwang::testing::randomUnitVector;

namespace {

constexpr double kPi = 3.14159265358979323846;

// The angles tried: uniform in [0, π], and 10^-k from 0 and from π (k = 1 … 15), and 0 and π themselves.
std::vector<double> angles(std::mt19937_64& rng) {
  std::vector<double> out{0.0, kPi};
  for (int k = 1; k <= 15; ++k) {
    out.push_back(std::pow(10.0, -k));
    out.push_back(kPi - std::pow(10.0, -k));
  }
  for (int k = 0; k < 200; ++k) out.push_back(zwang::testing::uniform(rng, 0.0, kPi));
  return out;
}

// The distance between two rotation vectors as rotations: at a half turn φ and −φ are the same.
double rotationVectorDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double direct = (a - b).norm();
  if (std::abs(b.norm() - kPi) > 1e-6) return direct;
  return std::min(direct, (a + b).norm());
}

}  // namespace

TEST_CASE("orientation: log and exp against Eigen's AngleAxisd, near 0 and near pi", "[orientation]") {
  // AngleAxisd's matrix is exact to rounding (entries ~1e-16 off); the log through the quaternion turns that into
  // an angle error of a few 1e-16 at every angle (2 atan2 of accurate components), so 1e-14 absolute on φ. The
  // textbook acos((tr R − 1)/2) would be 1e-8 off near 0: the bound sees it.
  std::mt19937_64 rng(2761);
  double worst_log = 0.0, worst_quat_log = 0.0, worst_exp = 0.0, worst_quat_exp = 0.0, worst_round_trip = 0.0;
  int cases = 0;
  for (const double theta : angles(rng)) {
    for (int k = 0; k < 5; ++k, ++cases) {
      const Eigen::Vector3d axis = randomUnitVector(rng), phi = theta * axis;
      const Eigen::AngleAxisd aa(theta, axis);
      const Eigen::Matrix3d R = aa.toRotationMatrix();
      const Eigen::Quaterniond q(aa);
      worst_log = std::max(worst_log, rotationVectorDistance(rotationLog(R), phi));
      const Eigen::Vector4d wxyz(q.w(), q.x(), q.y(), q.z());
      worst_quat_log = std::max(worst_quat_log, rotationVectorDistance(quaternionLog(wxyz), phi));
      worst_quat_log = std::max(worst_quat_log, rotationVectorDistance(quaternionLog(-wxyz), phi));  // the same turn
      worst_exp = std::max(worst_exp, (rotationExp(phi) - R).cwiseAbs().maxCoeff());
      const Eigen::Vector4d e = quaternionExp(phi);
      worst_quat_exp = std::max(worst_quat_exp, std::min((e - wxyz).norm(), (e + wxyz).norm()));
      worst_round_trip = std::max(worst_round_trip, (rotationExp(rotationLog(R)) - R).cwiseAbs().maxCoeff());
    }
  }
  std::printf(
      "orientation: %d rotations (angles near 0 and pi included); max error: log(R) %.2e  log(q) %.2e  exp -> R "
      "%.2e  exp -> q %.2e  exp(log(R)) - R %.2e\n",
      cases, worst_log, worst_quat_log, worst_exp, worst_quat_exp, worst_round_trip);
  CHECK(worst_log < 1e-14);
  CHECK(worst_quat_log < 1e-14);
  CHECK(worst_exp < 1e-14);
  CHECK(worst_quat_exp < 1e-14);
  CHECK(worst_round_trip < 1e-14);
  CHECK(rotationLog(Eigen::Matrix3d::Identity()) == Eigen::Vector3d::Zero());
  CHECK(quaternionLog(Eigen::Vector4d::Zero()) == Eigen::Vector3d::Zero());
  CHECK(quaternionLog(Eigen::Vector4d(2, 0, 0, 0)) == Eigen::Vector3d::Zero());  // normalised first
}

TEST_CASE("orientation: the error turns the current orientation into the desired one", "[orientation]") {
  std::mt19937_64 rng(2762);
  double worst = 0.0, worst_local = 0.0;
  for (int k = 0; k < 500; ++k) {
    const Eigen::Matrix3d current = randomRotation(rng), desired = randomRotation(rng);
    const Eigen::Vector3d e = orientationError(current, desired);
    worst = std::max(worst, (rotationExp(e) * current - desired).cwiseAbs().maxCoeff());
    // In the frame's axes: current · exp([Rᵀe]×) = desired.
    worst_local =
        std::max(worst_local, (current * rotationExp(current.transpose() * e) - desired).cwiseAbs().maxCoeff());
    CHECK(e.norm() <= kPi + 1e-15);  // the shortest rotation
  }
  std::printf("orientation error: 500 pairs, max |exp(e) R_c - R_d| %.2e, in local axes %.2e\n", worst, worst_local);
  CHECK(worst < 1e-14);  // a few products of orthonormal matrices: rounding only
  CHECK(worst_local < 1e-14);
  CHECK(orientationError(Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity()) == Eigen::Vector3d::Zero());
}

TEST_CASE("orientation: quaternion orders against Eigen's coeffs() (x y z w)", "[orientation]") {
  const Eigen::Quaterniond q = Eigen::Quaterniond(1.0, 2.0, 3.0, 4.0).normalized();  // Eigen's constructor: w first
  const Eigen::Vector4d wxyz(q.w(), q.x(), q.y(), q.z());
  CHECK(quaternionXyzwFromWxyz(wxyz) == q.coeffs());  // Eigen stores w last
  CHECK(quaternionWxyzFromXyzw(q.coeffs()) == wxyz);
  CHECK(quaternionWxyzFromXyzw(quaternionXyzwFromWxyz(wxyz)) == wxyz);
  CHECK(quaternionWxyzFromXyzw(Eigen::Vector4d(0.1, 0.2, 0.3, 0.9)) == Eigen::Vector4d(0.9, 0.1, 0.2, 0.3));
}
