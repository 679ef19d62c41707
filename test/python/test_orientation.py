"""The orientation helpers and the placement on a plane from Python (docs/python.md, "Orientation helpers"):
quaternion orders, rotation log/exp against Rodrigues' formula written here, near 0 and near π, the orientation
error's defining property, and Solo 12's feet placed on the ground (heights checked by frame_pose)."""
import numpy as np
import pytest

import zwang
from conftest import MODELS


def rodrigues(phi):
    """exp([φ]×) by Rodrigues' formula (independent of the module)."""
    theta = np.linalg.norm(phi)
    if theta == 0:
        return np.eye(3)
    k = phi / theta
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K


def test_quaternion_orders():
    wxyz = np.array([0.5, 0.1, -0.7, 0.3])
    np.testing.assert_array_equal(zwang.quaternion_xyzw_from_wxyz(wxyz), [0.1, -0.7, 0.3, 0.5])
    np.testing.assert_array_equal(zwang.quaternion_wxyz_from_xyzw([0.1, -0.7, 0.3, 0.5]), wxyz)
    with pytest.raises(ValueError):
        zwang.quaternion_wxyz_from_xyzw([1, 0, 0])


@pytest.mark.parametrize("theta", [0.0, 1e-12, 1e-7, 0.3, 2.0, np.pi - 1e-7, np.pi - 1e-12, np.pi])
def test_log_and_exp_near_0_and_pi(theta):
    rng = np.random.default_rng(int(theta * 1e6) % 1000)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    phi = theta * axis
    R = rodrigues(phi)
    # Rodrigues' matrix is exact to rounding (1e-16 per entry); the log keeps that: 1e-14 absolute on φ. At exactly
    # π the axis' sign is free.
    log = zwang.rotation_log(R)
    assert min(np.abs(log - phi).max(), np.abs(log + phi).max() if theta > 3 else 1) < 1e-14
    np.testing.assert_allclose(zwang.rotation_exp(phi), R, atol=1e-14)
    q = zwang.quaternion_exp(phi)
    assert abs(np.linalg.norm(q) - 1) < 1e-15
    back = zwang.quaternion_log(q)
    assert min(np.abs(back - phi).max(), np.abs(back + phi).max() if theta > 3 else 1) < 1e-14


def test_orientation_error():
    rng = np.random.default_rng(5)
    for _ in range(20):
        current, desired = rodrigues(rng.normal(size=3)), rodrigues(rng.normal(size=3))
        e = zwang.orientation_error(current, desired)
        np.testing.assert_allclose(rodrigues(e) @ current, desired, atol=1e-14)  # products of rotations: rounding


def test_place_solo_on_the_ground():
    model = zwang.load_urdf(MODELS / "solo12.urdf", base="free")
    ws = model.workspace()
    feet = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
    tilt = zwang.quaternion_exp([0.2, -0.1, 0.4])
    q = np.r_[0.3, -0.2, 1.0, tilt, [0, 0.8, -1.6, 0, 0.8, -1.6, 0, -0.8, 1.6, 0, -0.8, 1.6]]
    lowest, d_low = zwang.place_on_plane(model, q, feet, 0.05)
    z = [zwang.frame_pose(model, ws, lowest, f)[2, 3] for f in feet]
    assert min(z) == pytest.approx(0.05, abs=1e-12)  # a rigid motion of a 1 m robot: rounding
    assert d_low == pytest.approx(max(z) - 0.05, abs=1e-12)
    level, d_all = zwang.place_on_plane(model, q, feet, 0.05, all=True)
    z = [zwang.frame_pose(model, ws, level, f)[2, 3] for f in feet]
    np.testing.assert_allclose(z, 0.05, atol=1e-12)  # the standing posture's feet are coplanar
    assert d_all < 1e-12
    with pytest.raises(zwang.SolveError):
        zwang.place_on_plane(zwang.load_urdf(MODELS / "solo12.urdf"), np.zeros(12), feet)


def test_against_scipy():
    """SciPy's Rotation (x y z w quaternions) agrees through the conversions."""
    Rotation = pytest.importorskip("scipy.spatial.transform").Rotation
    rng = np.random.default_rng(9)
    for _ in range(20):
        phi = rng.normal(size=3)
        phi *= min(1.0, 3.0 / np.linalg.norm(phi))  # |φ| < π: one rotation vector
        r = Rotation.from_rotvec(phi)
        wxyz = zwang.quaternion_wxyz_from_xyzw(r.as_quat())
        np.testing.assert_allclose(zwang.quaternion_log(wxyz), phi, atol=1e-14)
        np.testing.assert_allclose(zwang.rotation_exp(phi), r.as_matrix(), atol=1e-14)
        xyzw = zwang.quaternion_xyzw_from_wxyz(zwang.quaternion_exp(phi))
        np.testing.assert_allclose(Rotation.from_quat(xyzw).as_rotvec(), phi, atol=1e-14)
