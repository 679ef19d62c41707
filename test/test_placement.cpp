// Placing a floating-base robot on a plane (placement.hpp, issue #27 item 6).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "support/bad_inputs.hpp"
#include "support/floating_reference.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"
//
// Each placement is checked by forward kinematics at the placed q (framePose): the frames' heights, the joints kept,
// the base's orientation kept (Lowest) or turned by the least rotation; on Solo 12's feet (coplanar in any
// posture symmetric about its sagittal plane) and on random trees' frames (any three origins are coplanar).

using namespace zwang;
using namespace zwang::testing;

namespace {

// Placement is a rigid motion of a robot of size ~1 m: positions to rounding of a few products, 1e-12 m.
constexpr double kTolerance = 1e-12;

std::vector<double> heights(const Model& model, Workspace& ws, const Eigen::VectorXd& q,
                            const std::vector<int>& frames) {
  REQUIRE(forwardKinematics(model, ws, q));
  std::vector<double> z;
  for (const int f : frames) {
    Eigen::Isometry3d pose;
    REQUIRE(framePose(model, ws, q, f, pose));
    z.push_back(pose.translation().z());
  }
  return z;
}

Model solo() {
  UrdfOptions options;
  options.base = BaseType::Free;
  return loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/solo12.urdf", options);
}

Eigen::Vector4d randomQuaternion(std::mt19937_64& rng) {
  const Eigen::Quaterniond q(randomRotation(rng));
  return {q.w(), q.x(), q.y(), q.z()};
}

}  // namespace

TEST_CASE("placement: Solo 12's lowest foot on the plane, or all four feet", "[placement]") {
  const Model model = solo();
  Workspace ws(model);
  std::vector<int> feet;
  for (const char* foot : {"FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"}) feet.push_back(model.frameIndex(foot));
  std::mt19937_64 rng(2763);
  double worst_lowest = 0.0, worst_all = 0.0, worst_joints = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    // A posture symmetric about the sagittal plane (hip abduction 0, left and right legs alike): the feet are
    // coplanar.
    Eigen::VectorXd q(model.nq());
    q.head<3>() = randomVector(rng, 3, 1.0);
    q.segment<4>(3) = randomQuaternion(rng);
    Eigen::Vector3d front = randomVector(rng, 3, 1.0), hind = randomVector(rng, 3, 1.0);
    front[0] = hind[0] = 0.0;
    q.tail(12) << front, front, hind, hind;
    const double h = uniform(rng, -0.5, 0.5);
    Eigen::VectorXd placed(model.nq());
    double distance = -1.0;
    REQUIRE(placeOnPlane(model, ws, q, feet, h, PlaneContact::Lowest, placed, distance));
    std::vector<double> z = heights(model, ws, placed, feet);
    worst_lowest = std::max(worst_lowest, std::abs(*std::min_element(z.begin(), z.end()) - h));
    CHECK(distance == Approx(*std::max_element(z.begin(), z.end()) - h).margin(kTolerance));
    // Only the height moves: x, y and the joints exactly kept, the orientation to the rounding of renormalising.
    CHECK(placed[0] == q[0]);
    CHECK(placed[1] == q[1]);
    CHECK((placed.segment<4>(3) - q.segment<4>(3)).cwiseAbs().maxCoeff() < 1e-15);
    CHECK(placed.tail(12) == q.tail(12));

    REQUIRE(placeOnPlane(model, ws, q, feet, h, PlaneContact::All, placed, distance));
    z = heights(model, ws, placed, feet);
    for (const double zk : z) worst_all = std::max(worst_all, std::abs(zk - h));
    CHECK(distance < kTolerance);
    worst_joints = std::max(worst_joints, (placed.tail(12) - q.tail(12)).cwiseAbs().maxCoeff());
    CHECK(std::abs(placed.segment<4>(3).norm() - 1.0) < 1e-15);  // a unit quaternion, to rounding
  }
  std::printf(
      "placement: Solo 12, 50 postures: max |lowest foot - h| %.2e (Lowest), max |foot - h| %.2e (All, four feet)\n",
      worst_lowest, worst_all);
  CHECK(worst_lowest < kTolerance);
  CHECK(worst_all < kTolerance);
  CHECK(worst_joints == 0.0);
}

TEST_CASE("placement: one, two and three frames of random trees all on the plane; four not coplanar", "[placement]") {
  std::mt19937_64 rng(2764);
  double worst = 0.0;
  int spread_cases = 0;
  for (int trial = 0; trial < 60; ++trial) {
    RandomTreeOptions options;
    options.min_moving_joints = 4;
    options.max_moving_joints = 12;
    const ChainSpec spec = randomTree(rng, options);
    const FloatingBase base{BaseKind::Free, Eigen::Isometry3d::Identity()};
    const Model model = floatingModelFromSpec(spec, base);
    Workspace ws(model);
    Eigen::VectorXd q(model.nq());
    std::uint64_t state = 1000 + static_cast<std::uint64_t>(trial);
    REQUIRE(randomConfiguration(model, state, q));
    const int count = static_cast<int>(model.frames().size());
    const int n = 1 + trial % 4;
    std::vector<int> frames;
    while (static_cast<int>(frames.size()) < n) {
      const int f = uniformInt(rng, 0, count - 1);
      if (std::find(frames.begin(), frames.end(), f) == frames.end()) frames.push_back(f);
    }
    Eigen::VectorXd placed = q;
    double distance = -1.0;
    REQUIRE(placeOnPlane(model, ws, placed, frames, 0.25, PlaneContact::All, placed, distance));  // in place
    const std::vector<double> z = heights(model, ws, placed, frames);
    const double low = *std::min_element(z.begin(), z.end()), high = *std::max_element(z.begin(), z.end());
    CHECK(std::abs(low - 0.25) < kTolerance);
    CHECK(distance == Approx(high - 0.25).margin(kTolerance));
    if (n <= 3) {
      worst = std::max(worst, high - low);
    } else if (distance > 1e-6) {
      ++spread_cases;  // four origins in general position: the plane is a fit, they straddle it
    }
  }
  std::printf(
      "placement: random trees, 1-3 frames: max height spread after All %.2e; %d of 15 four-frame sets spread\n", worst,
      spread_cases);
  CHECK(worst < kTolerance);
  CHECK(spread_cases >= 5);
}

TEST_CASE("placement: errors", "[placement]") {
  const Model arm = pandaModel();
  Workspace ws(arm);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(7), out(7);
  double distance = 0.0;
  Status s = placeOnPlane(arm, ws, q, {0}, 0.0, PlaneContact::Lowest, out, distance);
  CHECK(s.code == StatusCode::ModelMismatch);
  CHECK(std::string(s.message).find("needs a free base") != std::string::npos);
  const Model model = solo();
  Workspace ws_solo(model);
  Eigen::VectorXd qs = Eigen::VectorXd::Zero(model.nq()), outs(model.nq());
  qs[3] = 1.0;
  CHECK(placeOnPlane(model, ws_solo, qs, {}, 0.0, PlaneContact::Lowest, outs, distance).code ==
        StatusCode::ModelMismatch);
  CHECK(placeOnPlane(model, ws_solo, qs, {9999}, 0.0, PlaneContact::Lowest, outs, distance).code ==
        StatusCode::ModelMismatch);
  CHECK(placeOnPlane(model, ws_solo, qs, {0}, NAN, PlaneContact::Lowest, outs, distance).code == StatusCode::NonFinite);
  CHECK(placeOnPlane(model, ws_solo, qs, {0}, 0.0, PlaneContact::Lowest, out, distance).code ==
        StatusCode::SizeMismatch);
}
