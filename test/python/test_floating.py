"""Floating bases from Python (docs/python.md, "Floating base"): load_urdf(..., base=...), the model's
base_type, nq, nv and base_plane, solve() with q of nq entries and qd, tau of nv (the base's coordinates
first), res.base_acceleration_world; a URDF's floating or planar root joint; the errors; and the same
doubles as the command-line tool's "base" problems."""
import json
import os
import pathlib
import subprocess
import warnings

import numpy as np
import pytest

import zwang
from conftest import MODELS, ROOT

SOLO = MODELS / "solo12.urdf"
HUMANOID = MODELS / "simple_humanoid.urdf"
CART = ROOT / "test" / "cli" / "problems" / "planar_cart.urdf"  # a planar root joint, plane = the world's x-z
STAND = [0, 0.8, -1.6, 0, 0.8, -1.6, 0, -0.8, 1.6, 0, -0.8, 1.6]  # solo12's joints, standing
G = np.array([0.0, 0.0, -9.81])


def solo_q(position=(0, 0, 0.3), orientation=(1, 0, 0, 0), joints=STAND):
    return np.r_[position, orientation, joints].astype(float)


@pytest.mark.parametrize("path, dof", [(SOLO, 12), (HUMANOID, 29)])
def test_each_base_type(path, dof):
    for base, nq, nv in [("fixed", dof, dof), ("free", dof + 7, dof + 6), ("planar", dof + 3, dof + 3)]:
        model = zwang.load_urdf(path, base=base)
        assert (model.base_type, model.dof, model.nq, model.nv) == (base, dof, nq, nv)
        assert (model.base_plane is None) == (base != "planar")
    assert zwang.load_urdf(path).base_type == "fixed"  # the default adds no base
    free = zwang.load_urdf(path, base="free")
    assert f"free base, nq={dof + 7}, nv={dof + 6}" in repr(free)
    np.testing.assert_array_equal(zwang.load_urdf(path, base="planar").base_plane, np.eye(4))


def test_base_mass_is_the_root_link_and_what_is_welded_to_it():
    assert zwang.load_urdf(SOLO, base="free").base_mass == 1.16115091  # base_link's own <inertial>
    assert zwang.load_urdf(SOLO).base_mass == 1.16115091  # counted on a fixed base too (not in its dynamics)
    assert zwang.load_urdf(HUMANOID, base="free").base_mass == 27.0  # BODY, welded to the massless base_link


def test_free_fall_at_rest():
    model = zwang.load_urdf(SOLO, base="free")
    ws = model.workspace()
    res = zwang.solve(model, ws, solo_q(orientation=(np.cos(0.2), 0.0, np.sin(0.2), 0.0)))  # qd, tau: zeros (nv)
    assert res.qdd.shape == (18,)
    np.testing.assert_allclose(res.base_acceleration_world, np.r_[G, 0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(res.qdd[6:], 0.0, atol=1e-12)
    for frame in model.frame_names:
        np.testing.assert_allclose(res.frame_acceleration(frame), np.r_[G, 0, 0, 0], atol=1e-12)
    # res.qdd[:6] is the derivative of the velocity coordinates as given: [v̇; ω̇] in base axes, R^T g at rest.
    R = np.array([[np.cos(0.4), 0, np.sin(0.4)], [0, 1, 0], [-np.sin(0.4), 0, np.cos(0.4)]])  # 0.4 rad about y
    np.testing.assert_allclose(res.qdd[:3], R.T @ G, atol=1e-12)
    kept = res.copy()
    zwang.solve(model, ws, solo_q())
    with pytest.raises(zwang.StaleResultError):
        res.base_acceleration_world
    np.testing.assert_allclose(kept.base_acceleration_world, np.r_[G, 0, 0, 0], atol=1e-12)
    # A fixed base reports zeros.
    arm = zwang.load_urdf(MODELS / "one_dof_arm.urdf")
    np.testing.assert_array_equal(zwang.solve(arm, arm.workspace(), [0.3]).base_acceleration_world, np.zeros(6))


def test_floating_root_joint_equals_the_base_option():
    text = SOLO.read_text()
    at = text.index(">", text.index("<robot")) + 1
    joint = ('<link name="world"/><joint name="root_joint" type="floating"><parent link="world"/>'
             '<child link="base_link"/><origin xyz="1 2 3" rpy="0.1 0.2 0.3"/></joint>')
    from_file = zwang.load_urdf_string(text[:at] + joint + text[at:])
    option = zwang.load_urdf(SOLO, base="free")
    assert from_file.base_type == "free" and from_file.frame_names == option.frame_names
    rng = np.random.default_rng(5)
    for _ in range(10):
        quaternion = rng.normal(size=4)
        q = solo_q(rng.uniform(-1, 1, 3), quaternion / np.linalg.norm(quaternion), rng.uniform(-1, 1, 12))
        qd, tau = rng.uniform(-1, 1, 18), rng.uniform(-1, 1, 18)
        a = zwang.solve(option, option.workspace(), q, qd, tau).qdd.copy()
        b = zwang.solve(from_file, from_file.workspace(), q, qd, tau).qdd
        np.testing.assert_array_equal(a, b)
    with pytest.raises(zwang.ModelError, match=r"already has a floating root joint 'root_joint' \(from 'world' to "
                                               r"'base_link'\), a free base; drop base='free'"):
        zwang.load_urdf_string(text[:at] + joint + text[at:], base="free")


def test_planar_root_joint_with_friction():
    model = zwang.load_urdf(CART)
    assert (model.base_type, model.nq, model.nv) == ("planar", 4, 4)
    np.testing.assert_allclose(model.base_plane[:3, 3], [0, 0, 1])
    np.testing.assert_allclose(model.base_plane[:3, 2], [0, -1, 0], atol=1e-15)  # the normal: the world's -y
    # As test/cli/problems/planar_cart.json: held at its height, the pole sticks.
    held = zwang.Constraint("cart", [0, 0, 1, 0, 0, 0], expressed="world")
    res = zwang.solve(model, model.workspace(), [0.2, 0.0, 0.3, 0.4], [0.1, 0, 0, 0], constraints=[held],
                      friction=True)
    assert res.state == ["stick"] and abs(res.mu[0]) <= 0.5
    assert res.mu.shape == (1,) and res.tau_control.shape == (4,)
    assert abs(res.frame_acceleration("cart")[2]) < 1e-12
    np.testing.assert_allclose(res.base_acceleration_world[[0, 2, 4]], res.qdd[:3] * [1, 1, -1], atol=1e-12)


def test_errors():
    model = zwang.load_urdf(SOLO, base="free")
    ws = model.workspace()
    with pytest.raises(zwang.SolveError, match=r"q has 12 entries, the model has nq = 19 \(7 base coordinates \+ 12 "
                                               r"joints\)") as error:
        zwang.solve(model, ws, STAND)
    assert error.value.code == "SizeMismatch"
    with pytest.raises(zwang.SolveError, match="qd has 12 entries"):
        zwang.solve(model, ws, solo_q(), qd=np.zeros(12))
    with pytest.raises(zwang.SolveError, match=r"base quaternion \(entries 3-6, w x y z\) has norm 2") as error:
        zwang.solve(model, ws, solo_q(orientation=(2, 0, 0, 0)))
    assert error.value.code == "BadConfiguration"
    with pytest.raises(ValueError, match="base: unknown value 'flying' \\(expected 'fixed', 'free' or 'planar'\\)"):
        zwang.load_urdf(SOLO, base="flying")
    with pytest.raises(zwang.ModelError, match="already has a planar root joint 'rail'.*drop base='planar'"):
        zwang.load_urdf(CART, base="planar")
    with pytest.raises(ValueError, match="q needs nq = 19 entries and qd nv = 18"):
        model.follow_leaders(STAND, np.zeros(12))
    q, qd = model.follow_leaders(solo_q(), np.zeros(18))
    assert q.shape == (19,) and qd.shape == (18,)
    # A joint outside its limits is named with its index in the full q.
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        zwang.solve(model, ws, solo_q(joints=[0, 11] + STAND[2:]))
    assert any("q[8] = 11 puts joint 'FL_HFE' outside its limits [-10, 10]" in str(w.message) for w in caught)


CLI = os.environ.get("ZWANG_CLI")


@pytest.mark.skipif(not CLI or not pathlib.Path(CLI).exists(), reason="needs the zwang CLI (ZWANG_CLI)")
@pytest.mark.parametrize("name", ["solo_feet.json", "planar_cart.json"])
def test_same_doubles_as_the_cli(name):
    path = ROOT / "test" / "cli" / "problems" / name
    out = json.loads(subprocess.run([CLI, "solve", str(path)], check=True, capture_output=True, text=True).stdout)
    p = json.loads("\n".join(line for line in path.read_text().splitlines() if not line.startswith("//")))
    b = p["base"]
    if b["type"] == "free":
        model = zwang.load_urdf((path.parent / p["model"]).resolve(), base="free")
        q = np.r_[b["position"], b["orientation"], p["q"]]
        qd = np.r_[b["linear_velocity"], b["angular_velocity"], np.zeros(model.dof)]
    else:
        model = zwang.load_urdf(path.parent / p["model"])
        q = np.r_[b["position"], b["yaw"], p["q"]]
        qd = np.r_[b["velocity"], np.zeros(model.dof)]
    constraints = [zwang.Constraint(c["frame"], np.array(c["directions"]).T, expressed=c["expressed_in"])
                   for c in p["constraints"]]
    rows = sum(len(c["directions"]) for c in p["constraints"])
    res = zwang.solve(model, zwang.Workspace(model, rows), q, qd, constraints=constraints,
                      friction=True if "friction" in p else None)
    k = model.nv - model.dof
    assert res.qdd[k:].tolist() == out["qdd"]
    assert res.qdd[:k].tolist() == out["base"]["acceleration"]
    assert res.base_acceleration_world.tolist() == out["base"]["acceleration_world"]
    assert res.tau_constraint[:k].tolist() == out["base"]["tau_constraint"]
    assert res.nu.tolist() == out["nu"]


# ---- configuration helpers (docs/python.md, "Configuration helpers") ------------------------------------------


def quat_about_z(angle):
    return np.array([np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2)])


def test_integrate_closed_forms():
    model = zwang.load_urdf(SOLO, base="free")
    q0 = zwang.neutral_configuration(model)
    # neutral: the base at the origin, identity quaternion, joints at 0 inside solo12's limits (none are given)
    np.testing.assert_array_equal(q0, np.r_[0, 0, 0, 1, 0, 0, 0, np.zeros(12)])
    # a turn about z at 0.7 rad/s for 2 s: the quaternion of 1.4 rad about z, the joints moved by qd·dt
    v = np.r_[0, 0, 0, 0, 0, 0.7, np.linspace(-1, 1, 12)]
    q1 = zwang.integrate(model, q0, v, 2.0)
    np.testing.assert_allclose(q1[3:7], quat_about_z(1.4), atol=1e-15)  # a few roundings of sin, cos
    np.testing.assert_allclose(q1[7:], 2.0 * v[6:], atol=1e-15)
    np.testing.assert_allclose(q1[:3], 0.0, atol=1e-15)
    # a straight line in base axes from a base turned by 0.5 rad about z: p = R v dt
    start = np.r_[1, 2, 3, quat_about_z(0.5), np.zeros(12)]
    q2 = zwang.integrate(model, start, np.r_[1.0, 0, 0, np.zeros(15)], 0.25)
    np.testing.assert_allclose(q2[:3], [1 + 0.25 * np.cos(0.5), 2 + 0.25 * np.sin(0.5), 3], atol=1e-15)
    # the default dt is 1, and difference undoes integrate
    rng = np.random.default_rng(3)
    for seed in range(20):
        qa, _ = zwang.random_configuration(model, seed)
        v = rng.normal(size=model.nv)
        qb = zwang.integrate(model, qa, v)
        assert abs(np.linalg.norm(qb[3:7]) - 1) < 1e-15  # renormalised: within an ulp or two of unit
        # the log of a rotation of |ω| < π: unique, so the round trip is exact up to rounding (angles ~3 rad)
        if np.linalg.norm(v[3:6]) < 3.0:
            np.testing.assert_allclose(zwang.difference(model, qa, qb), v, atol=1e-12)


def test_random_configuration_is_reproducible_and_chains():
    model = zwang.load_urdf(HUMANOID, base="free")
    qa, state = zwang.random_configuration(model, 12345)
    qb, _ = zwang.random_configuration(model, 12345)
    np.testing.assert_array_equal(qa, qb)
    qc, _ = zwang.random_configuration(model, state)
    assert np.abs(qc - qa).max() > 0.1  # the next draw from the advanced state is another configuration
    assert abs(np.linalg.norm(qa[3:7]) - 1) < 1e-15
    lower, upper = model.lower, model.upper
    assert np.all(qa[7:] >= lower) and np.all(qa[7:] <= upper)
    planar = zwang.load_urdf(SOLO, base="planar")
    qp, _ = zwang.random_configuration(planar, 1)
    assert qp.shape == (15,) and np.all(np.abs(qp[:2]) <= 1) and abs(qp[2]) <= np.pi


def test_configuration_errors():
    model = zwang.load_urdf(SOLO, base="free")
    q = zwang.neutral_configuration(model)
    with pytest.raises(zwang.SolveError) as e:
        zwang.check_configuration(model, q[7:])
    assert e.value.code == "SizeMismatch"
    bad = q.copy()
    bad[4] = np.nan
    with pytest.raises(zwang.SolveError) as e:
        zwang.integrate(model, bad, np.zeros(18))
    assert e.value.code == "NonFinite"
    bad = q.copy()
    bad[3] = 1.1
    with pytest.raises(zwang.SolveError, match="norm 1.1") as e:
        zwang.check_configuration(model, bad)
    assert e.value.code == "BadConfiguration"
    np.testing.assert_allclose(zwang.normalize_configuration(model, bad), q, atol=0)  # (1.1, 0, 0, 0) → (1, 0, 0, 0)
    bad[3] = 0.0
    with pytest.raises(zwang.SolveError) as e:
        zwang.normalize_configuration(model, bad)
    assert e.value.code == "BadConfiguration"
    with pytest.raises(zwang.SolveError) as e:
        zwang.difference(model, q, np.zeros(18))
    assert e.value.code == "SizeMismatch"
    assert zwang.check_configuration(model, q) is None
    # The published tolerance is the one the check applies: a quaternion norm off by half of it passes, twice it
    # is refused (the norm is scaled along w, the only non-zero component of the neutral quaternion).
    tolerance = zwang.QUATERNION_NORM_TOLERANCE
    inside, outside = q.copy(), q.copy()
    inside[3] = 1 + 0.5 * tolerance
    outside[3] = 1 + 2 * tolerance
    assert zwang.check_configuration(model, inside) is None
    with pytest.raises(zwang.SolveError) as e:
        zwang.check_configuration(model, outside)
    assert e.value.code == "BadConfiguration"


# ---- contacts and joint rows --------------------------------------------------------------------------------

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")


def test_standing_on_contacts_with_joint_rows():
    """Solo 12 on four point contacts, every joint held by a joint row: nothing moves, the motors' torques are
    the joint torques of RNEA with the contact forces applied (an independent route), the base needs none."""
    model = zwang.load_urdf(SOLO, base="free")
    q = solo_q(position=(0.1, -0.2, 0.3), orientation=(np.cos(0.15), 0, 0, np.sin(0.15)))
    feet = [zwang.Constraint(f, np.eye(6)[:, :3], expressed="world", contact=True) for f in FEET]
    hold = [zwang.Constraint.on_joint(name) for name in model.joint_names]
    assert (feet[0].contact, feet[0].joint, hold[0].joint, hold[0].A, hold[0].rows) == (True, None, "FL_HAA", None, 1)
    assert repr(hold[0]) == "<zwang.Constraint on joint 'FL_HAA', 1 row>"
    ws = model.workspace(24)
    res = zwang.solve(model, ws, q, constraints=feet + hold)
    # 24 rows on nv = 18: dependent but consistent (each fixes q̈ = 0); the balance keeps 18 and meets all.
    # The ground's split between the feet is open (nu not unique): statically indeterminate, not a failure.
    assert (res.rows, res.rank, res.singular, res.nu_unique, res.consistent) == (24, 18, True, False, True)
    np.testing.assert_allclose(res.qdd, 0.0, atol=1e-10)  # 24 rows of size ~10 m/s², solved to ~1e-12
    ground = res.nu[:12].reshape(4, 3)  # world-axis forces on the feet
    assert abs(ground[:, 2].sum() - model.mass * 9.81 - model.base_mass * 9.81) < 1e-9  # they carry the weight
    push = [zwang.Wrench(f, force=ground[k], expressed="world") for k, f in enumerate(FEET)]
    rnea = zwang.inverse_dynamics(model, model.workspace(), q, wrenches=push)
    np.testing.assert_allclose(res.tau_control, rnea, atol=1e-9)  # RNEA's base entries are ~0 too
    np.testing.assert_allclose(res.tau_control[:6], 0.0, atol=1e-9)
    np.testing.assert_allclose(res.tau_control[6:], res.nu[12:], atol=1e-12)  # the joint rows' ν: motor torques
    np.testing.assert_allclose(res.tau_constraint, np.r_[np.zeros(6), res.nu[12:]], atol=1e-12)
    # the same feet as ordinary constraints: their force is then the motors', so τ_control includes it
    plain_feet = [zwang.Constraint(f, np.eye(6)[:, :3], expressed="world") for f in FEET]
    mixed = zwang.solve(model, model.workspace(24), q, constraints=plain_feet + hold)
    np.testing.assert_allclose(mixed.nu, res.nu, atol=1e-9)
    assert np.abs(mixed.tau_control[:6]).max() > 1.0  # the ground force now counts as the base's "motor"
    # One foot asked to rise: with every joint held the robot is one rigid body at rest, and three feet
    # that do not accelerate fix it, so no motion meets the fourth's row. The same rows and rank, but the
    # rank lost now leaves rows unmet.
    rise = zwang.Constraint("FL_FOOT", np.eye(6)[:, :3], b=[0.0, 0.0, 0.5], expressed="world", contact=True)
    apart = zwang.solve(model, model.workspace(24), q, constraints=[rise] + feet[1:] + hold)
    assert (apart.rows, apart.rank, apart.nu_unique, apart.consistent) == (24, 18, False, False)


def test_contact_and_joint_row_errors():
    model = zwang.load_urdf(SOLO, base="free")
    with pytest.raises(zwang.ModelError, match=r"constraints\[0\].*'nope'"):
        zwang.solve(model, model.workspace(), solo_q(), constraints=[zwang.Constraint.on_joint("nope")])
    with pytest.raises(ValueError, match="contact: is true with 'relative_to'"):
        zwang.Constraint("FL_FOOT", np.eye(6), relative_to="FR_FOOT", contact=True)
