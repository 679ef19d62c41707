"""Result.constraint_wrench (issue #27 item 2): a closed form on the report's arm, tau_c = sum J^T w over the
constrained frames on the two-arm tree (both hands of a relative constraint), the copy, and what is refused.
The dense reference checks the wrenches themselves (test_constraint_wrench.cpp)."""
import numpy as np
import pytest

import zwang
from conftest import TWO_ARMS


def test_arm_moment_row_closed_form(arm):
    """One moment row about z on link1 (2.25 kg m^2 about the joint), no gravity: nu = 2.25 qdd, the wrench
    [0, 0, 0, 0, 0, nu] in the link's axes and the world's (the link turns about z)."""
    row = zwang.Constraint("link1", [0, 0, 0, 0, 0, 1], [5.0], expressed="local")
    res = zwang.solve(arm, arm.workspace(), [0.3], constraints=[row], gravity=[0, 0, 0])
    nu = res.nu[0]
    assert nu == pytest.approx(2.25 * 5, abs=1e-12)  # the sweeps' rounding
    for expressed in ("local", "world"):
        np.testing.assert_allclose(res.constraint_wrench("link1", expressed), [0, 0, 0, 0, 0, nu], atol=1e-14)
    np.testing.assert_array_equal(res.constraint_wrench("base"), np.zeros(6))  # no constraint on it


def test_two_arms_relative_tau_c_and_copy():
    """The left hand held where the right hand sees it, under gravity: the hands' wrenches through the frames'
    Jacobians are tau_c (no contacts, no joint rows); equal and opposite forces."""
    model = zwang.load_urdf(str(TWO_ARMS))
    q = np.array([0.3, -0.4, 0.05, 0.7, -1.1])
    hold = zwang.Constraint("left_hand", np.eye(6)[:, :3], np.zeros(3), relative_to="right_hand")
    ws = model.workspace()
    res = zwang.solve(model, ws, q, constraints=[hold])
    left, right = res.constraint_wrench("left_hand"), res.constraint_wrench("right_hand")
    np.testing.assert_allclose(left[:3], -right[:3], atol=1e-12)
    jac = model.workspace()  # another workspace: a query on ws would make res stale
    tau_c = sum(zwang.frame_jacobian(model, jac, q, f, "world").T @ res.constraint_wrench(f)
                for f in ("left_hand", "right_hand"))
    np.testing.assert_allclose(tau_c, res.tau_constraint, atol=1e-10 * max(1.0, np.abs(tau_c).max()))
    local = res.constraint_wrench("left_hand", expressed="local")
    R = zwang.frame_pose(model, jac, q, "left_hand")[:3, :3]
    np.testing.assert_allclose(local, np.concatenate([R.T @ left[:3], R.T @ left[3:]]), atol=1e-12)
    kept = res.copy()
    zwang.solve(model, ws, q)  # the workspace moves on: the copy keeps its wrenches, the view is stale
    np.testing.assert_array_equal(kept.constraint_wrench("left_hand"), left)
    np.testing.assert_array_equal(kept.constraint_wrench("left_hand", "local"), local)
    with pytest.raises(zwang.StaleResultError):
        res.constraint_wrench("left_hand")
    with pytest.raises(Exception, match="nowhere"):
        kept.constraint_wrench("nowhere")
