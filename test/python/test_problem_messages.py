"""The problem layer's messages through the Python module: each row of test/problem/bad_inputs.json
(the table the CLI's test and the layer's own test read too) as zwang.solve's arguments."""
import json

import numpy as np
import pytest

import zwang
from conftest import ROOT

TABLE = json.loads((ROOT / "test" / "problem" / "bad_inputs.json").read_text(encoding="utf-8"))


def same_quotes(text):
    """JSON quotes with ", Python with '."""
    return text.replace('"', "'")


def constraint(c):
    if "joint" in c:
        return zwang.Constraint.on_joint(c["joint"])
    relative = {"relative_to": c["relative_to"]} if "relative_to" in c else {}
    return zwang.Constraint(c["frame"], np.array(c["directions"], dtype=float).T, expressed=c.get("expressed_in"),
                            contact=c.get("contact", False), **relative)


def solve_row(panda, ws, row):
    """The row's input as zwang.solve's arguments: what fails, fails while they are made or in the solve."""
    kwargs = {}
    if "constraint" in row:
        kwargs["constraints"] = [constraint(row["constraint"])]
    if "wrench" in row:
        w = row["wrench"]
        kwargs["wrenches"] = [zwang.Wrench(w["frame"], expressed=w.get("expressed_in", "local"))]
    if "balance" in row:
        kwargs["balance"] = zwang.Balance(**row["balance"])
    if "friction" in row or "breakaway" in row:
        breakaway = {"breakaway": row["breakaway"]} if "breakaway" in row else {}
        kwargs["friction"] = zwang.Friction(**row.get("friction", {}), **breakaway)
    if "joint_modes" in row:
        kwargs["modes"] = row["joint_modes"]
    if "rotor_inertia" in row:
        panda = panda.with_rotor_inertia(row["rotor_inertia"])
        ws = panda.workspace()
    zwang.solve(panda, ws, np.zeros(panda.nq), **kwargs)


def check_raised(row, call):
    error = zwang.ModelError if row["kind"] == "model" else ValueError
    with pytest.raises(error) as e:
        call()
    assert isinstance(e.value, zwang.ModelError) == (row["kind"] == "model")  # a ModelError is a ValueError too
    assert same_quotes(row["expect"]) in same_quotes(str(e.value))


def test_the_table_has_rows():
    assert len(TABLE["rows"]) >= 10


@pytest.mark.parametrize("row", TABLE["rows"], ids=[row["name"] for row in TABLE["rows"]])
def test_shared_bad_input(panda, row):
    check_raised(row, lambda: solve_row(panda, panda.workspace(), row))


BREAKAWAY_ROWS = [row for row in TABLE["rows"] if "breakaway" in row]


@pytest.mark.parametrize("row", BREAKAWAY_ROWS, ids=[row["name"] for row in BREAKAWAY_ROWS])
def test_shared_bad_breakaway_as_the_models_friction(panda, row):
    """Model.with_friction takes the same per-joint array as Friction(breakaway=...), with the same words."""
    check_raised(row, lambda: panda.with_friction(row["breakaway"]))
