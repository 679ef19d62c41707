"""The reference cases and closed forms, from Python (docs/theory.md, "The reference cases")."""
import math

import numpy as np
import pytest

import zwang
from conftest import READY

NO_GRAVITY = [0.0, 0.0, 0.0]
I_JOINT = 2.25  # inertia of the report's arm about its joint: I_zz 2 at the COM + 1 kg * 0.5 m^2


def tip_force(fy):
    return zwang.Wrench("tip", force=[0.0, fy, 0.0], expressed="world")


def test_arm_model_is_the_reports(arm):
    assert arm.dof == 1 and arm.joint_names == ["joint1"]
    assert arm.frame_names == ["base", "link1", "tip"]
    assert arm.breakaway_friction[0] == 10.0
    ws = arm.workspace()
    H = zwang.joint_space_inertia(arm, ws, [0.3])
    assert H[0, 0] == pytest.approx(I_JOINT, rel=1e-14)


def test_scenario1_minus_5N_sticks(arm):
    ws = arm.workspace()
    res = zwang.solve(arm, ws, [0.0], [0.0], [0.0], wrenches=[tip_force(-5.0)], friction=zwang.Friction(),
                      gravity=NO_GRAVITY)
    assert res.state == ["stick"]
    assert res.mu[0] == pytest.approx(-5.0, abs=1e-12)
    assert res.qdd[0] == pytest.approx(0.0, abs=1e-12)
    assert res.tau_control[0] == pytest.approx(0.0, abs=1e-12)
    assert res.stuck == [0] and res.converged and not res.indeterminate


def test_scenario2_minus_11N_slips(arm):
    ws = arm.workspace()
    res = zwang.solve(arm, ws, [0.0], [0.0], [0.0], wrenches=[tip_force(-11.0)], friction=zwang.Friction(),
                      gravity=NO_GRAVITY)
    assert res.state == ["slip-"]
    assert res.mu[0] == -10.0
    assert res.qdd[0] == pytest.approx(-1.0 / I_JOINT, rel=1e-14)  # -0.4444...
    assert round(res.qdd[0], 4) == -0.4444
    assert res.tau_friction[0] == pytest.approx(10.0)
    # g(mu*) = Z + mu* qdd*, and the tip accelerates tangentially (the link points along x at q = 0).
    assert res.gauss_dual == pytest.approx(res.gauss + res.mu[0] * res.qdd[0], rel=1e-14)
    assert res.frame_acceleration("tip", "world") == pytest.approx([0, -1 / I_JOINT, 0, 0, 0, -1 / I_JOINT])


def test_fig_5_5_fully_constrained_vertex(arm):
    ws = arm.workspace()
    hold = zwang.Constraint("link1", [0, 0, 0, 0, 0, 1], b=[5.0], expressed="local")
    res = zwang.solve(arm, ws, [0.0], [0.0], [0.0], constraints=[hold],
                      friction=zwang.Friction(velocity_tolerance=1e-9), gravity=NO_GRAVITY)
    assert res.state == ["slip+"]
    assert res.mu[0] == 10.0
    assert res.qdd[0] == pytest.approx(5.0, rel=1e-14)
    assert res.tau_control[0] == pytest.approx(I_JOINT * 5 + 10, rel=1e-14)  # 21.25
    assert res.nu[0] == pytest.approx(21.25, rel=1e-14)
    assert res.rank == 1 and not res.singular


def test_scenario_sweep_g_is_concave_and_maximal_at_mu_star(arm):
    """The report's sampling of g(mu) (eq. 5.9) by the plain solver with tau = -mu: its best sample is mu*."""
    ws = arm.workspace()
    load = tip_force(-5.0)
    mus = np.linspace(-10, 10, 201)
    g = []
    for mu in mus:
        res = zwang.solve(arm, ws, [0.0], [0.0], [-mu], wrenches=[load], gravity=NO_GRAVITY)
        g.append(res.gauss)
    assert mus[int(np.argmax(g))] == pytest.approx(-5.0)
    assert np.all(np.diff(g, 2) < 0)  # concave


def test_plain_solver_closed_forms(arm):
    ws = arm.workspace()
    res = zwang.solve(arm, ws, [0.3], [0.0], [3.0], gravity=NO_GRAVITY)
    assert res.qdd[0] == pytest.approx(3.0 / I_JOINT, rel=1e-14)
    assert res.gauss == pytest.approx(-9.0 / (2 * I_JOINT), rel=1e-13)
    heavy = arm.with_rotor_inertia([0.75])
    assert heavy.rotor_inertia[0] == 0.75 and arm.rotor_inertia[0] == 0.0
    res = zwang.solve(heavy, heavy.workspace(), [0.3], [0.0], [3.0], gravity=NO_GRAVITY)
    assert res.qdd[0] == pytest.approx(3.0 / (I_JOINT + 0.75), rel=1e-14)


def test_classical_accelerations(arm):
    """Constraints and frame accelerations are classical (centripetal term included)."""
    ws = arm.workspace()
    c = zwang.Constraint("tip", [0, 1, 0, 0, 0, 0], b=[2.0])
    omega = 3.0
    res = zwang.solve(arm, ws, [0.4], [omega], [0.0], constraints=[c], gravity=NO_GRAVITY)
    assert res.qdd[0] == pytest.approx(2.0, rel=1e-14)
    a = res.frame_acceleration("tip", "local")
    assert a[0] == pytest.approx(-omega ** 2, rel=1e-13) and a[1] == pytest.approx(2.0, rel=1e-13)


def test_closure_property_on_panda(panda):
    """The unconstrained arm driven by tau_control accelerates with exactly the constrained qdd."""
    ws = panda.workspace()
    rng = np.random.default_rng(7)
    q, qd, tau = rng.uniform(-1, 1, 7), rng.uniform(-1, 1, 7), rng.uniform(-5, 5, 7)
    c = zwang.Constraint("tool0", np.eye(6)[:, :3], b=[0.1, -0.2, 0.3], expressed="world")
    w = zwang.Wrench("panda_link5", [1, -2, 3, 0.1, 0.2, -0.3])
    res = zwang.solve(panda, ws, q, qd, tau, constraints=[c], wrenches=[w]).copy()
    free = zwang.solve(panda, ws, q, qd, res.tau_control, wrenches=[w])
    np.testing.assert_allclose(free.qdd, res.qdd, rtol=0, atol=1e-10)
    # RNEA at that qdd gives tau_control back; the tool meets its set points.
    tau_id = zwang.inverse_dynamics(panda, ws, q, qd, res.qdd, wrenches=[w])
    np.testing.assert_allclose(tau_id, res.tau_control, rtol=0, atol=1e-9)
    # forward_dynamics is that unconstrained solve, by its name.
    qdd_fd = zwang.forward_dynamics(panda, ws, q, qd, res.tau_control, wrenches=[w])
    np.testing.assert_allclose(qdd_fd, res.qdd, rtol=0, atol=1e-10)
    np.testing.assert_allclose(res.frame_acceleration("tool0", "world")[:3], [0.1, -0.2, 0.3], atol=1e-10)


def test_panda_hold_pose_friction_carries_the_load(panda):
    """Holding still is statically indeterminate; the effort-minimising mu* lowers |tau|^2.

    docs/friction.md, "When mu* is not unique"."""
    ws = panda.workspace()
    hold = zwang.Constraint("tool0", np.eye(6), expressed="world")
    plain = zwang.solve(panda, ws, READY, constraints=[hold]).copy()
    fric = zwang.solve(panda, ws, READY, constraints=[hold], friction=zwang.Friction())
    assert fric.indeterminate and fric.state == ["stick"] * 7
    np.testing.assert_allclose(fric.qdd, 0, atol=1e-12)
    assert np.all(np.abs(fric.mu) <= panda.breakaway_friction + 1e-12)
    assert np.sum(fric.tau_control ** 2) < np.sum(plain.tau_control ** 2) - 1.0
    # A smaller margin uses less of the friction: more effort, never more than without friction.
    half = zwang.solve(panda, ws, READY, constraints=[hold], friction=zwang.Friction(margin=0.5))
    effort_half = np.sum(half.tau_control ** 2)
    assert np.all(np.abs(half.mu) <= 0.5 * panda.breakaway_friction + 1e-9)
    assert effort_half <= np.sum(plain.tau_control ** 2) + 1e-9


def test_forward_dynamics_against_crba_and_rnea(panda):
    """forward_dynamics: qdd = H^-1 (tau - C) with H from CRBA and C from RNEA at qdd = 0; gravity and
    wrenches as inverse_dynamics takes them; constraints belong to solve()."""
    ws = panda.workspace()
    rng = np.random.default_rng(11)
    for _ in range(20):
        q, qd, tau = rng.uniform(-1, 1, 7), rng.uniform(-1, 1, 7), rng.uniform(-5, 5, 7)
        gravity = rng.uniform(-10, 10, 3)
        w = zwang.Wrench("panda_link4", rng.uniform(-2, 2, 6))
        qdd = zwang.forward_dynamics(panda, ws, q, qd, tau, wrenches=[w], gravity=gravity)
        H = zwang.joint_space_inertia(panda, ws, q)
        C = zwang.inverse_dynamics(panda, ws, q, qd, wrenches=[w], gravity=gravity)
        np.testing.assert_allclose(qdd, np.linalg.solve(H, tau - C), rtol=1e-9, atol=1e-9)
    # Defaults: at rest, no torque, default gravity: the arm falls as the plain solve says.
    np.testing.assert_array_equal(zwang.forward_dynamics(panda, ws, READY), zwang.solve(panda, ws, READY).qdd)


def test_pendulum_rnea_crba_kinematics(panda):
    ws = panda.workspace()
    q = np.array(READY)
    H = zwang.joint_space_inertia(panda, ws, q)
    np.testing.assert_allclose(H, H.T, atol=1e-14)
    assert np.all(np.linalg.eigvalsh(H) > 0)
    # Gravity torque from RNEA = what a plain solve needs to hold: qdd(tau = g(q)) = 0.
    g = zwang.inverse_dynamics(panda, ws, q)
    res = zwang.solve(panda, ws, q, None, g)
    np.testing.assert_allclose(res.qdd, 0, atol=1e-10)
    # Jacobian against finite differences of the pose.
    J = zwang.frame_jacobian(panda, ws, q, "tool0", "world")
    T0 = zwang.frame_pose(panda, ws, q, "tool0")
    h = 1e-7
    for j in range(7):
        dq = q.copy()
        dq[j] += h
        T1 = zwang.frame_pose(panda, ws, dq, "tool0")
        np.testing.assert_allclose((T1[:3, 3] - T0[:3, 3]) / h, J[:3, j], atol=1e-5)
    qd = np.linspace(-0.5, 0.5, 7)
    np.testing.assert_allclose(zwang.frame_velocity(panda, ws, q, qd, "tool0", "world"), J @ qd, atol=1e-12)
    assert math.isclose(T0[3, 3], 1.0)


def test_unreachable_row_least_squares_reported(arm):
    """The 1-DOF arm at rest, its tip asked for 2 m/s² along the link (out of
    reach) and 0.5 m/s² across it: the across row is met, the along row is the
    least-squares residual with no force along it, and the result says so."""
    ws = arm.workspace()
    A = np.zeros((6, 2))
    A[0, 0] = A[1, 1] = 1.0
    c = zwang.Constraint("tip", A, b=[2.0, 0.5], expressed="local")
    res = zwang.solve(arm, ws, [0.0], [0.0], [0.0], constraints=[c], gravity=[0, 0, 0],
                      balance=zwang.Balance(singular_threshold=1e-5))
    assert res.qdd[0] == pytest.approx(0.5, rel=1e-12)
    assert abs(res.nu[0]) < 1e-12
    assert res.singular and res.rank == 1
    assert not res.consistent
    assert res.residual == pytest.approx(2.0, rel=1e-12)
    held = zwang.solve(arm, ws, [0.0], [0.0], [0.0], constraints=[zwang.Constraint("tip", A[:, 1:], b=[0.5])],
                       gravity=[0, 0, 0])
    assert held.consistent and held.residual < 1e-12
