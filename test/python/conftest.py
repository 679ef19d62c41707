"""Shared fixtures of the Python tests (run by ctest with PYTHONPATH=<build>/python)."""
import os
import pathlib

import pytest

import zwang

ROOT = pathlib.Path(__file__).resolve().parents[2]
MODELS = pathlib.Path(os.environ.get("ZWANG_MODELS_DIR", ROOT / "models"))
PANDA = MODELS / "panda.urdf"
ARM = MODELS / "one_dof_arm.urdf"
BAXTER = MODELS / "baxter.urdf"  # a dual-arm tree with mimic fingers (load with lock_mimic=True)
TWO_ARMS = ROOT / "test" / "cli" / "problems" / "two_arms.urdf"  # a small tree: waist, two 2-joint arms
READY = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]  # the Panda ready pose of test/cli/problems/panda_hold.json


@pytest.fixture(scope="session")
def arm():
    return zwang.load_urdf(ARM)


@pytest.fixture(scope="session")
def panda():
    return zwang.load_urdf(PANDA, root="panda_link0", tip="tool0")


@pytest.fixture
def scratch(tmp_path):
    return tmp_path
