"""Kinematic trees (issue #14) from Python: the whole tree, a subtree, a chain; the tree's
structure (parents, subtree_end, supports); mimic joints modelled (follow_leaders) or locked (lock_mimic=True);
constraints relative to another frame (Constraint(..., relative_to=...))."""
import warnings

import numpy as np
import pytest

import zwang
from conftest import BAXTER, PANDA, TWO_ARMS

BAXTER_JOINTS = ["head_pan", "left_s0", "left_s1", "left_e0", "left_e1", "left_w0", "left_w1", "left_w2",
                 "l_gripper_l_finger_joint", "right_s0", "right_s1", "right_e0", "right_e1", "right_w0", "right_w1",
                 "right_w2", "r_gripper_l_finger_joint"]


@pytest.fixture(scope="module")
def two_arms():
    return zwang.load_urdf(TWO_ARMS)


@pytest.fixture(scope="module")
def baxter():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", zwang.ModelWarning)
        return zwang.load_urdf(BAXTER, lock_mimic=True)


def test_the_whole_tree_and_its_structure(two_arms):
    m = two_arms
    assert m.joint_names == ["waist", "left_shoulder", "left_elbow", "right_shoulder", "right_elbow"]
    assert not m.is_chain and m.body_count == 6
    assert m.parents.tolist() == [-1, 0, 1, 0, 3]  # per joint: the joint moving its parent body
    assert [m.parent(b) for b in range(6)] == [-1, 0, 1, 2, 1, 4]
    assert [m.subtree_end(b) for b in range(6)] == [6, 6, 4, 4, 6, 6]
    assert m.supports(1, 5) and not m.supports(2, 4)
    assert m.frames[m.frame_index("sensor")].body == 1
    for bad in (-1, 6):
        with pytest.raises(IndexError, match=f"parent: body {bad} out of range"):
            m.parent(bad)
    with pytest.raises(IndexError, match="subtree_end"):
        m.subtree_end(99)


def test_subtree_and_chain(two_arms):
    sub = zwang.load_urdf(TWO_ARMS, root="chest")
    assert sub.joint_names == ["left_shoulder", "left_elbow", "right_shoulder", "right_elbow"]
    assert sub.parents.tolist() == [-1, 0, -1, 2]
    assert sub.frames[sub.frame_index("torso")].body == 0 and not sub.has_frame("world")
    with pytest.warns(zwang.ModelWarning, match="off the chain"):  # the right arm rides on the waist
        chain = zwang.load_urdf(TWO_ARMS, tip="left_hand")
    assert chain.is_chain and chain.joint_names == ["waist", "left_shoulder", "left_elbow"]
    assert zwang.load_urdf(PANDA).is_chain
    with pytest.raises(zwang.ModelError, match=r"root link 'shoulders' not found \(links: 'chest'"):
        zwang.load_urdf(TWO_ARMS, root="shoulders")


def test_mimic_joints_modelled_or_locked(baxter):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", zwang.ModelWarning)
        full = zwang.load_urdf(BAXTER)  # the default: the mimic fingers follow their leaders
    assert full.dof == 19 and len(full.mimic_joints) == 2
    for j in full.mimic_joints:
        leader, multiplier, offset = full.joints[j].mimic
        assert full.joint_names[j].endswith("_gripper_r_finger_joint")
        assert full.joint_names[leader].endswith("_gripper_l_finger_joint")
        assert (multiplier, offset) == (-1.0, 0.0)
    assert full.joints[0].mimic is None
    q, qd, tau = np.zeros(19), np.zeros(19), np.zeros(19)
    leaders = [full.joints[j].mimic[0] for j in full.mimic_joints]
    q[leaders], qd[leaders], tau[leaders] = 0.01, -0.02, 5.0
    tau[full.mimic_joints] = 1.0
    with pytest.raises(zwang.SolveError, match=r"joint 'l_gripper_r_finger_joint' mimics "
                       r"'l_gripper_l_finger_joint'.*follow_leaders"):
        zwang.solve(full, full.workspace(), q, qd, tau)
    q, qd = full.follow_leaders(q, qd)
    assert q[full.mimic_joints].tolist() == [-0.01, -0.01] and qd[full.mimic_joints].tolist() == [0.02, 0.02]
    res = zwang.solve(full, full.workspace(), q, qd, tau)
    qdd = np.array(res.qdd)
    np.testing.assert_allclose(qdd[full.mimic_joints], -qdd[leaders], atol=1e-10 * (1 + np.abs(qdd).max()))
    assert np.array(res.tau_control)[full.mimic_joints].tolist() == [0.0, 0.0]  # the leaders' motors carry them
    np.testing.assert_allclose(np.array(res.tau_control)[leaders], 5.0 - 1.0, atol=1e-12)
    # rows and rank are the task's: the two internal mimic rows are not counted (none here).
    assert (res.rows, res.rank, res.nu_unique, res.consistent) == (0, 0, True, True)

    assert baxter.joint_names == BAXTER_JOINTS  # 19 moving joints in the file, 2 of them mimic: locked
    assert [code for code, _ in baxter.warnings].count("mimic_locked") == 2
    with pytest.warns(zwang.ModelWarning) as record:
        zwang.load_urdf(BAXTER, lock_mimic=True)
    assert sum("locked at q = 0 (lock_mimic=True)" in str(w.message) for w in record) == 2
    # The lock's note passes strict mode; Baxter's placeholder inertias do not.
    with pytest.raises(zwang.ModelError, match=r"strict mode \(4 warnings\)"):
        zwang.load_urdf(BAXTER, lock_mimic=True, strict=True)


def test_balance_counts_the_task_rows_not_the_mimic_rows():
    """Baxter with its mimic fingers modelled (one internal balance row each): both grippers held in world
    axes are 12 rows, each gripper's 6 on its own 7-joint arm at a pose away from its singularities (rank 12,
    the stacked Jacobian's, computed here); a joint row on each finger of one gripper is 2 rows on one degree
    of freedom of the coupled gripper (rank 1): met when they ask for the law (qdd_r = -qdd_l), with only the
    split of the torque between them open, and not met otherwise."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", zwang.ModelWarning)
        full = zwang.load_urdf(BAXTER)
    q = np.zeros(19)
    q[1:8] = [-0.3, -0.5, -0.2, 1.2, 0.3, 0.8, -0.1]
    q[10:17] = [0.3, -0.5, 0.2, 1.2, -0.3, 0.8, 0.1]
    q, qd = full.follow_leaders(q, np.zeros(19))
    ws = full.workspace(12)
    grippers = [zwang.Constraint(f, np.eye(6), expressed="world") for f in ("left_gripper", "right_gripper")]
    J = np.vstack([zwang.frame_jacobian(full, ws, q, f, expressed="world") for f in ("left_gripper", "right_gripper")])
    assert np.linalg.matrix_rank(J) == 12
    res = zwang.solve(full, ws, q, qd, constraints=grippers)
    assert (res.rows, res.rank, res.nu_unique, res.consistent) == (12, 12, True, True)
    assert len(res.nu) == 12
    left, right = full.joint_names.index("l_gripper_l_finger_joint"), full.joint_names.index("l_gripper_r_finger_joint")
    assert full.joints[right].mimic == (left, -1.0, 0.0)
    for qdd_right, met in ((-1.0, True), (1.0, False)):
        fingers = [zwang.Constraint.on_joint("l_gripper_l_finger_joint", 1.0),
                   zwang.Constraint.on_joint("l_gripper_r_finger_joint", qdd_right)]
        res = zwang.solve(full, ws, q, qd, constraints=fingers)
        assert (res.rows, res.rank, res.singular, res.nu_unique, res.consistent) == (2, 1, True, False, met)
        if met:
            np.testing.assert_allclose(np.array(res.qdd)[[left, right]], [1.0, -1.0], rtol=1e-9)


def test_relative_constraint_two_hands_hold_a_box(baxter):
    hold = zwang.Constraint("left_gripper", np.eye(6), relative_to="right_gripper")
    assert hold.relative_to == "right_gripper" and hold.expressed == "reference"
    assert "relative to 'right_gripper'" in repr(hold)
    assert zwang.Constraint("left_gripper", np.eye(6)).relative_to is None
    ws = baxter.workspace()
    q = np.zeros(17)
    q[1:8] = [-0.3, -0.5, -0.2, 1.2, 0.3, 0.8, -0.1]
    q[9:16] = [0.3, -0.5, 0.2, 1.2, -0.3, 0.8, 0.1]
    box = zwang.Wrench("right_gripper", force=[0, 0, -30], expressed="world")
    res = zwang.solve(baxter, ws, q, constraints=[hold], wrenches=[box])
    assert res.rank == 6 and res.consistent and res.residual < 1e-12
    left, right = res.frame_acceleration("left_gripper"), res.frame_acceleration("right_gripper")
    np.testing.assert_allclose(left[3:], right[3:], atol=1e-12)  # at rest: they turn together
    # The closure: tau_control reproduces qdd through inverse dynamics (the wrench included).
    tau = zwang.inverse_dynamics(baxter, ws, q, np.zeros(17), np.array(res.qdd), wrenches=[box])
    builds = ws.task_builds
    res = zwang.solve(baxter, ws, q, constraints=[hold], wrenches=[box])
    np.testing.assert_allclose(tau, res.tau_control, atol=1e-9 * (1 + np.abs(tau).max()))
    assert ws.task_builds == builds  # the same objects: the task is not rebuilt
    # Other axes are allowed for a relative constraint; 'reference' is only for one.
    assert zwang.Constraint("left_gripper", np.eye(6), expressed="local", relative_to="right_gripper").expressed == \
        "local"
    with pytest.raises(ValueError, match="'reference' is for a constraint with 'relative_to'"):
        zwang.Constraint("left_gripper", np.eye(6), expressed="reference")
    with pytest.raises(zwang.ModelError, match=r"relative_to: is the constrained frame itself \('left_gripper'\)"):
        zwang.Constraint("left_gripper", np.eye(6), relative_to="left_gripper")
    with pytest.raises(TypeError, match="relative_to: expected a frame name"):
        zwang.Constraint("left_gripper", np.eye(6), relative_to=3)
    with pytest.raises(zwang.ModelError, match=r"constraints\[0\].relative_to: model '\w+' has no frame 'box' \(frames: "):
        zwang.solve(baxter, ws, q, constraints=[zwang.Constraint("left_gripper", np.eye(6), relative_to="box")])


def test_mimic_leader_missing_names_lock_mimic():
    urdf = """<robot name="m"><link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="m2" type="revolute"><parent link="base"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="gone" offset="0.1"/></joint>
  <link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
</robot>"""
    with pytest.raises(zwang.ModelError) as error:
        zwang.load_urdf_string(urdf)
    assert str(error.value) == (
        "<string>: joint 'm2' (q = 1·q_gone + 0.1) mimics joint 'gone', which the URDF does not have: "
        "set lock_mimic=True to weld it at q = 0.1 (its position when 'gone' is at rest)"
    )
    with pytest.warns(zwang.ModelWarning, match="locked at q = 0.1"):
        assert zwang.load_urdf_string(urdf, lock_mimic=True).dof == 1
