"""zwang.simulate (issue #29; docs/simulation.md): the report's 1-DOF arm under a torque ramp against the closed form,
the same run as the CLI's (test_cli_simulate) and the C++ test's, the GIL released while it steps, and bad arguments
refused with the problem layer's words."""
import math
import threading

import numpy as np
import pytest

import zwang

RAMP_T = [0.0, 1.0, 3.0]
RAMP_TAU = [[0.0], [20.0], [-20.0]]


def ramp(arm, integrator="rk4", duration=2.6, **kwargs):
    ws = arm.workspace()
    return zwang.simulate(arm, ws, [0.0], [0.0], duration=duration, dt=1e-3, integrator=integrator,
                          schedule_t=RAMP_T, schedule_tau=RAMP_TAU, friction=True, gravity=[0, 0, 0], **kwargs)


def test_ramp_sticks_slips_and_sticks_at_the_closed_forms_times(arm):
    run = ramp(arm)
    # Breakaway at τ = f = 10 N·m (0.5 s), at rest at 1 + (1 + √2)/2 s, away again at τ = −f (2.5 s).
    expected = [(0.5, "slip+"), (1.0 + 0.5 * (1.0 + math.sqrt(2.0)), "stick"), (2.5, "slip-")]
    assert [(name, kind) for _, name, kind in run["events"]] == [("joint1", k) for _, k in expected]
    for (t, _, _), (t_exact, _) in zip(run["events"], expected):
        assert abs(t - t_exact) < 1e-9
    assert run["t"].shape == (2601,) and run["q"].shape == (2601, 1) and run["tau_control"].shape == (2600, 1)
    assert run["t"][1000] == 1.0  # the grid k·dt
    assert run["state"][100] == ["stick"] and abs(run["mu"][100, 0] - 2.0) < 1e-9  # μ = τ = 20 t while it sticks
    rest = run["q"][2210:2500, 0]
    assert np.all(rest == rest[0])  # not a bit of creep at rest
    d, T, a, inertia = 0.5, 0.5 * (1.0 + math.sqrt(2.0)), 20.0, 2.25
    q_closed = a * d**3 / (6 * inertia) + a * d * d / (2 * inertia) * T + a / inertia * (0.5 * d * T * T - T**3 / 6)
    assert rest[0] == pytest.approx(q_closed, rel=1e-9)
    assert abs(run["energy"]["balance_error"]) < 1e-9


def test_the_gil_is_released_while_it_steps(arm):
    # Two runs on two threads give the single run's result; the GIL released, they overlap (not timed here: the
    # C++ thread test checks determinism, this that the binding lets go of the interpreter without breaking it).
    results = [None, None]

    def work(k):
        results[k] = ramp(arm, integrator="euler", duration=1.0)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    single = ramp(arm, integrator="euler", duration=1.0)
    for r in results:
        np.testing.assert_array_equal(r["q"], single["q"])
        assert r["events"] == single["events"]


def test_bad_arguments_are_refused_in_the_problem_layers_words(arm):
    ws = arm.workspace()
    with pytest.raises(ValueError, match="dt: must be finite and > 0"):
        zwang.simulate(arm, ws, [0.0], duration=1.0, dt=-1.0)
    with pytest.raises(ValueError, match="unknown integrator 'leapfrog'"):
        zwang.simulate(arm, ws, [0.0], duration=1.0, integrator="leapfrog")
    with pytest.raises(ValueError, match=r"schedule.t\[2\]: must be after t\[1\]"):
        zwang.simulate(arm, ws, [0.0], duration=1.0, schedule_t=[0, 3, 1], schedule_tau=RAMP_TAU)
    with pytest.raises(ValueError, match="schedule_tau needs schedule_t"):
        zwang.simulate(arm, ws, [0.0], duration=1.0, schedule_tau=RAMP_TAU)
