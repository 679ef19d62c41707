"""MJCF models through zwang.load_mjcf (docs/mujoco.md): the report's 1-DOF arm as MJCF gives the seed table, the
same model as the URDF arm; the Menagerie Panda loads with its unmapped parts named; bad input is a ModelError.
Without MuJoCo in the build, load_mjcf says so."""
import numpy as np
import pytest

import zwang
from conftest import ARM, MODELS

ARM_MJCF = MODELS / "one_dof_arm.xml"
PANDA_MJCF = MODELS / "mjcf" / "franka_emika_panda__panda.xml"
NO_GRAVITY = [0.0, 0.0, 0.0]


def has_mujoco():
    try:
        zwang.load_mjcf(ARM_MJCF)
    except zwang.ModelError as e:
        assert "MJCF needs zwang built with MuJoCo" in str(e)
        return False
    return True


pytestmark = pytest.mark.skipif(not has_mujoco(), reason="zwang built without MuJoCo")


def tip_force(fy):
    return zwang.Wrench("tip", force=[0.0, fy, 0.0], expressed="world")


def test_arm_is_the_urdf_arm():
    arm, urdf = zwang.load_mjcf(ARM_MJCF), zwang.load_urdf(ARM)
    assert arm.joint_names == urdf.joint_names == ["joint1"]
    assert arm.frame_names == ["world", "link1", "tip"]  # MuJoCo's world body is the URDF's base
    for field in ["lower", "upper", "breakaway_friction", "kinetic_friction", "viscous_friction", "rotor_inertia"]:
        assert list(getattr(arm, field)) == list(getattr(urdf, field)), field
    H = zwang.joint_space_inertia(arm, arm.workspace(), [0.3])
    assert H[0, 0] == pytest.approx(2.25, rel=1e-14)  # 2 at the COM + 1 kg * 0.5 m squared
    model, gravity = zwang.read_mjcf(ARM_MJCF)
    assert model.dof == 1 and list(gravity) == [0.0, 0.0, -9.81]


@pytest.mark.parametrize("force, mu, qdd, state", [(-5.0, -5.0, 0.0, "stick"), (-11.0, -10.0, -1 / 2.25, "slip-")])
def test_seed_table(force, mu, qdd, state):
    arm = zwang.load_mjcf(ARM_MJCF)
    res = zwang.solve(arm, arm.workspace(), [0.0], [0.0], [0.0], wrenches=[tip_force(force)],
                      friction=zwang.Friction(), gravity=NO_GRAVITY)
    assert res.state == [state]
    assert res.mu[0] == pytest.approx(mu, abs=1e-12)
    assert res.qdd[0] == pytest.approx(qdd, abs=1e-12)


def test_panda_warns_of_what_is_not_mapped():
    with pytest.warns(zwang.ModelWarning, match="tendons 'split' are not mapped"):
        panda = zwang.load_mjcf(PANDA_MJCF)
    assert panda.dof == 9
    assert ("unmapped" in [code for code, _ in panda.warnings])
    with pytest.raises(zwang.ModelError, match="refused in strict mode"):
        zwang.load_mjcf(PANDA_MJCF, strict=True)


def test_bad_input():
    with pytest.raises(zwang.ModelError, match="^<string>: MuJoCo refuses the model: .*XML parse error"):
        zwang.load_mjcf_string("<mujoco><worldbody>")
    with pytest.raises(zwang.ModelError, match="cannot open the file"):
        zwang.load_mjcf(MODELS / "no_such_model.xml")
    with pytest.raises(zwang.ModelError, match=r"the root element is <robot>, not <mujoco>"):
        zwang.load_mjcf(ARM)
