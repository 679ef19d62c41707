"""Doubtful URDF data: zwang.ModelWarning per finding, Model.warnings, strict=True refuses;
attach_beyond_tip; q outside the limits at solve time."""
import warnings

import numpy as np
import pytest

import zwang

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
