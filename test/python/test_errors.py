"""Bad input from Python raises a clear exception and never crashes the interpreter."""
import subprocess
import sys

import numpy as np
import pytest

import zwang
from conftest import ARM, PANDA, READY


@pytest.fixture
def ws(panda):
    return panda.workspace()


def solve(panda, ws, **kw):
    args = dict(q=np.array(READY), qd=np.zeros(7), tau=np.zeros(7))
    args.update(kw)
    return zwang.solve(panda, ws, args.pop("q"), args.pop("qd"), args.pop("tau"), **args)


@pytest.mark.parametrize("name", ["q", "qd", "tau"])
def test_wrong_length_carries_the_cpp_status(panda, ws, name):
    with pytest.raises(zwang.SolveError) as e:
        solve(panda, ws, **{name: np.zeros(6)})
    assert e.value.code == "SizeMismatch"
    assert e.value.status_message == f"{name} has 6 entries, the model has 7 joints"
    assert isinstance(e.value, ValueError) and isinstance(e.value, zwang.Error)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite(panda, ws, bad):
    q = np.array(READY)
    q[3] = bad
    with pytest.raises(zwang.SolveError, match=r"q\[3\] \(joint 'panda_joint4'\) is .*not finite") as e:
        solve(panda, ws, q=q)
    assert e.value.code == "NonFinite"
    with pytest.raises(zwang.SolveError, match="gravity"):
        solve(panda, ws, gravity=[0, 0, bad])
    w = zwang.Wrench("tool0", [0, 0, bad, 0, 0, 0])
    with pytest.raises(zwang.SolveError, match="wrench 0"):
        solve(panda, ws, wrenches=[w])
    c = zwang.Constraint("tool0", np.eye(6)[:, :1], b=[bad])
    with pytest.raises(zwang.SolveError, match="constraint targets"):
        solve(panda, ws, constraints=[c])
    with pytest.raises(ValueError, match="non-finite"):
        zwang.Constraint("tool0", [0, 0, bad, 0, 0, 1])


@pytest.mark.parametrize("value, error, text", [
    (np.zeros(7, dtype=complex), TypeError, "complex"),
    (np.zeros(7, dtype=bool), TypeError, "bool"),
    (np.array(["a"] * 7), TypeError, "dtype <U1"),
    ("0123456", TypeError, "real numbers"),
    (None, TypeError, "None"),
    ([0.0] * 6 + ["x"], TypeError, "real numbers"),
    (np.array([object()] * 7), TypeError, "object"),
    (np.zeros((7, 1)), ValueError, r"1-D array, got shape \(7, 1\)"),
    (np.zeros((1, 7)), ValueError, "1-D"),
    (np.float64(1.0), ValueError, "1-D"),
    ({"a": 1}, TypeError, "real numbers"),
])
def test_wrong_dtype_or_shape(panda, ws, value, error, text):
    with pytest.raises(error, match=text):
        zwang.solve(panda, ws, value)


def test_accepted_inputs_give_the_same_answer(panda, ws):
    """float64 arrays are read in place; lists, ints, float32, big-endian and strided arrays are converted."""
    q = np.array(READY)
    ref = zwang.solve(panda, ws, q).copy()
    strided = np.zeros(14)
    strided[::2] = q
    for variant in [list(q), tuple(q), q.astype(">f8"), strided[::2], np.asfortranarray(q)]:
        np.testing.assert_array_equal(zwang.solve(panda, ws, variant).qdd, ref.qdd)
    np.testing.assert_allclose(zwang.solve(panda, ws, q.astype(np.float32)).qdd, ref.qdd, rtol=1e-5, atol=1e-5)
    ints = zwang.solve(panda, ws, np.zeros(7, dtype=np.int64)).copy()
    np.testing.assert_array_equal(ints.qdd, zwang.solve(panda, ws, np.zeros(7)).qdd)


def test_unknown_frames_and_joints(panda, ws):
    with pytest.raises(
        zwang.ModelError,
        match=r"constraints\[1\]\.frame: model 'panda' has no frame 'hand' \(frames: 'panda_link0', .*'tool0'",
    ):
        solve(panda, ws, constraints=[zwang.Constraint("tool0", np.eye(6)), zwang.Constraint("hand", np.eye(6))])
    with pytest.raises(zwang.ModelError, match=r"wrenches\[0\]\.frame: model 'panda' has no frame 'nowhere' \(frames: "):
        solve(panda, ws, wrenches=[zwang.Wrench("nowhere")])
    with pytest.raises(zwang.ModelError, match="no frame 'hand'"):
        panda.frame_index("hand")
    with pytest.raises(zwang.ModelError, match="no moving joint 'elbow'"):
        panda.joint("elbow")
    with pytest.raises(zwang.ModelError, match="out of range"):
        zwang.frame_pose(panda, ws, READY, 99)
    # Every kinematics accessor: names and indices, past either end.
    for frame in [-1, len(panda.frames), "hand"]:
        with pytest.raises(zwang.ModelError):
            zwang.frame_pose(panda, ws, READY, frame)
        with pytest.raises(zwang.ModelError):
            zwang.frame_velocity(panda, ws, READY, np.zeros(7), frame)
        with pytest.raises(zwang.ModelError):
            zwang.frame_jacobian(panda, ws, READY, frame)
        with pytest.raises(zwang.ModelError):
            solve(panda, ws).frame_acceleration(frame)
    # The workspace still works after the errors.
    assert solve(panda, ws).qdd.shape == (7,)


def test_frame_pose_of_the_last_kinematics_needs_some(panda, ws):
    # q=None reads what the workspace holds: nothing yet is NotComputed (the
    # C++ Status, issue #24), not a meaningless pose.
    with pytest.raises(zwang.SolveError) as e:
        zwang.frame_pose(panda, ws, None, "tool0")
    assert e.value.code == "NotComputed"
    assert e.value.status_message.startswith("framePose: the workspace holds no kinematics")
    # A call that fails computes nothing either.
    zwang.forward_kinematics(panda, ws, READY)
    with pytest.raises(zwang.SolveError):
        zwang.forward_kinematics(panda, ws, np.full(7, np.nan))
    with pytest.raises(zwang.SolveError, match="NotComputed|holds no kinematics"):
        zwang.frame_pose(panda, ws, None, "tool0")
    # After kinematics or a solve: the pose at that q.
    zwang.forward_kinematics(panda, ws, READY)
    expected = zwang.frame_pose(panda, panda.workspace(), READY, "tool0")
    np.testing.assert_array_equal(zwang.frame_pose(panda, ws, None, "tool0"), expected)
    solve(panda, ws)
    np.testing.assert_array_equal(zwang.frame_pose(panda, ws, None, "tool0"), expected)


def test_bad_constraints_wrenches_and_options(panda, ws):
    with pytest.raises(ValueError, match=r"6×m matrix"):
        zwang.Constraint("tool0", np.eye(5))
    with pytest.raises(ValueError, match=r"6×m matrix"):
        zwang.Constraint("tool0", np.eye(6).T.reshape(36))
    with pytest.raises(ValueError, match="b: has 2 entries, A has 1 columns"):
        zwang.Constraint("tool0", np.eye(6)[:, :1], b=[1.0, 2.0])
    with pytest.raises(ValueError, match="expected 'local', 'world' or 'aligned'"):
        zwang.Constraint("tool0", np.eye(6), expressed="global")
    with pytest.raises(ValueError, match="expected 'local' or 'world'"):
        zwang.Wrench("tool0", expressed="aligned")
    with pytest.raises(ValueError, match="expected 6 numbers"):
        zwang.Wrench("tool0", [1, 2, 3])
    c = zwang.Constraint("tool0", np.eye(6)[:, :2])
    with pytest.raises(ValueError, match="b: has 3 entries"):
        c.b = [1, 2, 3]
    with pytest.raises(TypeError, match=r"constraints\[0\]: expected zwang.Constraint, got Wrench"):
        solve(panda, ws, constraints=[zwang.Wrench("tool0")])
    with pytest.raises(TypeError, match="expected a list of zwang.Wrench"):
        solve(panda, ws, wrenches="tool0")
    with pytest.raises(TypeError, match="friction"):
        solve(panda, ws, friction=0.8)
    with pytest.raises(ValueError, match=r"margin: must be between 0 and 1, got 1.5"):
        zwang.Friction(margin=1.5)
    with pytest.raises(zwang.ModelError, match=r"breakaway: has 3 entries, expected 7 \(one per moving joint"):
        solve(panda, ws, friction=zwang.Friction(breakaway=[1, 2, 3]))
    with pytest.raises(ValueError, match=r"kinetic\[0\]: must be finite and >= 0, got nan"):
        solve(panda, ws, friction=zwang.Friction(kinetic=[np.nan] + [0.0] * 6))
    with pytest.raises(ValueError, match="method: unknown value 'newton' \\(expected one of 'automatic', 'active_set', "
                                         "'projected_gradient', 'stick_patterns'\\)"):
        zwang.Friction(method="newton")
    with pytest.raises(ValueError, match="expected 3 numbers"):
        solve(panda, ws, gravity=[0, -9.81])
    with pytest.raises(TypeError):
        zwang.Friction(0.8)  # keyword-only


def test_model_and_workspace_mismatch(panda, arm):
    ws_arm = arm.workspace()
    with pytest.raises(zwang.SolveError, match="made for model 'one_dof_arm'") as e:
        zwang.solve(panda, ws_arm, READY)
    assert e.value.code == "ModelMismatch"
    with pytest.raises(TypeError, match="zwang.Workspace"):
        zwang.solve(panda, "ws", READY)
    with pytest.raises(TypeError):
        zwang.solve(None, ws_arm, [0.0])


def test_urdf_errors(tmp_path):
    with pytest.raises(zwang.ModelError, match="no_such.urdf"):
        zwang.load_urdf(tmp_path / "no_such.urdf")
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='r'><link name='a'/><joint name='j' type='revolute'>")
    with pytest.raises(zwang.ModelError):
        zwang.load_urdf(bad)
    with pytest.raises(zwang.ModelError, match="tip"):
        zwang.load_urdf(PANDA, tip="no_link")
    with pytest.raises(zwang.ModelError):
        zwang.load_urdf_string("not xml at all")
    with pytest.raises(TypeError):
        zwang.load_urdf(PANDA, rotor_inertia=[1, 2])
    arm = zwang.load_urdf(ARM)
    with pytest.raises(zwang.ModelError, match=r"rotor_inertia: has 2 entries, expected 1 \(one per moving joint: joint1\)"):
        arm.with_rotor_inertia([1.0, 2.0])
    with pytest.raises(ValueError, match=r"rotor_inertia\[0\]: must be finite and >= 0, got -1"):
        arm.with_rotor_inertia([-1.0])


def test_infeasible_raises_with_the_finite_result(arm):
    """docs/friction.md, "Joint position limits": the arm on its upper limit, driven into it."""
    ws = arm.workspace()
    push = zwang.Constraint("link1", [0, 0, 0, 0, 0, 1], b=[5.0])
    with pytest.raises(zwang.InfeasibleError, match="upper limit") as e:
        zwang.solve(arm, ws, [arm.upper[0]], constraints=[push], friction=True, gravity=[0, 0, 0])
    assert e.value.code == "Infeasible" and isinstance(e.value, zwang.SolveError)
    res = e.value.result
    assert res.infeasible and "upper limit" in res.message
    assert np.all(np.isfinite(res.qdd)) and np.all(np.isfinite(res.mu))


def test_garbage_never_crashes_the_interpreter():
    """Random junk into every entry point, in a child interpreter: only Python exceptions."""
    code = r'''
import random, numpy as np, zwang, sys
m = zwang.load_urdf(sys.argv[1], tip="tool0"); ws = m.workspace()
junk = [None, 1, -1, 1e308, float("nan"), "tool0", "", b"x", [], [1.0] * 7, np.zeros(7), np.zeros((7, 7)),
        np.zeros(0), np.array([np.nan] * 7), np.zeros(7, dtype=complex), object(), {}, (1, 2), np.zeros(6),
        [zwang.Wrench("tool0")], [zwang.Constraint("tool0", np.eye(6))], zwang.Friction(), True, ws, m,
        [zwang.Constraint("tool0", np.eye(6), relative_to="panda_link3")], 7, 8, "reference"]
calls = [lambda a, b, c: zwang.solve(m, ws, a, b, c),
         lambda a, b, c: zwang.solve(m, ws, np.zeros(7), constraints=a, wrenches=b, friction=c),
         lambda a, b, c: zwang.solve(m, ws, a, gravity=b, friction=c),
         lambda a, b, c: zwang.Constraint(a, b, c),
         lambda a, b, c: zwang.Constraint(a, np.eye(6), expressed=b, relative_to=c),
         lambda a, b, c: (m.parent(a), m.subtree_end(b), m.supports(a, c)),
         lambda a, b, c: zwang.load_urdf_string(a, b, c, lock_mimic=True),
         lambda a, b, c: zwang.Wrench(a, b),
         lambda a, b, c: zwang.frame_jacobian(m, ws, a, b, c),
         lambda a, b, c: zwang.inverse_dynamics(m, ws, a, b, c),
         lambda a, b, c: zwang.Workspace(a, b),
         lambda a, b, c: zwang.simulate(m, ws, a, b, c, duration=0.01),
         lambda a, b, c: zwang.simulate(m, ws, np.zeros(7), duration=a, dt=b, schedule_t=c, schedule_tau=c),
         lambda a, b, c: zwang.load_urdf_string(a, b, c)]
rng = random.Random(3)
count = 0
for _ in range(4000):
    f = rng.choice(calls)
    try:
        f(rng.choice(junk), rng.choice(junk), rng.choice(junk))
    except (zwang.Error, TypeError, ValueError, RuntimeError, OverflowError, IndexError):
        count += 1
print("ok", count)
'''
    out = subprocess.run([sys.executable, "-c", code, str(PANDA)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.startswith("ok")


def test_balance_options_out_of_range(panda, ws):
    with pytest.raises(ValueError, match=r"singular_threshold: must be between 0 and 1 \(exclusive\), got 0"):
        zwang.Balance(singular_threshold=0)
    with pytest.raises(ValueError, match=r"rank_tolerance: must be >= 0 and below singular_threshold \(0.0001\), got 0.001"):
        zwang.Balance(singular_threshold=1e-4, rank_tolerance=1e-3)
    with pytest.raises(ValueError, match="residual_tolerance: must be finite and positive, got nan"):
        zwang.Balance(residual_tolerance=float("nan"))
    with pytest.raises(TypeError, match="balance: expected zwang.Balance"):
        solve(panda, ws, balance={"singular_threshold": 1e-6})
    with pytest.raises(TypeError):
        zwang.Balance(1e-6)  # keyword-only
