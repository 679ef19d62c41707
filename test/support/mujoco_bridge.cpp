#include "support/mujoco_bridge.hpp"

#include <cstring>
#include <memory>
#include <stdexcept>

#include "support/mjcf_writer.hpp"

namespace zwang::testing {

Mujoco::Mujoco(const std::string& xml) {
  static const char kFile[] = "zwang_model.xml";
  const auto vfs = std::make_unique<mjVFS>();  // ~2 MB of fixed-size name table: not on the stack
  mj_defaultVFS(vfs.get());
  // One byte more than the text: the buffer ends in '\0' whether or not the parser relies on a terminator.
  const int size = static_cast<int>(xml.size()) + 1;
  if (mj_makeEmptyFileVFS(vfs.get(), kFile, size) != 0) throw std::runtime_error("mj_makeEmptyFileVFS failed");
  const int file = mj_findFileVFS(vfs.get(), kFile);
  std::memcpy(vfs->filedata[file], xml.c_str(), static_cast<std::size_t>(size));
  char error[1000] = "";
  model_ = mj_loadXML(kFile, vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (model_ == nullptr) throw std::runtime_error(std::string("mj_loadXML: ") + error + "\n" + xml);
  data_ = mj_makeData(model_);
}

Mujoco::~Mujoco() {
  mj_deleteData(data_);
  mj_deleteModel(model_);
}

namespace {

int jointId(const mjModel* m, const std::string& name, int type) {
  const int id = mj_name2id(m, mjOBJ_JOINT, name.c_str());
  if (id < 0) throw std::runtime_error("MuJoCo model has no joint " + name);
  if (m->jnt_type[id] != type)
    throw std::runtime_error("MuJoCo joint " + name + " has type " + std::to_string(m->jnt_type[id]) + ", expected " +
                             std::to_string(type));
  return id;
}

}  // namespace

MujocoCoordinates mapCoordinates(const ChainSpec& spec, const FloatingBase& base, const mjModel* m) {
  if (m->nq != base.nq(spec) || m->nv != base.nv(spec))
    throw std::runtime_error("MuJoCo model has nq = " + std::to_string(m->nq) + ", nv = " + std::to_string(m->nv) +
                             "; expected " + std::to_string(base.nq(spec)) + ", " + std::to_string(base.nv(spec)));
  MujocoCoordinates map;
  if (base.kind == BaseKind::Free) {
    const int id = jointId(m, kMjcfFreeJoint, mjJNT_FREE);
    for (int k = 0; k < 7; ++k) map.qpos.push_back(m->jnt_qposadr[id] + k);
    for (int k = 0; k < 6; ++k) map.dof.push_back(m->jnt_dofadr[id] + k);
  } else if (base.kind == BaseKind::Planar) {
    const int types[] = {mjJNT_SLIDE, mjJNT_SLIDE, mjJNT_HINGE};
    const char* names[] = {kMjcfPlanarX, kMjcfPlanarY, kMjcfPlanarYaw};
    for (int k = 0; k < 3; ++k) {
      const int id = jointId(m, names[k], types[k]);
      map.qpos.push_back(m->jnt_qposadr[id]);
      map.dof.push_back(m->jnt_dofadr[id]);
    }
  }
  for (const int k : spec.movingJoints()) {
    const JointSpec& joint = spec.joints[static_cast<std::size_t>(k)];
    const int type = joint.isPrismatic()   ? mjJNT_SLIDE
                     : joint.isSpherical() ? mjJNT_BALL
                     : joint.isFree()      ? mjJNT_FREE
                                           : mjJNT_HINGE;
    const int id = jointId(m, joint.name, type);
    for (int i = 0; i < joint.nq(); ++i) map.qpos.push_back(m->jnt_qposadr[id] + i);
    for (int i = 0; i < joint.nv(); ++i) map.dof.push_back(m->jnt_dofadr[id] + i);
  }
  return map;
}

namespace {

// A free joint's place in q and v and its child's orientation ⁰R (the joint hangs from the world at the identity).
struct FreeBlock {
  Eigen::Index v = 0;
  Eigen::Matrix3d R;
};

// The base's free joint, then the spec's free joints (q and v laid out as mapCoordinates does).
std::vector<FreeBlock> freeBlocks(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q) {
  std::vector<FreeBlock> blocks;
  if (base.kind == BaseKind::Free) blocks.push_back({0, basePose(base, q).linear()});
  Eigen::Index qi = base.baseConfigurationSize(), vi = base.baseVelocitySize();
  for (const int k : spec.movingJoints()) {
    const JointSpec& joint = spec.joints[static_cast<std::size_t>(k)];
    if (joint.isFree()) {
      const Eigen::Quaterniond quat(q(qi + 3), q(qi + 4), q(qi + 5), q(qi + 6));  // w x y z
      blocks.push_back({vi, quat.normalized().toRotationMatrix()});
    }
    qi += joint.nq();
    vi += joint.nv();
  }
  return blocks;
}

}  // namespace

void scatter(const Eigen::VectorXd& x, const std::vector<int>& address, mjtNum* to) {
  for (std::size_t i = 0; i < address.size(); ++i) to[address[i]] = x(static_cast<Eigen::Index>(i));
}

Eigen::VectorXd gather(const mjtNum* from, const std::vector<int>& address) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(address.size()));
  for (std::size_t i = 0; i < address.size(); ++i) x(static_cast<Eigen::Index>(i)) = from[address[i]];
  return x;
}

Eigen::MatrixXd mujocoVelocityMap(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q) {
  const int nv = base.nv(spec);
  Eigen::MatrixXd T = Eigen::MatrixXd::Identity(nv, nv);
  for (const FreeBlock& block : freeBlocks(spec, base, q)) T.block<3, 3>(block.v, block.v) = block.R;
  return T;
}

Eigen::VectorXd mujocoVelocityMapRate(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q,
                                      const Eigen::VectorXd& v) {
  Eigen::VectorXd rate = Eigen::VectorXd::Zero(v.size());
  for (const FreeBlock& block : freeBlocks(spec, base, q))
    rate.segment<3>(block.v) =
        block.R * Eigen::Vector3d(v.segment<3>(block.v + 3)).cross(Eigen::Vector3d(v.segment<3>(block.v)));
  return rate;
}

Vector6d worldWrench(const WrenchInput& w, const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d R =
      w.axes == Axes::World ? Eigen::Matrix3d(Eigen::Matrix3d::Identity()) : Eigen::Matrix3d(pose.linear());
  Vector6d out;
  out << R * w.wrench.head<3>(), R * w.wrench.tail<3>();
  return out;
}

namespace {

int bodyId(const mjModel* m, const std::string& link) {
  const int body = mj_name2id(m, mjOBJ_BODY, link.c_str());
  if (body < 1) throw std::runtime_error("MuJoCo model has no body " + link);
  return body;
}

}  // namespace

std::vector<Eigen::Isometry3d> mujocoLinkPoses(const ChainSpec& spec, const mjModel* m, const mjData* d) {
  std::vector<Eigen::Isometry3d> poses;
  for (const LinkSpec& link : spec.links) {
    const int body = bodyId(m, link.name);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(d->xpos[3 * body], d->xpos[3 * body + 1], d->xpos[3 * body + 2]);
    pose.linear() = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>(d->xmat + 9 * body);  // MuJoCo's are row-major
    poses.push_back(pose);
  }
  return poses;
}

void addWrenchesToXfrc(const ChainSpec& spec, const std::vector<Eigen::Isometry3d>& poses,
                       const std::vector<WrenchInput>& wrenches, const mjModel* m, mjData* d) {
  for (const WrenchInput& w : wrenches) {
    const auto link = static_cast<std::size_t>(spec.linkIndex(w.link));
    const Eigen::Isometry3d& pose = poses[link];
    const Vector6d fw = worldWrench(w, pose);
    const Eigen::Vector3d c = pose * spec.links[link].com;
    const Eigen::Vector3d force = fw.head<3>();
    const Eigen::Vector3d torque = fw.tail<3>() + (pose.translation() - c).cross(force);
    const int body = bodyId(m, w.link);
    for (int k = 0; k < 3; ++k) {
      d->xfrc_applied[6 * body + k] += force(k);
      d->xfrc_applied[6 * body + 3 + k] += torque(k);
    }
  }
}

std::vector<mjtNum> wrenchGeneralizedForces(const ChainSpec& spec, const std::vector<Eigen::Isometry3d>& poses,
                                            const std::vector<WrenchInput>& wrenches, const mjModel* m, mjData* d) {
  std::vector<mjtNum> qfrc(static_cast<std::size_t>(m->nv), 0.0);
  for (const WrenchInput& w : wrenches) {
    const Eigen::Isometry3d& pose = poses[static_cast<std::size_t>(spec.linkIndex(w.link))];
    const Vector6d fw = worldWrench(w, pose);
    const mjtNum force[3] = {fw(0), fw(1), fw(2)}, torque[3] = {fw(3), fw(4), fw(5)};
    const Eigen::Vector3d p = pose.translation();
    const mjtNum point[3] = {p.x(), p.y(), p.z()};
    mj_applyFT(m, d, force, torque, point, bodyId(m, w.link), qfrc.data());
  }
  return qfrc;
}

}  // namespace zwang::testing
