"""Centre of mass and centroidal momentum from Python (docs/python.md, "Centre of mass"): zwang.subtree_mass,
center_of_mass, center_of_mass_velocity, jacobian_center_of_mass, centroidal_momentum and Result.com, against
closed forms on a two-link planar arm built here (every number below is worked out by hand from the link lengths,
masses and angles), and the physics of a free-floating Solo 12 (its centre of mass falls with g)."""
import numpy as np
import pytest

import zwang
from conftest import MODELS

# Link lengths [m] and masses [kg] of the arm below; each link's centre of mass at its middle.
L1, L2, M1, M2 = 0.7, 0.5, 2.0, 1.5


def two_link_arm():
    """Two revolute joints about z, the second at the end of the first link (x = L1)."""
    b = zwang.ModelBuilder("two_link", "base")
    b.add_joint("shoulder", "revolute", "upper", mass=M1, com=[L1 / 2, 0, 0], inertia=0.01 * np.eye(3))
    elbow = np.eye(4)
    elbow[0, 3] = L1
    b.add_joint("elbow", "revolute", "fore", parent="upper", placement=elbow, mass=M2, com=[L2 / 2, 0, 0],
                inertia=0.01 * np.eye(3))
    return b.build()


def closed_form(q, qd):
    """The arm's centre of mass, its Jacobian and velocity, by hand."""
    a, b = q[0], q[0] + q[1]
    c1 = np.array([L1 / 2 * np.cos(a), L1 / 2 * np.sin(a), 0])
    c2 = np.array([L1 * np.cos(a) + L2 / 2 * np.cos(b), L1 * np.sin(a) + L2 / 2 * np.sin(b), 0])
    J1 = np.array([[-L1 / 2 * np.sin(a), 0], [L1 / 2 * np.cos(a), 0], [0, 0]])
    J2 = np.array([[-L1 * np.sin(a) - L2 / 2 * np.sin(b), -L2 / 2 * np.sin(b)],
                   [L1 * np.cos(a) + L2 / 2 * np.cos(b), L2 / 2 * np.cos(b)], [0, 0]])
    M = M1 + M2
    c = (M1 * c1 + M2 * c2) / M
    J = (M1 * J1 + M2 * J2) / M
    return c, J, J @ qd, c2, J2 @ qd


def test_two_link_arm_against_closed_forms():
    model = two_link_arm()
    ws = model.workspace()
    q, qd = np.array([0.4, -1.1]), np.array([0.8, 1.3])
    c, J, cd, c2, cd2 = closed_form(q, qd)
    # Sums of a few products of sines and cosines: round-off near 1e-16 of sizes near 1.
    assert zwang.subtree_mass(model) == pytest.approx(M1 + M2, abs=1e-15)
    assert zwang.subtree_mass(model, "elbow") == pytest.approx(M2, abs=1e-15)
    np.testing.assert_allclose(zwang.center_of_mass(model, ws, q), c, atol=1e-14)
    np.testing.assert_allclose(zwang.center_of_mass(model, ws, q, "elbow"), c2, atol=1e-14)
    np.testing.assert_allclose(zwang.center_of_mass(model, ws, q, 1), c2, atol=1e-14)  # by index
    np.testing.assert_allclose(zwang.jacobian_center_of_mass(model, ws, q), J, atol=1e-14)
    np.testing.assert_allclose(zwang.center_of_mass_velocity(model, ws, q, qd), cd, atol=1e-14)
    np.testing.assert_allclose(zwang.center_of_mass_velocity(model, ws, q, qd, "elbow"), cd2, atol=1e-14)
    # Linear momentum M ċ; the angular part about c is Σ I ω + m (c_i − c) × ċ_i: its z alone is non-zero.
    h = zwang.centroidal_momentum(model, ws, q, qd)
    np.testing.assert_allclose(h[:3], (M1 + M2) * cd, atol=1e-14)
    np.testing.assert_allclose(h[3:5], 0, atol=1e-14)


def test_result_com_acceleration_by_differences():
    """Result.com['acceleration'] against central differences of the closed-form velocity along the solve's motion:
    ε = 1e-6, error ε² ~ 1e-12 and rounding 1e-16/ε ~ 1e-10 (sizes ~1), so 1e-8."""
    model = two_link_arm()
    ws = model.workspace()
    q, qd, tau = np.array([0.4, -1.1]), np.array([0.8, 1.3]), np.array([3.0, -1.0])
    res = zwang.solve(model, ws, q, qd, tau)
    com = res.com
    qdd = res.qdd.copy()
    c, _, cd, _, _ = closed_form(q, qd)
    np.testing.assert_allclose(com["position"], c, atol=1e-14)
    np.testing.assert_allclose(com["velocity"], cd, atol=1e-14)
    eps = 1e-6
    plus = closed_form(q + eps * qd, qd + eps * qdd)[2]
    minus = closed_form(q - eps * qd, qd - eps * qdd)[2]
    np.testing.assert_allclose(com["acceleration"], (plus - minus) / (2 * eps), atol=1e-8)
    kept = res.copy()
    zwang.solve(model, ws, q, qd, -tau)  # the copy keeps its com
    np.testing.assert_array_equal(kept.com["acceleration"], com["acceleration"])


def test_free_floating_solo_falls_with_g():
    model = zwang.load_urdf(MODELS / "solo12.urdf", base="free")
    ws = model.workspace()
    rng = np.random.default_rng(27)
    q = np.r_[0, 0, 0.3, 1, 0, 0, 0, rng.uniform(-1, 1, 12)]
    qd = rng.uniform(-1, 1, model.nv)
    tau = np.r_[np.zeros(6), rng.uniform(-2, 2, 12)]
    res = zwang.solve(model, ws, q, qd, tau)
    # Joint torques are internal: c̈ = g exactly (the solve's round-off, sizes ~10).
    np.testing.assert_allclose(res.com["acceleration"], [0, 0, -9.81], atol=1e-12)
    assert zwang.subtree_mass(model) == pytest.approx(model.mass + model.base_mass, rel=1e-15)


def test_errors():
    model = two_link_arm()
    ws = model.workspace()
    with pytest.raises(zwang.ModelError, match="joint index 5 is out of range"):
        zwang.center_of_mass(model, ws, [0, 0], 5)
    with pytest.raises(zwang.ModelError):
        zwang.center_of_mass(model, ws, [0, 0], "no_such_joint")
    with pytest.raises(TypeError):
        zwang.center_of_mass(model, ws, [0, 0], 1.5)
    with pytest.raises(zwang.SolveError):
        zwang.center_of_mass(model, ws, [0, 0, 0])
