"""Joint modes (issue #27 item 1) through zwang.solve(modes=...): the same answers as joint rows, which the dense
reference checks (test_prescribed), a closed form on the report's arm, and the modes reset between calls."""
import numpy as np
import pytest

import zwang
from conftest import READY


def test_arm_prescribed_closed_form(arm):
    """Fig. 5.5's motion told by the joint's mode: tau = I qdd (2.25 kg m^2), no friction unknown."""
    ws = arm.workspace()
    res = zwang.solve(arm, ws, [0.0], gravity=[0, 0, 0], friction=True, modes={"joint1": {"acceleration": 5.0}})
    assert res.qdd[0] == 5.0
    assert res.tau_control[0] == pytest.approx(2.25 * 5, abs=1e-12)
    assert res.state == ["prescribed"]
    res = zwang.solve(arm, ws, [0.0], [1.0], gravity=[0, 0, 0], friction=True, modes={"joint1": 5.0})
    assert res.tau_control[0] == pytest.approx(2.25 * 5 + 10, abs=1e-12)  # and overcomes kinetic friction


def test_panda_modes_match_joint_rows(panda):
    """Joint 1 locked and joint 3 prescribed: the motion and torques of the same task with joint rows (the tip's
    position stays reachable with joints 2, 4 and 6: a regular task both ways)."""
    q = np.array(READY)
    qd = np.full(7, 0.2)
    tau = np.linspace(-1.0, 1.0, 7)
    tip = zwang.Constraint("tool0", np.eye(6)[:, :3], np.zeros(3), expressed="world")
    ws = panda.workspace()
    by_modes = zwang.solve(panda, ws, q, qd, tau, constraints=[tip],
                           modes={"panda_joint1": "locked", "panda_joint3": {"acceleration": [0.5]}}).copy()
    rows = [tip, zwang.Constraint.on_joint("panda_joint1", 0.0), zwang.Constraint.on_joint("panda_joint3", 0.5)]
    by_rows = zwang.solve(panda, panda.workspace(max_constraint_rows=5), q, qd, tau, constraints=rows)
    assert by_modes.consistent and by_rows.consistent and not by_rows.singular
    np.testing.assert_allclose(by_modes.qdd, by_rows.qdd, atol=1e-10)
    np.testing.assert_allclose(by_modes.tau_control, by_rows.tau_control, atol=1e-9)
    np.testing.assert_allclose(by_modes.nu, by_rows.nu[:3], atol=1e-9)
    assert by_modes.qdd[0] == 0.0 and by_modes.qdd[2] == 0.5


def test_modes_reset_between_calls(panda):
    """A call without modes= solves every joint torque-driven, whatever the workspace's last call had."""
    q = np.array(READY)
    ws = panda.workspace()
    plain = zwang.solve(panda, ws, q).copy()
    zwang.solve(panda, ws, q, modes={"panda_joint1": "locked", "panda_joint3": 1.0})
    again = zwang.solve(panda, ws, q)
    np.testing.assert_array_equal(plain.qdd, again.qdd)
    released = zwang.solve(panda, ws, q, modes={"panda_joint1": "torque"})
    np.testing.assert_array_equal(plain.qdd, released.qdd)


def test_bad_modes(panda):
    ws = panda.workspace()
    q = np.array(READY)
    with pytest.raises(TypeError, match="modes: expected a dict"):
        zwang.solve(panda, ws, q, modes=["panda_joint1"])
    with pytest.raises(ValueError, match=r"modes\['panda_joint1'\]: unknown mode 'fixed'"):
        zwang.solve(panda, ws, q, modes={"panda_joint1": "fixed"})
    with pytest.raises(zwang.ModelError, match=r"unknown joint 'elbow'"):
        zwang.solve(panda, ws, q, modes={"elbow": "locked"})
    with pytest.raises(ValueError, match=r"acceleration\[0\]: must be finite"):
        zwang.solve(panda, ws, q, modes={"panda_joint1": float("nan")})
