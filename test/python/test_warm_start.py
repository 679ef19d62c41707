"""Warm start of the friction solve (issue #28) from Python: zwang.Friction(warm_start=True) in a loop on one
workspace answers from the last stick/slip pattern (Result.warm_started) with the full solve's answer; the C++ test
(test_warm_start) checks both against the brute-force enumeration."""
import numpy as np

import zwang
from conftest import READY


def test_control_loop_answers_warm_with_the_full_solves_answer(panda):
    q = np.array(READY)
    qd = np.array([0.2, 0.3, -0.1, 0.4, 0.0, 0.0, 0.0])  # 3 stuck joints
    tip = zwang.Constraint("tool0", np.eye(6)[:, :2], np.zeros(2), expressed="world")
    warm = zwang.Friction(breakaway=np.full(7, 50.0), warm_start=True)
    cold = zwang.Friction(breakaway=np.full(7, 50.0))
    assert warm.warm_start and not cold.warm_start
    ws, ws_cold = panda.workspace(), panda.workspace()
    answered_warm = []
    for cycle in range(5):
        tau = np.linspace(-1.0, 1.0, 7) + 0.01 * cycle  # the next cycle's torques
        res = zwang.solve(panda, ws, q, qd, tau, constraints=[tip], friction=warm).copy()
        ref = zwang.solve(panda, ws_cold, q, qd, tau, constraints=[tip], friction=cold)
        answered_warm.append(res.warm_started)
        assert not ref.warm_started
        np.testing.assert_allclose(res.qdd, ref.qdd, rtol=0, atol=1e-10)
        np.testing.assert_allclose(res.mu, ref.mu, rtol=0, atol=1e-10)
        np.testing.assert_allclose(res.tau_control, ref.tau_control, rtol=0, atol=1e-10)
        assert res.state == ref.state
    assert answered_warm == [False, True, True, True, True]
