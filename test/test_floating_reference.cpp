// The dense floating-base reference (test/support/floating_reference.*) against
// MuJoCo (Debian's libmujoco-dev 2.2.2: mj_forward, mj_inverse, mj_fullM, body
// poses and velocities) on random floating trees, and against physics in
// closed form (momentum, free fall, a single rigid body's Newton–Euler).
//
// The conventions and the conversions between our coordinates and MuJoCo's
// (a free joint's qvel is [ṗ in world axes; ω in body axes]; ours is
// [Rᵀṗ; ω]) are written once in test/support/mujoco_bridge.hpp, which this
// test and test_mujoco_floating share; this test checks them rather than
// assuming them (poses, velocities, the base's classical acceleration straight
// from qacc, and the mistakes that must be seen).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <catch2/catch.hpp>

#include "support/dense_reference.hpp"
#include "support/floating_reference.hpp"
#include "support/mjcf_writer.hpp"
#include "support/mujoco_bridge.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"

using namespace zwang::testing;

namespace {

// max |x − y| / max(1, max |y|).
double relErr(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) {
  if (x.rows() != y.rows() || x.cols() != y.cols()) return std::numeric_limits<double>::infinity();
  if (x.size() == 0) return 0.0;
  return (x - y).cwiseAbs().maxCoeff() / std::max(1.0, y.cwiseAbs().maxCoeff());
}

struct Figures {
  double forward = 0.0, inverse = 0.0, mass = 0.0, base_acc = 0.0, poses = 0.0, velocities = 0.0;
  void max(const Figures& o) {
    forward = std::max(forward, o.forward);
    inverse = std::max(inverse, o.inverse);
    mass = std::max(mass, o.mass);
    base_acc = std::max(base_acc, o.base_acc);
    poses = std::max(poses, o.poses);
    velocities = std::max(velocities, o.velocities);
  }
};

// A deliberate mistake for the comparison to find (the default: none).
struct Mistake {
  const ChainSpec* spec = nullptr;     // another spec handed to MuJoCo
  const FloatingBase* base = nullptr;  // another base (same kind) handed to MuJoCo
  bool no_conversion = false;          // MuJoCo's free-joint vectors taken as ours (T = 1)
};

// One floating problem (no constraints) both ways against MuJoCo, plus H, poses, velocities and the base's
// classical acceleration.
Figures compareWithMujoco(const ChainSpec& spec, const FloatingBase& base, const FloatingInput& in,
                          const Eigen::VectorXd& qdd_inverse, const Mistake& mistake = {}) {
  REQUIRE(in.constraints.empty());  // MuJoCo's equality constraints are soft
  const int nv = base.nv(spec);
  const FloatingResult ref = floatingDynamics(spec, base, in);
  const FloatingKinematics kin = floatingKinematics(spec, base, in.q, in.v);

  const Mujoco mj(toMjcf(mistake.spec ? *mistake.spec : spec, in.gravity, mistake.base ? *mistake.base : base));
  const mjModel* m = mj.m();
  mjData* d = mj.d();
  const MujocoCoordinates map = mapCoordinates(spec, base, m);
  const Eigen::MatrixXd T =
      mistake.no_conversion ? Eigen::MatrixXd::Identity(nv, nv) : mujocoVelocityMap(spec, base, in.q);
  const Eigen::VectorXd Tdot_v =
      mistake.no_conversion ? Eigen::VectorXd::Zero(nv) : mujocoVelocityMapRate(spec, base, in.q, in.v);

  Figures f;
  // Forward: τ as generalized forces f_mj = T⁻ᵀ τ, wrenches as xfrc_applied at each body's COM.
  scatter(in.q, map.qpos, d->qpos);
  scatter(T * in.v, map.dof, d->qvel);
  scatter(T.transpose().lu().solve(in.tau), map.dof, d->qfrc_applied);
  addWrenchesToXfrc(spec, kin.poses, in.wrenches, m, d);
  mj_forward(m, d);
  const Eigen::VectorXd qacc_mj = gather(d->qacc, map.dof);
  const Eigen::VectorXd qdd_mj = T.lu().solve(qacc_mj - Tdot_v);  // v̇ = T⁻¹ (u̇ − Ṫ v)
  f.forward = relErr(ref.qdd, qdd_mj);
  // The base's classical acceleration straight from MuJoCo's qacc, without our conversion of v̇:
  // Free [p̈; R ω̇_body], Planar [ẍ u_x + ÿ u_y + (centripetal of nothing: the plane's axes are fixed); ψ̈ u_z].
  Vector6d base_acc = Vector6d::Zero();
  if (base.kind == BaseKind::Free) {
    base_acc << qacc_mj.head<3>(), basePose(base, in.q).linear() * qacc_mj.segment<3>(3);
  } else {
    const Eigen::Matrix3d RP = base.plane.linear();
    base_acc << qacc_mj(0) * RP.col(0) + qacc_mj(1) * RP.col(1), qacc_mj(2) * RP.col(2);
  }
  f.base_acc = relErr(ref.base_acc_world, base_acc);

  // Poses and velocities of every body origin (mjOBJ_XBODY: the body frame, [ω; ṗ] in world axes).
  for (std::size_t i = 0; i < spec.links.size(); ++i) {
    const int body = mj_name2id(m, mjOBJ_BODY, spec.links[i].name.c_str());
    REQUIRE(body >= 1);
    const Eigen::Vector3d xpos(d->xpos[3 * body], d->xpos[3 * body + 1], d->xpos[3 * body + 2]);
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> xmat(d->xmat + 9 * body);
    f.poses = std::max(f.poses, std::max((xpos - kin.poses[i].translation()).cwiseAbs().maxCoeff(),
                                         (Eigen::Matrix3d(xmat) - kin.poses[i].linear()).cwiseAbs().maxCoeff()));
    mjtNum vel[6];
    mj_objectVelocity(m, d, mjOBJ_XBODY, body, vel, 0);
    const Eigen::Vector3d w = kin.v[i].tail<3>();
    Vector6d ours, theirs;
    ours << kin.v[i].head<3>() + w.cross(kin.poses[i].translation()), w;  // [ṗ; ω]
    theirs << vel[3], vel[4], vel[5], vel[0], vel[1], vel[2];
    f.velocities = std::max(f.velocities, relErr(ours, theirs));
  }

  // Mass matrix: H = Tᵀ M_mj T.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> M_full(m->nv, m->nv);
  mj_fullM(m, M_full.data(), d->qM);
  Eigen::MatrixXd M(nv, nv);
  for (int r = 0; r < nv; ++r)
    for (int c = 0; c < nv; ++c)
      M(r, c) = M_full(map.dof[static_cast<std::size_t>(r)], map.dof[static_cast<std::size_t>(c)]);
  f.mass = relErr(floatingMassMatrix(spec, base, in.q), T.transpose() * M * T);

  // Inverse: u̇ = T v̇ + Ṫ v; qfrc_inverse (no applied forces in it) minus the wrenches' generalized forces.
  std::fill(d->qfrc_applied, d->qfrc_applied + m->nv, 0.0);
  std::fill(d->xfrc_applied, d->xfrc_applied + 6 * m->nbody, 0.0);
  scatter(T * qdd_inverse + Tdot_v, map.dof, d->qacc);
  mj_inverse(m, d);
  const std::vector<mjtNum> qfrc_wrench = wrenchGeneralizedForces(spec, kin.poses, in.wrenches, m, d);
  const Eigen::VectorXd qfrc = gather(d->qfrc_inverse, map.dof) - gather(qfrc_wrench.data(), map.dof);
  f.inverse = relErr(floatingInverseDynamics(spec, base, in.q, in.v, qdd_inverse, in.gravity, in.wrenches),
                     T.transpose() * qfrc);
  return f;
}

// A single free rigid body (no joints): links[0] only.
ChainSpec singleBody(std::mt19937_64& rng) {
  ChainSpec spec;
  spec.name = "single_body";
  LinkSpec link;
  link.name = "body";
  link.mass = uniform(rng, 0.2, 5.0);
  link.com = randomVector(rng, 3, 0.3);
  link.inertial_rpy = randomVector(rng, 3, 3.0);
  link.inertia = randomInertia(rng, link.mass);
  spec.links.push_back(link);
  spec.check();
  return spec;
}

// The central difference of g(t) = h(q(t), v + t v̇), q(t) the flow of q̇ = configurationRate(q, v) (v held: the
// same first derivative as the true path, and g stays smooth, so the error has even powers only), extrapolated
// (Richardson) to O(dt⁴): the rate of the total momentum along the motion, independent of J̇ v.
Vector6d momentumRateByDifferences(const ChainSpec& spec, const FloatingBase& base, const FloatingInput& in,
                                   const Eigen::VectorXd& qdd, double dt) {
  auto central = [&](double h) -> Vector6d {
    const Eigen::VectorXd qp = integrateConfiguration(base, in.q, in.v, h, 8);
    const Eigen::VectorXd qm = integrateConfiguration(base, in.q, in.v, -h, 8);
    return (floatingMomentum(spec, base, qp, in.v + h * qdd) - floatingMomentum(spec, base, qm, in.v - h * qdd)) /
           (2.0 * h);
  };
  return (4.0 * central(dt / 2) - central(dt)) / 3.0;
}

// The options of the MuJoCo comparisons: no constraints (MuJoCo's are soft), random wrenches (also on the base),
// a random base force in half the draws.
RandomFloatingOptions mujocoOptions() {
  RandomFloatingOptions options;
  options.max_constraint_rows = 0;
  options.max_wrenches = 2;
  options.base_tau_probability = 0.5;
  return options;
}

}  // namespace

TEST_CASE("toMjcf with a floating base: MuJoCo compiles a free joint or the planar joints at the plane pose",
          "[floating][mujoco]") {
  std::mt19937_64 rng(77);
  for (int trial = 0; trial < 20; ++trial) {
    const ChainSpec spec = randomTree(rng);
    // The fixed overload is the old writer, byte for byte.
    CHECK(toMjcf(spec, Eigen::Vector3d(0, 0, -9.81), FloatingBase{BaseKind::Fixed, Eigen::Isometry3d::Identity()}) ==
          toMjcf(spec, Eigen::Vector3d(0, 0, -9.81)));
    RandomFloatingOptions options;
    options.identity_plane_probability = 0.0;
    const FloatingBase base = randomFloatingBase(rng, options);
    const Mujoco mj(toMjcf(spec, Eigen::Vector3d(0, 0, -9.81), base));
    const mjModel* m = mj.m();
    CHECK(m->nq == base.nq(spec));
    CHECK(m->nv == base.nv(spec));
    const int root = mj_name2id(m, mjOBJ_BODY, spec.links[0].name.c_str());
    REQUIRE(root == 1);
    CHECK(m->body_parentid[root] == 0);
    const Eigen::Vector3d pos(m->body_pos[3], m->body_pos[4], m->body_pos[5]);
    const Eigen::Matrix3d R =
        Eigen::Quaterniond(m->body_quat[4], m->body_quat[5], m->body_quat[6], m->body_quat[7]).toRotationMatrix();
    if (base.kind == BaseKind::Free) {
      const int id = mj_name2id(m, mjOBJ_JOINT, kMjcfFreeJoint);
      REQUIRE(id >= 0);
      CHECK(m->jnt_type[id] == mjJNT_FREE);
      CHECK(m->jnt_bodyid[id] == root);
      CHECK(m->jnt_dofadr[id] == 0);
      CHECK(pos.isZero(0.0));
    } else {
      CHECK((pos - base.plane.translation()).cwiseAbs().maxCoeff() < 1e-15);
      CHECK((R - base.plane.linear()).cwiseAbs().maxCoeff() < 1e-14);
      const char* names[] = {kMjcfPlanarX, kMjcfPlanarY, kMjcfPlanarYaw};
      for (int k = 0; k < 3; ++k) {
        const int id = mj_name2id(m, mjOBJ_JOINT, names[k]);
        REQUIRE(id >= 0);
        CHECK(m->jnt_bodyid[id] == root);
        CHECK(m->jnt_dofadr[id] == k);  // in this order, before every other dof
        CHECK(m->dof_armature[k] == 0.0);
      }
    }
  }
  // A massless floating root is refused; so is a plane pose on a free base.
  ChainSpec spec = randomTree(rng);
  spec.links[0].mass = 0.0;
  spec.links[0].inertia.setZero();
  CHECK_THROWS_WITH(toMjcf(spec, Eigen::Vector3d::Zero(), FloatingBase{}), Catch::Contains("base"));
  FloatingBase wrong;
  wrong.plane.translation() << 1.0, 0.0, 0.0;
  CHECK_THROWS(toMjcf(randomTree(rng), Eigen::Vector3d::Zero(), wrong));
}

TEST_CASE("the floating reference matches MuJoCo on 240 random floating trees and chains and 20 single bodies",
          "[floating][mujoco]") {
  REQUIRE(mj_version() == mjVERSION_HEADER);
  std::mt19937_64 rng(20240501);
  const RandomFloatingOptions options = mujocoOptions();
  Figures worst[2];
  int count[2] = {0, 0}, joints = 0, max_joints = 0, min_joints = 1000, with_gravity = 0, with_wrenches = 0, chains = 0,
      tilted_planes = 0;
  for (int trial = 0; trial < 260; ++trial) {
    FloatingProblem p = randomFloatingProblem(rng, options);
    if (trial >= 240) {  // the last 20: a single rigid body (no joints), with a random wrench on it
      p.spec = singleBody(rng);
      p.input = randomFloatingInput(rng, p.spec, p.base, options);
      WrenchInput w;
      w.link = p.spec.links[0].name;
      w.wrench = randomVector(rng, 6, 5.0);
      w.axes = trial % 4 < 2 ? Axes::Local : Axes::World;
      p.input.wrenches.push_back(w);
    }
    // Half free, half planar, whatever the draw.
    const BaseKind kind = trial % 2 == 0 ? BaseKind::Free : BaseKind::Planar;
    if (p.base.kind != kind) {
      p.base.kind = kind;
      p.base.plane = Eigen::Isometry3d::Identity();
      if (kind == BaseKind::Planar && trial % 4 != 1) {
        p.base.plane.linear() = randomRotation(rng);
        p.base.plane.translation() = randomVector(rng, 3, 1.0);
      }
      p.input = randomFloatingInput(rng, p.spec, p.base, options);
      if (trial >= 240)
        p.input.wrenches =
            std::vector<WrenchInput>(1, WrenchInput{p.spec.links[0].name, Vector6d::Ones(), Axes::Local});
    }
    const Eigen::VectorXd qdd = randomVector(rng, p.base.nv(p.spec), 5.0);
    INFO("trial " << trial << " base " << toString(p.base.kind) << " joints " << p.spec.dof());
    const Figures f = compareWithMujoco(p.spec, p.base, p.input, qdd);
    const int b = p.base.kind == BaseKind::Free ? 0 : 1;
    worst[b].max(f);
    ++count[b];
    joints += p.spec.dof();
    max_joints = std::max(max_joints, p.spec.dof());
    min_joints = std::min(min_joints, p.spec.dof());
    with_gravity += p.input.gravity.isZero() ? 0 : 1;
    with_wrenches += p.input.wrenches.empty() ? 0 : 1;
    chains += p.spec.isChain() && p.spec.dof() > 0 ? 1 : 0;
    tilted_planes += p.base.kind == BaseKind::Planar && !p.base.plane.matrix().isIdentity(0.0) ? 1 : 0;
  }
  const char* names[] = {"free", "planar"};
  std::printf(
      "MuJoCo %s vs the floating reference: %d free + %d planar bases (%d tilted planes), %d serial chains, %d–%d joints "
      "(%d in all), %d under gravity, %d with wrenches\n",
      mj_versionString(), count[0], count[1], tilted_planes, chains, min_joints, max_joints, joints, with_gravity,
      with_wrenches);
  for (int b = 0; b < 2; ++b)
    std::printf(
        "  %-6s max rel. error: qdd (mj_forward) %.2e  tau (mj_inverse) %.2e  H (mj_fullM) %.2e  base classical acc "
        "%.2e  poses %.2e  body velocities %.2e\n",
        names[b], worst[b].forward, worst[b].inverse, worst[b].mass, worst[b].base_acc, worst[b].poses,
        worst[b].velocities);
  for (int b = 0; b < 2; ++b) {
    CHECK(count[b] >= 100);
    CHECK(worst[b].forward < 1e-9);
    CHECK(worst[b].inverse < 1e-9);
    CHECK(worst[b].mass < 1e-9);
    CHECK(worst[b].base_acc < 1e-9);
    CHECK(worst[b].poses < 1e-12);
    CHECK(worst[b].velocities < 1e-12);
  }
  CHECK(min_joints == 0);
  CHECK(max_joints >= 25);
}

TEST_CASE("the MuJoCo comparison of floating trees fails on a wrong model or a wrong convention",
          "[floating][mujoco]") {
  // Mistakes the comparison must see, each far above its 1e-9: a heavier root link handed to MuJoCo; a free base
  // whose vectors are exchanged with MuJoCo's without the conversion (ṗ in world axes, p̈ instead of v̇); a plane
  // handed to MuJoCo turned by 90° about its normal.
  std::mt19937_64 rng(99);
  const RandomFloatingOptions options = mujocoOptions();
  double least[3] = {1e300, 1e300, 1e300};
  int applied[3] = {0, 0, 0};
  for (int trial = 0; trial < 40; ++trial) {
    FloatingProblem p = randomFloatingProblem(rng, options);
    p.input.gravity = 9.81 * randomUnitVector(rng);
    const Eigen::VectorXd qdd = randomVector(rng, p.base.nv(p.spec), 5.0);
    auto disagreement = [](const Figures& f) { return std::max(f.forward, f.inverse); };
    ChainSpec heavy = p.spec;
    heavy.links[0].mass *= 1.5;
    Mistake mass;
    mass.spec = &heavy;
    least[0] = std::min(least[0], disagreement(compareWithMujoco(p.spec, p.base, p.input, qdd, mass)));
    ++applied[0];
    if (p.base.kind == BaseKind::Free) {
      Mistake raw;
      raw.no_conversion = true;
      least[1] = std::min(least[1], disagreement(compareWithMujoco(p.spec, p.base, p.input, qdd, raw)));
      ++applied[1];
    } else {
      FloatingBase turned = p.base;
      turned.plane.rotate(Eigen::AngleAxisd(1.5707963267948966, Eigen::Vector3d::UnitZ()));
      Mistake plane;
      plane.base = &turned;
      least[2] = std::min(least[2], disagreement(compareWithMujoco(p.spec, p.base, p.input, qdd, plane)));
      ++applied[2];
    }
  }
  const char* names[] = {"root link mass x1.5", "free joint vectors not converted", "plane turned 90 deg"};
  for (int k = 0; k < 3; ++k) {
    std::printf("floating MuJoCo comparison with a mistake (%s): %d draws, smallest disagreement %.2e\n", names[k],
                applied[k], least[k]);
    CHECK(applied[k] >= 10);
    CHECK(least[k] > 1e-6);
  }
}

TEST_CASE("floating reference physics: momentum, free fall, a single rigid body's Newton–Euler",
          "[floating][physics]") {
  std::mt19937_64 rng(31337);
  RandomFloatingOptions options;
  options.max_constraint_rows = 0;
  options.max_wrenches = 0;
  options.gravity_probability = 0.0;
  double momentum = 0.0, momentum_planar = 0.0, momentum_fd = 0.0, momentum_external = 0.0, fall = 0.0,
         fall_angular = 0.0;
  int free_count = 0, planar_count = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const FloatingProblem p = randomFloatingProblem(rng, options);
    const FloatingResult r = floatingDynamics(p.spec, p.base, p.input);
    const FloatingKinematics kin = floatingKinematics(p.spec, p.base, p.input.q, p.input.v);
    // ḣ = Σ_i I_i a_i + v_i ×* I_i v_i; scale: the largest single term.
    Vector6d hdot = Vector6d::Zero();
    double scale = 1.0;
    for (std::size_t i = 0; i < p.spec.links.size(); ++i) {
      const Vector6d term =
          kin.inertia[i] * (kin.J[i] * r.qdd + kin.bias[i]) + forceCross(kin.v[i]) * kin.inertia[i] * kin.v[i];
      hdot += term;
      scale = std::max(scale, term.cwiseAbs().maxCoeff());
    }
    const Vector6d fd = momentumRateByDifferences(p.spec, p.base, p.input, r.qdd, 1e-3);
    if (p.base.kind == BaseKind::Free) {
      // No external force: all six components of the momentum are conserved (joint torques are internal; the
      // rotor inertias act on the joints only).
      momentum = std::max(momentum, hdot.cwiseAbs().maxCoeff() / scale);
      momentum_fd = std::max(momentum_fd, fd.cwiseAbs().maxCoeff() / scale);
      ++free_count;
    } else {
      // Planar: the plane supports the base; only the components along the base's three columns are conserved
      // (linear momentum along u_x, u_y; the moment about the yaw axis through the base origin).
      const Eigen::MatrixXd S = kin.J[0].leftCols(3);
      momentum_planar = std::max(momentum_planar, (S.transpose() * hdot).cwiseAbs().maxCoeff() / scale);
      momentum_fd = std::max(momentum_fd, (S.transpose() * fd).cwiseAbs().maxCoeff() / scale);
      ++planar_count;
    }
  }

  // Free bases with gravity and wrenches: ḣ = Σ external wrenches + Σ gravity wrenches, and the COM of a robot in
  // free fall (gravity only) accelerates at g with no moment about it.
  RandomFloatingOptions falling = options;
  falling.free_probability = 1.0;
  falling.gravity_probability = 1.0;
  for (int trial = 0; trial < 100; ++trial) {
    falling.max_wrenches = trial % 2 == 0 ? 0 : 3;
    FloatingProblem p = randomFloatingProblem(rng, falling);
    const FloatingResult r = floatingDynamics(p.spec, p.base, p.input);
    const FloatingKinematics kin = floatingKinematics(p.spec, p.base, p.input.q, p.input.v);
    double M = 0.0;
    Eigen::Vector3d Mc_ddot = Eigen::Vector3d::Zero(), Mc = Eigen::Vector3d::Zero();
    Vector6d external = Vector6d::Zero();
    for (std::size_t i = 0; i < p.spec.links.size(); ++i) {
      const double m = p.spec.links[i].mass;
      const Eigen::Vector3d c = kin.poses[i] * p.spec.links[i].com;
      const Vector6d a = kin.J[i] * r.qdd + kin.bias[i];
      const Eigen::Vector3d w = kin.v[i].tail<3>();
      const Eigen::Vector3d c_dot = kin.v[i].head<3>() + w.cross(c);
      Mc_ddot += m * (a.head<3>() + a.tail<3>().cross(c) + w.cross(c_dot));
      Mc += m * c;
      M += m;
      external.head<3>() += m * p.input.gravity;
      external.tail<3>() += c.cross(m * p.input.gravity);
    }
    for (const WrenchInput& w : p.input.wrenches) {
      const Eigen::Isometry3d& pose = kin.poses[static_cast<std::size_t>(p.spec.linkIndex(w.link))];
      const Vector6d fw = worldWrench(w, pose);
      external.head<3>() += fw.head<3>();
      external.tail<3>() += fw.tail<3>() + pose.translation().cross(fw.head<3>());
    }
    const Vector6d fd = momentumRateByDifferences(p.spec, p.base, p.input, r.qdd, 1e-3);
    const double scale = std::max(1.0, external.cwiseAbs().maxCoeff());
    momentum_external = std::max(momentum_external, (fd - external).cwiseAbs().maxCoeff() / scale);
    if (p.input.wrenches.empty()) {
      fall = std::max(fall, (Mc_ddot / M - p.input.gravity).norm() / p.input.gravity.norm());
      // The angular momentum about the (moving) COM: d/dt L_c = ḣ_ang − c × ḣ_lin − ċ × (M ċ) ... = 0, with ḣ
      // from differences: L_O rate − c × (linear rate) = Σ c_i × m_i g − c × M g = 0.
      const Eigen::Vector3d c = Mc / M;
      fall_angular = std::max(fall_angular, (fd.tail<3>() - c.cross(fd.head<3>())).norm() / (M * 9.81));
    }
  }

  // A single free rigid body: Newton–Euler in closed form, with gravity, a body wrench on the base coordinates
  // (τ_base: a force and moment at the origin in body axes) and an external world wrench at the origin.
  double newton_euler = 0.0, newton_euler_base = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const ChainSpec spec = singleBody(rng);
    FloatingBase base;
    FloatingInput in;
    const Eigen::Matrix3d R = randomRotation(rng);
    const Eigen::Quaterniond quat(R);
    const Eigen::Vector3d p = randomVector(rng, 3, 2.0);
    in.q.resize(7);
    in.q << p, quat.w(), quat.x(), quat.y(), quat.z();
    in.v = randomVector(rng, 6, 3.0);
    in.tau = randomVector(rng, 6, 10.0);
    in.gravity = 9.81 * randomUnitVector(rng);
    WrenchInput w;
    w.link = "body";
    w.axes = Axes::World;
    w.wrench = randomVector(rng, 6, 5.0);
    in.wrenches.push_back(w);
    const FloatingResult r = floatingDynamics(spec, base, in);

    const LinkSpec& link = spec.links[0];
    const double m = link.mass;
    const Eigen::Matrix3d Ri = rpyToMatrix(link.inertial_rpy);
    const Eigen::Matrix3d I_world = R * Ri * link.inertia * Ri.transpose() * R.transpose();
    const Eigen::Vector3d r_c = R * link.com;  // origin → COM, world axes
    const Eigen::Vector3d omega = R * in.v.segment<3>(3);
    const Eigen::Vector3d f_body = R * in.tau.head<3>(), n_body = R * in.tau.tail<3>();
    const Eigen::Vector3d F = m * in.gravity + f_body + w.wrench.head<3>();
    const Eigen::Vector3d N_c = n_body + w.wrench.tail<3>() + (-r_c).cross(f_body + w.wrench.head<3>());
    const Eigen::Vector3d alpha = I_world.inverse() * (N_c - omega.cross(I_world * omega));
    const Eigen::Vector3d c_ddot = F / m;
    const Eigen::Vector3d p_ddot = c_ddot - alpha.cross(r_c) - omega.cross(omega.cross(r_c));
    Vector6d expected;
    const Eigen::Vector3d v_lin = in.v.head<3>();
    expected << R.transpose() * p_ddot - in.v.segment<3>(3).cross(v_lin), R.transpose() * alpha;
    newton_euler = std::max(newton_euler, relErr(r.qdd, expected));
    Vector6d classical;
    classical << p_ddot, alpha;
    newton_euler_base = std::max(newton_euler_base, relErr(r.base_acc_world, classical));
  }

  std::printf(
      "floating physics: momentum rate without external forces (%d free) %.2e, planar components (%d planar) %.2e, "
      "by finite differences %.2e; with gravity and wrenches vs the external wrench %.2e; free fall COM "
      "acceleration vs g %.2e, moment about the COM %.2e; single body vs Newton–Euler: v̇ %.2e, [p̈; ω̇] %.2e\n",
      free_count, momentum, planar_count, momentum_planar, momentum_fd, momentum_external, fall, fall_angular,
      newton_euler, newton_euler_base);
  CHECK(free_count >= 60);
  CHECK(planar_count >= 60);
  CHECK(momentum < 1e-9);
  CHECK(momentum_planar < 1e-9);
  CHECK(momentum_fd < 1e-7);
  CHECK(momentum_external < 1e-7);
  CHECK(fall < 1e-9);
  CHECK(fall_angular < 1e-7);
  CHECK(newton_euler < 1e-9);
  CHECK(newton_euler_base < 1e-9);
}

TEST_CASE("floating reference: Jacobians, J̇v, constraints, Gauss minimum, inverse dynamics, fixed base", "[floating]") {
  std::mt19937_64 rng(4242);
  RandomFloatingOptions options;
  options.max_constraint_rows = 6;
  options.max_wrenches = 2;
  options.relative_probability = 0.3;
  options.base_tau_probability = 0.3;
  double jac = 0.0, jdot = 0.0, rows = 0.0, gauss_gap = 0.0, kkt = 0.0, id = 0.0, fixed = 0.0;
  int constrained = 0, fixed_count = 0, absolute_rows = 0, relative_rows = 0, mimic_draws = 0;
  double mimic = 0.0;
  for (int trial = 0; trial < 150; ++trial) {
    FloatingProblem p = randomFloatingProblem(rng, options);
    if (trial % 3 == 0 && p.spec.dof() >= 2) {  // mimic joints on a floating robot: one row each after the user's
      addRandomMimics(rng, p.spec);
      p.input = randomFloatingInput(rng, p.spec, p.base, options);
      ++mimic_draws;
    }
    const FloatingKinematics kin = floatingKinematics(p.spec, p.base, p.input.q, p.input.v);
    // Link velocities J_i v against the poses' rates, and J̇_i v against the rate of J_i v (v held), by central
    // differences along the flow of q̇ = configurationRate(q, v), Richardson-extrapolated.
    const double dt = 1e-3;
    auto at = [&](double h) {
      return floatingKinematics(p.spec, p.base, integrateConfiguration(p.base, p.input.q, p.input.v, h, 8), p.input.v);
    };
    const FloatingKinematics kp = at(dt), km = at(-dt), kp2 = at(dt / 2), km2 = at(-dt / 2);
    for (std::size_t i = 0; i < p.spec.links.size(); ++i) {
      auto rate = [&](const FloatingKinematics& a, const FloatingKinematics& b, double h) {
        // [ṗ; ω] from the poses: ω from the rotation's skew part.
        Vector6d x;
        const Eigen::Matrix3d dR = (a.poses[i].linear() - b.poses[i].linear()) / (2.0 * h);
        const Eigen::Matrix3d W = dR * kin.poses[i].linear().transpose();
        x << (a.poses[i].translation() - b.poses[i].translation()) / (2.0 * h),
            0.5 * Eigen::Vector3d(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1));
        return x;
      };
      const Vector6d fd = (4.0 * rate(kp2, km2, dt / 2) - rate(kp, km, dt)) / 3.0;
      const Eigen::Vector3d w = kin.v[i].tail<3>();
      Vector6d classical;
      classical << kin.v[i].head<3>() + w.cross(kin.poses[i].translation()), w;
      jac = std::max(jac, relErr(fd, classical));
      const Vector6d Jv_rate = (4.0 * (kp2.J[i] - km2.J[i]) / dt - (kp.J[i] - km.J[i]) / (2.0 * dt)) / 3.0 * p.input.v;
      jdot = std::max(jdot, relErr(Jv_rate, kin.bias[i]));
    }

    const FloatingResult r = floatingDynamics(p.spec, p.base, p.input);
    // Inverse dynamics reproduces τ plus the constraint forces.
    id = std::max(id, relErr(floatingInverseDynamics(p.spec, p.base, p.input.q, p.input.v, r.qdd, p.input.gravity,
                                                     p.input.wrenches),
                             p.input.tau + r.tau_c));
    // Every mimic joint follows its resolved leader: v̇_m = a·v̇_l (the base entries come first).
    for (const MimicLaw& law : p.spec.mimicLaws()) {
      const int base_velocity_size = p.base.baseVelocitySize();
      mimic = std::max(mimic, std::abs(r.qdd(base_velocity_size + law.joint) -
                                       law.multiplier * r.qdd(base_velocity_size + law.leader)) /
                                  std::max(1.0, std::abs(r.qdd(base_velocity_size + law.joint))));
    }
    // Keep well-posed draws only (as wellPosed in random_problem.hpp): every row reachable. A row the base and joints
    // cannot affect (an out-of-plane force on a planar base, say) has G ≈ 0.
    if (r.user_rows == 0 || !r.wellConditioned(1e6) || r.constraint_rank < r.user_rows ||
        Eigen::JacobiSVD<Eigen::MatrixXd>(r.G).singularValues().minCoeff() < 1e-6)
      continue;
    ++constrained;
    kkt = std::max(kkt, relErr(r.H * r.qdd + r.C, p.input.tau + r.G.transpose() * r.nu));
    // Each row holds in terms of classical accelerations (acc_world) and velocities: Aᵀ Ẍ = b, for a relative row
    // with Ẍ = [p̈_rel; ω̇_rel] of dense_reference.hpp (ConstraintInput) in the row's axes.
    for (const ConstraintInput& c : p.input.constraints) {
      const auto a = static_cast<std::size_t>(p.spec.linkIndex(c.link));
      Eigen::Vector3d acc_lin = r.acc_world[a].head<3>(), acc_ang = r.acc_world[a].tail<3>();
      Eigen::Matrix3d R = c.axes == Axes::Local ? kin.poses[a].linear() : Eigen::Matrix3d(Eigen::Matrix3d::Identity());
      if (!c.relative_to.empty()) {
        const auto b = static_cast<std::size_t>(p.spec.linkIndex(c.relative_to));
        auto pointVelocity = [&](std::size_t i) -> Eigen::Vector3d {
          return kin.v[i].head<3>() + kin.v[i].tail<3>().cross(kin.poses[i].translation());
        };
        const Eigen::Vector3d d = kin.poses[a].translation() - kin.poses[b].translation();
        const Eigen::Vector3d d_dot = pointVelocity(a) - pointVelocity(b);
        const Eigen::Vector3d w_a = kin.v[a].tail<3>(), w_r = kin.v[b].tail<3>();
        const Eigen::Vector3d alpha_r = r.acc_world[b].tail<3>();
        acc_lin =
            acc_lin - r.acc_world[b].head<3>() - alpha_r.cross(d) - 2.0 * w_r.cross(d_dot) + w_r.cross(w_r.cross(d));
        acc_ang = acc_ang - alpha_r - w_r.cross(w_a - w_r);
        if (c.axes == Axes::Reference) R = kin.poses[b].linear();
      }
      Vector6d acc;
      acc << R.transpose() * acc_lin, R.transpose() * acc_ang;
      rows = std::max(rows, relErr(c.A.transpose() * acc, c.b));
      (c.relative_to.empty() ? absolute_rows : relative_rows) += static_cast<int>(c.A.cols());
    }
    // Gauss: any other acceleration that meets the rows costs more (Z grows by ½ δᵀHδ).
    const Eigen::MatrixXd N = Eigen::FullPivLU<Eigen::MatrixXd>(r.G).kernel();
    FloatingInput input = p.input;
    for (int k = 0; k < 3 && N.cols() > 0 && !(N.cols() == 1 && N.isZero(0.0)); ++k) {
      const Eigen::VectorXd delta = N * randomVector(rng, static_cast<int>(N.cols()), 0.1);
      const double expected = 0.5 * delta.dot(r.H * delta);
      const double Z = floatingGaussFunction(p.spec, p.base, input, r.qdd + delta);
      gauss_gap = std::max(gauss_gap, std::abs((Z - r.gauss) / expected - 1.0));
    }
  }

  // The Fixed kind is the fixed-base dense reference (mimic joints and relative rows included).
  RandomProblemOptions dense_options;
  dense_options.relative_probability = 0.3;
  for (int trial = 0; trial < 60; ++trial) {
    ChainSpec spec = randomTree(rng);
    if (trial % 2 == 0) addRandomMimics(rng, spec);
    const DynamicsInput in = randomProblem(rng, spec, dense_options);
    FloatingInput fin;
    fin.q = in.q;
    fin.v = in.qd;
    fin.tau = in.tau;
    fin.gravity = in.gravity;
    fin.wrenches = in.wrenches;
    fin.constraints = in.constraints;
    const DenseResult d = denseDynamics(spec, in);
    if (!d.wellConditioned(1e6) || d.constraint_rank < static_cast<int>(d.G.rows())) continue;
    const FloatingResult f = floatingDynamics(spec, FloatingBase{BaseKind::Fixed, Eigen::Isometry3d::Identity()}, fin);
    fixed = std::max({fixed, relErr(f.qdd, d.qdd), relErr(f.nu, d.nu), relErr(f.H, d.H), relErr(f.C, d.C),
                      relErr(f.tau_control, d.tau_control),
                      std::abs(f.gauss - d.gauss) / std::max(1.0, std::abs(d.gauss))});
    ++fixed_count;
  }
  std::printf(
      "floating reference self-checks: link velocities vs pose differences %.2e, J̇v vs differences of Jv %.2e; "
      "%d constrained draws: KKT residual %.2e, %d absolute and %d relative rows vs classical accelerations %.2e, |Z(v̇ + δ) − Z(v̇)| / (½δᵀHδ) − 1 for δ in ker G %.2e; "
      "inverse dynamics = τ + Gᵀν %.2e; mimic laws on %d floating draws %.2e; Fixed kind vs denseDynamics (%d draws) %.2e\n",
      jac, jdot, constrained, kkt, absolute_rows, relative_rows, rows, gauss_gap, id, mimic_draws, mimic, fixed_count,
      fixed);
  CHECK(jac < 1e-8);
  CHECK(jdot < 1e-8);
  CHECK(constrained >= 40);
  CHECK(kkt < 1e-9);
  CHECK(relative_rows >= 30);
  CHECK(rows < 1e-9);
  CHECK(gauss_gap < 1e-6);
  CHECK(id < 1e-9);
  CHECK(mimic_draws >= 30);
  CHECK(mimic < 1e-9);
  CHECK(fixed_count >= 30);
  CHECK(fixed < 1e-12);
}
