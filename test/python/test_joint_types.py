"""Joint types from Python (docs/python.md, "Joint types"; docs/conventions.md, "Joint types"):
zwang.ModelBuilder builds every type anywhere in the tree, Joint.nq/nv/q_index/v_index, Model.all_joints and
Model.dofs describe the layout, and the configuration helpers work on every joint type. References are
independent of zwang: rotation matrices from quaternions and by Rodrigues from axis-angle, written out here,
and the exponential of a twist by a Taylor series with scaling and squaring."""
import math

import numpy as np
import pytest

import zwang
from conftest import MODELS

EYE = np.eye(3) * 0.01


def shifted(x=0.1, y=0.0, z=0.0):
    T = np.eye(4)
    T[:3, 3] = [x, y, z]
    return T


def mixed(base="free"):
    """hip (spherical) → knee (revolute) → slider (planar) → drone (free) → slide (prismatic), and a wheel
    (continuous) off the base: every joint type, the multi-DOF ones in the middle of the tree."""
    b = zwang.ModelBuilder("mixed", "base")
    inertial = dict(mass=1.0, com=[0.1, 0, 0], inertia=EYE)
    b.add_joint("hip", "spherical", "thigh", parent="base", placement=shifted(), **inertial)
    b.add_joint("knee", "revolute", "shin", axis=[0, 1, 0], placement=shifted(), lower=-2.0, upper=0.5, **inertial)
    b.add_joint("slider", "planar", "sled", placement=shifted(), **inertial)
    b.add_joint("drone", "free", "body", placement=shifted(), **inertial)
    b.add_joint("slide", "prismatic", "tip", axis=[1, 0, 0], placement=shifted(), **inertial)
    b.add_joint("wheel", "continuous", "rim", parent="base", axis=[0, 0, 1], placement=shifted(y=0.2), **inertial)
    b.add_base_link_inertia(2.0, inertia=EYE)
    if base != "fixed":
        b.set_base(base)
    return b.build()


def rotation(q):
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def skew(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def rodrigues(w):
    theta = np.linalg.norm(w)
    if theta == 0:
        return np.eye(3)
    A = skew(np.asarray(w) / theta)
    return np.eye(3) + math.sin(theta) * A + (1 - math.cos(theta)) * A @ A


def expm(M):
    """exp(M): scaled below norm 1/2, 30 Taylor terms, squared back."""
    s = max(0, math.ceil(math.log2(max(np.abs(M).sum(axis=1).max(), 1e-300) / 0.5)))
    A = M / 2.0 ** s
    E, term = np.eye(len(M)), np.eye(len(M))
    for k in range(1, 31):
        term = term @ A / k
        E = E + term
    for _ in range(s):
        E = E @ E
    return E


def pose(q7):
    M = np.eye(4)
    M[:3, :3], M[:3, 3] = rotation(q7[3:]), q7[:3]
    return M


def twist(v6):
    T = np.zeros((4, 4))
    T[:3, :3], T[:3, 3] = skew(v6[3:]), v6[:3]
    return T


def joint_distance(joint, a, b):
    x, y = a[joint.q_index:joint.q_index + joint.nq], b[joint.q_index:joint.q_index + joint.nq]
    if joint.type == "spherical":
        return np.abs(rotation(x) - rotation(y)).max()
    if joint.type == "free":
        return np.abs(pose(x) - pose(y)).max()
    if joint.type == "planar":
        return max(np.abs(x[:2] - y[:2]).max(), abs(math.remainder(x[2] - y[2], 2 * math.pi)))
    return abs(x[0] - y[0])


def test_the_builder_makes_every_joint_type_and_the_layout_is_readable():
    model = mixed()
    types = [j.type for j in model.all_joints]
    assert types == ["free", "spherical", "revolute", "planar", "free", "prismatic", "continuous"]
    assert model.all_joints[0].name == "root_joint" and [j.name for j in model.joints] == model.joint_names
    assert [(j.nq, j.nv, j.q_index, j.v_index) for j in model.all_joints] == [
        (7, 6, 0, 0), (4, 3, 7, 6), (1, 1, 11, 9), (3, 3, 12, 10), (7, 6, 15, 13), (1, 1, 22, 19), (1, 1, 23, 20)]
    assert (model.nq, model.nv, model.dof, model.body_count, model.base_body) == (24, 21, 15, 22, 6)
    names = [d.name for d in model.dofs]
    assert names[:9] == ["root_joint.vx", "root_joint.vy", "root_joint.vz", "root_joint.wx", "root_joint.wy",
                         "root_joint.wz", "hip.wx", "hip.wy", "hip.wz"]
    assert names[9:13] == ["knee", "slider.x", "slider.y", "slider.yaw"] and names[-2:] == ["slide", "wheel"]
    assert [d.joint for d in model.dofs][5:8] == [-1, 0, 0]
    assert model.dofs[10].in_joint_frame and not model.dofs[10].rotation and model.dofs[12].rotation
    # knee hangs from the hip, the wheel from the base; per-DOF arrays have model.dof entries
    np.testing.assert_array_equal(model.parents, [-1, 0, 1, 2, 3, -1])
    assert model.lower.shape == (15,) and model.lower[3] == -2.0 and np.isinf(model.lower[0])
    assert "6 joints" in repr(model) and repr(model.all_joints[1]) == "<zwang.Joint 'hip' spherical>"
    fixed = mixed("fixed")
    assert (fixed.nq, fixed.nv, fixed.dof, fixed.base_body) == (17, 15, 15, 0)
    assert [j.q_index for j in fixed.all_joints] == [0, 4, 5, 8, 15, 16]


def test_a_loaded_floating_base_is_its_root_joint():
    solo = zwang.load_urdf(MODELS / "solo12.urdf", base="free")
    root = solo.all_joints[0]
    assert (root.name, root.type, root.nq, root.nv, root.q_index, root.v_index) == ("root_joint", "free", 7, 6, 0, 0)
    assert len(solo.all_joints) == 13 and solo.all_joints[1].q_index == 7 and solo.all_joints[1].v_index == 6
    assert solo.parents[0] == -1 and solo.base_body == 6 and len(solo.dofs) == 18


def test_builder_errors():
    b = zwang.ModelBuilder()
    with pytest.raises(ValueError, match="type: unknown joint type 'ball'"):
        b.add_joint("j", "ball", "l", mass=1.0)
    with pytest.raises(ValueError, match="placement: expected a finite 4×4 rigid transform"):
        b.add_joint("j", "revolute", "l", mass=1.0, placement=2 * np.eye(4))
    with pytest.raises(ValueError, match="placement: expected a 4×4 matrix, got shape"):
        b.add_joint("j", "revolute", "l", mass=1.0, placement=np.eye(3))
    with pytest.raises(zwang.ModelError, match="joint 'j'"):
        b.add_joint("j", "spherical", "l", mass=1.0, lower=-1.0, upper=1.0)  # multi-DOF: no position limits
    with pytest.raises(ValueError,
                       match=r"set_base: unknown value 'fixed' \(expected 'free' or 'planar'; a fixed base is a builder"):
        b.set_base("fixed")
    assert b.add_joint("j", "spherical", "l", mass=1.0) is b  # chains
    c, s = math.cos(0.3), math.sin(0.3)
    P = np.array([[c, -s, 0, 0.1], [s, c, 0, 0.2], [0, 0, 1, 0.3], [0, 0, 0, 1.0]])
    b.add_joint("k", "revolute", "m", mass=1.0, placement=P)
    np.testing.assert_array_equal(b.build().joint("k").placement, P)  # the pose given is the pose read back
    with pytest.raises(zwang.ModelError, match="zero mass on a moving body"):
        zwang.ModelBuilder().add_joint("j", "free", "l").build()


def test_per_dof_friction_and_rotor_inertia():
    model = mixed()
    f = np.arange(model.dof, dtype=float)
    with pytest.raises(zwang.ModelError, match=r"breakaway: entries 0-2 \(the DOFs of joint 'hip'\) differ"):
        model.with_friction(f)
    per_joint = model.with_friction([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])  # one per joint
    np.testing.assert_array_equal(per_joint.breakaway_friction, [1, 1, 1, 2, 3, 3, 3, 4, 4, 4, 4, 4, 4, 5, 6])
    again = model.with_friction(per_joint.breakaway_friction)  # one per DOF, as the getter gives them
    np.testing.assert_array_equal(again.breakaway_friction, per_joint.breakaway_friction)
    assert [d.breakaway_friction for d in again.dofs][:6] == [0.0] * 6  # the root joint: no friction
    heavy = model.with_rotor_inertia(np.full(model.dof, 0.5))
    assert heavy.dofs[6].rotor_inertia == 0.5 and heavy.joint("drone").rotor_inertia == 0.5
    with pytest.raises(zwang.ModelError, match=r"has 4 entries, expected 6 \(one per moving joint: .*\) or 15 \(one per DOF: "):
        model.with_rotor_inertia([1.0, 2.0, 3.0, 4.0])


@pytest.mark.parametrize("base", ["fixed", "free", "planar"])
def test_configuration_helpers_on_every_joint_type(base):
    model = mixed(base)
    rng = np.random.default_rng(25)
    q, state = zwang.random_configuration(model, 2511)
    q1, _ = zwang.random_configuration(model, state)
    again, state2 = zwang.random_configuration(model, 2511)
    np.testing.assert_array_equal(again, q)  # reproducible
    assert state2 == state
    for joint in model.all_joints:
        i = joint.q_index + {"spherical": 0, "free": 3}.get(joint.type, -100)
        if i >= 0:
            assert abs(np.linalg.norm(q[i:i + 4]) - 1) < 4e-16  # unit to a rounding or two
    zwang.check_configuration(model, q)

    # integrate against the closed forms, joint by joint
    v = rng.uniform(-2, 2, model.nv)
    dt = 0.7
    out = zwang.integrate(model, q, v, dt)
    for joint in model.all_joints:
        x, y = q[joint.q_index:joint.q_index + joint.nq], out[joint.q_index:joint.q_index + joint.nq]
        w = v[joint.v_index:joint.v_index + joint.nv]
        if joint.type == "spherical":
            expected = rotation(x) @ rodrigues(w * dt)
            np.testing.assert_allclose(rotation(y), expected, atol=1e-13, err_msg=joint.name)
        elif joint.type == "free":
            np.testing.assert_allclose(pose(y), pose(x) @ expm(twist(w) * dt), atol=1e-13, err_msg=joint.name)
        else:
            np.testing.assert_allclose(y, x + w * dt, atol=1e-14, err_msg=joint.name)

    # round trips: integrate(q, q1 - q, 1) = q1 up to the quaternion's sign; (q + w dt) - q = w dt
    d = zwang.difference(model, q, q1)
    back = zwang.integrate(model, q, d)
    assert max(joint_distance(j, back, q1) for j in model.all_joints) < 1e-12
    small = v * 0.3  # rotations under pi
    np.testing.assert_allclose(zwang.difference(model, q, zwang.integrate(model, q, small, 1.0)), small, atol=1e-12)

    # neutral: identity quaternions, zeros, the knee clamped into [-2, 0.5] (0 is inside)
    n = zwang.neutral_configuration(model)
    for joint in model.all_joints:
        expected = {"spherical": [1, 0, 0, 0], "free": [0, 0, 0, 1, 0, 0, 0]}.get(joint.type, [0.0] * joint.nq)
        np.testing.assert_array_equal(n[joint.q_index:joint.q_index + joint.nq], expected)

    # normalisation: every quaternion, nothing else
    scaled = q.copy()
    for joint in model.all_joints:
        i = joint.q_index + {"spherical": 0, "free": 3}.get(joint.type, -100)
        if i >= 0:
            scaled[i:i + 4] *= 3.0
    np.testing.assert_allclose(zwang.normalize_configuration(model, scaled), q, atol=4e-16)


def test_messages_name_the_joint_and_the_coordinate():
    model = mixed()
    q = zwang.neutral_configuration(model)
    bad = q.copy()
    bad[8] = np.nan
    with pytest.raises(zwang.SolveError, match=r"q\[8\] \(joint 'hip' quaternion x\) is nan") as e:
        zwang.check_configuration(model, bad)
    assert e.value.code == "NonFinite"
    bad = q.copy()
    bad[18:22] *= 2
    with pytest.raises(zwang.SolveError,
                       match=r"q: joint 'drone' quaternion \(entries 18-21, w x y z\) has norm 2") as e:
        zwang.integrate(model, bad, np.zeros(model.nv))
    assert e.value.code == "BadConfiguration"
    with pytest.raises(zwang.SolveError, match=r"v\[7\] \(joint 'hip' angular velocity y \(child axes\)\) is inf"):
        v = np.zeros(model.nv)
        v[7] = np.inf
        zwang.integrate(model, q, v)
    with pytest.raises(zwang.SolveError, match=r"nq = 24 \(7 base coordinates \+ 17 joint coordinates\)"):
        zwang.check_configuration(model, q[:-1])
