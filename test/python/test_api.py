"""The Python API: introspection, zero-copy results and their lifetime, the task cache,
workspace growth, and no per-call growth of memory."""
import gc
import tracemalloc

import numpy as np
import pytest

import zwang
from conftest import PANDA, READY


def test_introspection(panda):
    assert panda.name == "panda" and panda.dof == 7
    assert panda.joint_names == [f"panda_joint{k}" for k in range(1, 8)]
    assert panda.frame_names[0] == "panda_link0" and panda.frame_names[-1] == "tool0"
    assert [j.name for j in panda.joints] == panda.joint_names
    j4 = panda.joint("panda_joint4")
    assert j4.type == "revolute" and j4.lower < j4.upper and j4.breakaway_friction > 0
    assert panda.joint_index("panda_joint4") == 3 and panda.frame_index("tool0") == len(panda.frames) - 1
    for field in ["lower", "upper", "effort_limit", "velocity_limit", "breakaway_friction", "kinetic_friction",
                  "viscous_friction", "rotor_inertia"]:
        values = getattr(panda, field)
        assert values.shape == (7,) and values.dtype == np.float64
        assert list(values) == [getattr(j, field) for j in panda.joints]
    np.testing.assert_allclose(np.linalg.norm(j4.axis), 1.0)
    assert j4.placement.shape == (4, 4)
    assert panda.frames[-1].body == 7 and panda.has_frame("tool0") and not panda.has_frame("hand")
    assert 10 < panda.mass < 30
    assert "7 joints" in repr(panda)
    f = panda.with_friction([1.0] * 7)
    assert list(f.breakaway_friction) == [1.0] * 7 and list(f.kinetic_friction) == [1.0] * 7
    assert list(panda.breakaway_friction) != [1.0] * 7  # the original is unchanged (models are immutable)
    cut = zwang.load_urdf(PANDA, root="panda_link0", tip="panda_link4")
    assert cut.dof == 4
    assert zwang.load_urdf_string(PANDA.read_text(), tip="tool0").dof == 7


def test_results_are_views_until_the_next_call(panda):
    ws = panda.workspace()
    res = zwang.solve(panda, ws, READY)
    qdd = res.qdd
    assert not qdd.flags.writeable and not qdd.flags.owndata
    assert np.shares_memory(qdd, res.qdd)  # both views of ws, no copy
    kept = res.copy()
    before = qdd.copy()
    zwang.solve(panda, ws, np.zeros(7))
    with pytest.raises(zwang.StaleResultError, match="copy"):
        res.qdd
    assert not np.array_equal(qdd, before)  # the old view shows the new solve (documented)
    np.testing.assert_array_equal(kept.qdd, before)  # the copy does not
    assert kept.is_copy and not np.shares_memory(kept.qdd, qdd)
    np.testing.assert_array_equal(kept.frame_acceleration("tool0"), kept.frame_acceleration(len(panda.frames) - 1))
    # Views keep the workspace alive.
    view = zwang.solve(panda, panda.workspace(), READY).tau_control
    gc.collect()
    assert view.shape == (7,) and np.all(np.isfinite(view))


def test_result_fields(panda):
    ws = panda.workspace()
    hold = zwang.Constraint("tool0", np.eye(6), expressed="world")
    res = zwang.solve(panda, ws, READY, constraints=[hold], friction=zwang.Friction(margin=0.8))
    assert res.with_friction and res.converged and res.iterations >= 0
    assert res.rows == 6 and res.rank == 6 and not res.singular and res.condition >= 1 and res.damping == 0
    assert res.nu.shape == (6,) and res.mu.shape == (7,) and res.tau_friction.shape == (7,)
    assert res.dqdd_dmu.shape == (7, 7) and res.stuck == list(range(7))
    assert res.body_acc_local.shape == (8, 6) and res.body_acc_world.shape == (8, 6)
    assert res.gauss_dual is not None and res.kkt_residual >= 0 and res.impact_joint == -1
    np.testing.assert_allclose(res.tau_control, res.tau_constraint, atol=1e-12)  # tau = 0
    plain = zwang.solve(panda, ws, READY)
    assert plain.mu is None and plain.state is None and not plain.with_friction and not plain.indeterminate
    assert "Result" in repr(plain)


def test_task_is_built_once_and_targets_update(arm):
    ws = arm.workspace()
    c = zwang.Constraint("link1", [0, 0, 0, 0, 0, 1])
    w = zwang.Wrench("tip", expressed="world")
    for k, target in enumerate([1.0, 2.0, 3.0]):
        c.b[:] = target                 # in place
        w.force = [0.0, -k, 0.0]
        res = zwang.solve(arm, ws, [0.0], constraints=[c], wrenches=[w], gravity=[0, 0, 0])
        assert res.qdd[0] == pytest.approx(target, rel=1e-14)
        assert res.nu[0] == pytest.approx(2.25 * target + k, rel=1e-14)
    assert ws.task_builds == 1
    c.b = [4.0]
    assert zwang.solve(arm, ws, [0.0], constraints=[c], wrenches=[w]).qdd[0] == pytest.approx(4.0)
    assert ws.task_builds == 1
    zwang.solve(arm, ws, [0.0], constraints=[zwang.Constraint("link1", c.A, b=[1.0])], wrenches=[w])
    assert ws.task_builds == 2  # a new object: rebuilt
    zwang.solve(arm, ws, [0.0])
    assert ws.task_builds == 3


def test_workspace_grows_for_bigger_tasks(panda):
    ws = panda.workspace(max_constraint_rows=1)
    res = zwang.solve(panda, ws, READY, constraints=[zwang.Constraint("tool0", np.eye(6)),
                                                      zwang.Constraint("panda_link4", np.eye(6)[:, :3])])
    assert ws.constraint_capacity == 9 and res.rows == 9
    exact = zwang.Workspace(panda, 9)
    res2 = zwang.solve(panda, exact, READY, constraints=[zwang.Constraint("tool0", np.eye(6)),
                                                          zwang.Constraint("panda_link4", np.eye(6)[:, :3])])
    np.testing.assert_array_equal(res.qdd, res2.qdd)


def test_no_memory_growth_per_call(panda):
    """Repeated solves on one workspace allocate nothing that stays (Python side, tracemalloc)."""
    ws = panda.workspace()
    q, qd, tau = np.array(READY), np.zeros(7), np.zeros(7)
    hold = [zwang.Constraint("tool0", np.eye(6), expressed="world")]
    friction = zwang.Friction(margin=0.8)
    for _ in range(100):
        zwang.solve(panda, ws, q, qd, tau, constraints=hold, friction=friction)
    gc.collect()
    tracemalloc.start()
    start, _ = tracemalloc.get_traced_memory()
    for _ in range(2000):
        res = zwang.solve(panda, ws, q, qd, tau, constraints=hold, friction=friction)
        res.qdd, res.mu
    del res
    gc.collect()
    end, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert end - start < 4096
    assert peak - start < 32768  # a Result and two small view objects at a time (measured: 10 KiB)
    assert ws.task_builds == 1
