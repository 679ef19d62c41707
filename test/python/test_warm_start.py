"""The friction methods and the warm start (issue #28) from Python: zwang.Friction(warm_start=True) in a loop on one
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


def test_methods_by_name_and_the_method_that_answered(panda):
    q = np.array(READY)
    rest = np.zeros(7)
    tau = np.linspace(-4.0, 5.0, 7)
    breakaway = np.linspace(0.5, 3.0, 7)  # some joints stick, some slip
    answers = {}
    for method in ("automatic", "active_set", "projected_gradient", "stick_patterns"):
        f = zwang.Friction(method=method, breakaway=breakaway)
        assert f.method == method
        answers[method] = zwang.solve(panda, panda.workspace(), q, rest, tau, friction=f).copy()
    assert answers["stick_patterns"].method == "stick_patterns"
    assert answers["active_set"].method == "active_set"
    assert answers["projected_gradient"].method == "projected_gradient"
    assert answers["automatic"].method == "active_set"  # 7 stuck joints: too few to search from every one sticking
    assert not answers["stick_patterns"].dqdd_dmu.any()  # the search forms no K
    for res in answers.values():
        np.testing.assert_allclose(res.qdd, answers["active_set"].qdd, rtol=0, atol=1e-9)
        np.testing.assert_allclose(res.mu, answers["active_set"].mu, rtol=0, atol=1e-9)
