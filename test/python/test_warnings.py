"""Doubtful URDF data: zwang.ModelWarning per finding, Model.warnings, strict=True refuses;
attach_beyond_tip; q outside the limits at solve time, warned once per model and joint (Result.warnings has
every occurrence); contacts on a fixed base with mass."""
import warnings

import numpy as np
import pytest

import zwang
from conftest import MODELS

ARM = """<robot name="doubtful"><link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit {limit}/></joint>
  <link name="l1"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia {inertia}/></inertial></link>{extra}</robot>"""
POINT_MASS = 'ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"'
BOX = 'ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"'
PLACEHOLDER_LIMITS = 'lower="0" upper="0" effort="0" velocity="0"'
LIMITS = 'lower="-1" upper="1" effort="5" velocity="2"'
FINGER = """<joint name="finger_joint" type="prismatic"><parent link="l1"/><child link="finger"/>
    <origin xyz="1 0 0"/><axis xyz="0 1 0"/><limit lower="0" upper="0.1" effort="5" velocity="1"/></joint>
  <link name="finger"><inertial><mass value="0.5"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>"""


def arm(inertia=BOX, limit=LIMITS, extra=""):
    return ARM.format(inertia=inertia, limit=limit, extra=extra)


def test_model_warning_is_a_user_warning():
    assert issubclass(zwang.ModelWarning, UserWarning)


def test_each_warning_issued_once_and_listed():
    with pytest.warns(zwang.ModelWarning) as record:
        model = zwang.load_urdf_string(arm(POINT_MASS, PLACEHOLDER_LIMITS))
    messages = [str(w.message) for w in record if issubclass(w.category, zwang.ModelWarning)]
    assert len(messages) == 2
    assert any("link 'l1': a point mass" in m for m in messages)
    assert any("joint 'j1': placeholder <limit" in m for m in messages)
    assert [code for code, _ in model.warnings] == ["point_mass", "placeholder_limits"]
    assert model.joints[0].lower == -np.inf and model.joints[0].upper == np.inf


def test_clean_data_warns_nothing():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = zwang.load_urdf_string(arm())
    assert model.warnings == []
    assert model.base_mass == 0.0 and model.mass == 2.0


def test_strict_refuses():
    with pytest.raises(zwang.ModelError, match=r"refused in strict mode \(1 warning\): link 'l1': a point mass"):
        zwang.load_urdf_string(arm(POINT_MASS), strict=True)


def test_warnings_as_errors_through_the_filter():
    with warnings.catch_warnings():
        warnings.simplefilter("error", zwang.ModelWarning)
        with pytest.raises(zwang.ModelWarning):
            zwang.load_urdf_string(arm(POINT_MASS))


def test_mass_beyond_the_tip_and_the_payload():
    xml = arm(extra=FINGER)
    with pytest.warns(zwang.ModelWarning, match=r"'finger', 0.5 kg in all.*set attach_beyond_tip=True"):
        ignored = zwang.load_urdf_string(xml, tip="l1")
    assert ignored.mass == 2.0
    with pytest.warns(zwang.ModelWarning, match="welded to the tip body as a payload"):
        payload = zwang.load_urdf_string(xml, tip="l1", attach_beyond_tip=True)
    assert payload.dof == 1 and payload.mass == pytest.approx(2.5)
    assert payload.has_frame("finger")


def test_q_outside_the_limits_warns_at_solve_time():
    model = zwang.load_urdf_string(arm())
    ws = model.workspace()
    with pytest.warns(zwang.ModelWarning, match=r"q\[0\] = 1.5 puts joint 'j1' outside its limits \[-1, 1\]"):
        zwang.solve(model, ws, np.array([1.5]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        zwang.solve(model, ws, np.array([0.5]))


def model_warnings(record):
    return [str(w.message) for w in record if issubclass(w.category, zwang.ModelWarning)]


def test_a_repeated_condition_warns_once_with_its_first_value():
    # q drifting outside the limits for 200 control cycles: one ModelWarning, even with the
    # "always" filter (the dedupe is zwang's, per model and joint); Result.warnings has every one.
    model = zwang.load_urdf_string(arm())
    ws = model.workspace()
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        for k in range(200):
            q = 1.5 + 0.001 * k
            res = zwang.solve(model, ws, np.array([q]))
            assert res.warnings == [("outside_limits", f"q[0] = {q:g} puts joint 'j1' outside its limits [-1, 1]")]
        inside = zwang.solve(model, ws, np.array([0.5]))
        assert inside.warnings == []
    issued = model_warnings(record)
    assert len(issued) == 1
    assert issued[0].startswith("q[0] = 1.5 puts joint 'j1' outside its limits [-1, 1]")
    assert "Result.warnings" in issued[0]
    # Another joint, another model: each warned once in its turn.
    two = zwang.load_urdf_string(arm(extra=FINGER))
    ws2 = two.workspace()
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        for _ in range(3):
            zwang.solve(two, ws2, np.array([1.5, 0.0]))
            zwang.solve(two, ws2, np.array([1.5, 0.2]))
        zwang.solve(model, ws, np.array([2.0]))  # the first model's joint: said already
    issued = model_warnings(record)
    assert len(issued) == 2
    assert issued[0].startswith("q[0] = 1.5 puts joint 'j1'")
    assert issued[1].startswith("q[1] = 0.2 puts joint 'finger_joint'")


def test_every_occurrence_is_in_result_warnings_and_its_copy():
    model = zwang.load_urdf_string(arm(extra=FINGER))
    ws = model.workspace()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = zwang.solve(model, ws, np.array([-2.0, 0.5]))
    expected = [("outside_limits", "q[0] = -2 puts joint 'j1' outside its limits [-1, 1]"),
                ("outside_limits", "q[1] = 0.5 puts joint 'finger_joint' outside its limits [0, 0.1]")]
    assert res.warnings == expected
    kept = res.copy()
    zwang.solve(model, ws, np.array([0.0, 0.0]))
    assert kept.warnings == expected


def test_contacts_on_a_bolted_down_humanoid_warn_once_naming_the_free_base():
    humanoid = zwang.load_urdf(MODELS / "simple_humanoid.urdf")  # no root joint: a fixed base (BODY, 27 kg)
    assert humanoid.base_type == "fixed" and humanoid.base_mass == 27.0
    feet = [zwang.Constraint(foot, np.eye(6), expressed="world", contact=True) for foot in ("l_ankle", "r_ankle")]
    q = np.zeros(humanoid.nq)
    q[[16, 23]] = 0.1  # shoulder rolls inside their limits (>= 0.0087)
    ws = humanoid.workspace(12)
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        for _ in range(3):
            res = zwang.solve(humanoid, ws, q, constraints=feet)
    issued = model_warnings(record)
    assert len(issued) == 1
    assert issued[0].startswith("contact on frame 'l_ankle' of a fixed-base model whose base carries 27 kg")
    assert 'Python base="free"' in issued[0]
    assert [code for code, _ in res.warnings] == ["fixed_base_contact"]
    free = zwang.load_urdf(MODELS / "simple_humanoid.urdf", base="free")
    qf = np.r_[0, 0, 1, 1, 0, 0, 0, q]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = zwang.solve(free, free.workspace(12), qf, constraints=feet)
    assert res.warnings == []


def test_a_joint_driven_into_its_limit_warns_and_effort_beyond_the_limit_is_listed():
    # j1 at its upper limit (1) turning into it: a stop would need an impulse (reported, not modelled).
    # tau = 8 N·m is beyond the URDF's effort = 5.
    model = zwang.load_urdf_string(arm())
    ws = model.workspace()
    with pytest.warns(zwang.ModelWarning, match=r"joint 'j1' moves into its limit: stopping it needs an impulse"):
        res = zwang.solve(model, ws, np.array([1.0]), np.array([0.5]), np.array([8.0]), friction=zwang.Friction())
    assert res.limit_impact and res.impact_joint == 0
    assert ("limit_impact", "joint 'j1' moves into its limit: stopping it needs an impulse, which the solve does "
            "not model (friction.limit_impact)") in res.warnings
    assert res.effort_exceeded == ["j1"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        away = zwang.solve(model, ws, np.array([1.0]), np.array([-0.5]), np.array([1.0]), friction=zwang.Friction())
    assert not away.limit_impact and away.effort_exceeded == []
