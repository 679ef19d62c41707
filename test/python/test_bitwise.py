"""Random problems solved from Python and by the C++ command-line tool (`zwang solve`, JSON out):
every number must be the same double. The CLI writes the shortest decimal that reads back as
the same double (docs/cli.md), so exact equality is a bit-for-bit comparison.

The CLI makes a Workspace sized exactly for the task, so the Python side does the same
(zwang.Workspace(model, max_constraint_rows=rows)); test_reused_workspace checks a shared one.
"""
import json
import os
import pathlib
import subprocess
import warnings

import numpy as np
import pytest

import zwang
from conftest import ARM, BAXTER, PANDA

CLI = os.environ.get("ZWANG_CLI")
pytestmark = pytest.mark.skipif(not CLI or not pathlib.Path(CLI).exists(),
                                reason="needs the zwang CLI (ZWANG_CLI, set by ctest when ZWANG_BUILD_CLI is on)")

N_PANDA = 60
N_ARM = 20
FRAMES = ["panda_link1", "panda_link2", "panda_link3", "panda_link4", "panda_link5", "panda_link6",
          "panda_link7", "panda_link8", "tool0"]


def random_problem(rng, seed, panda=True):
    """A JSON problem (docs/cli.md) with random state, constraints, wrenches and friction."""
    n = 7 if panda else 1
    p = {"model": str(PANDA if panda else ARM)}
    if panda:
        p.update(root="panda_link0", tip="tool0")
    p["gravity"] = rng.uniform(-10, 10, 3).tolist() if rng.random() < 0.5 else [0.0, 0.0, -9.81]
    p["q"] = rng.uniform(-2.5, 2.5, n).tolist()
    qd = rng.uniform(-1, 1, n)
    qd[rng.random(n) < 0.6] = 0.0  # stuck joints
    p["qd"] = qd.tolist()
    p["tau"] = rng.uniform(-20, 20, n).tolist()
    if rng.random() < 0.3:
        p["rotor_inertia"] = rng.uniform(0, 0.2, n).tolist()
    frames = FRAMES if panda else ["link1", "tip"]
    constraints = []
    for _ in range(rng.integers(0, 3)):
        m = int(rng.integers(1, 4))
        constraints.append({"frame": str(rng.choice(frames)),
                            "expressed_in": str(rng.choice(["local", "world", "aligned"])),
                            "directions": rng.normal(size=(m, 6)).tolist(),
                            "acceleration": rng.normal(size=m).tolist()})
    p["constraints"] = constraints
    p["wrenches"] = [{"frame": str(rng.choice(frames)), "expressed_in": str(rng.choice(["local", "world"])),
                      "force": rng.normal(0, 5, 3).tolist(), "torque": rng.normal(0, 1, 3).tolist()}
                     for _ in range(rng.integers(0, 3))]
    if rng.random() < 0.7:
        p["friction"] = {"velocity_tolerance": 1e-6, "margin": float(rng.choice([1.0, 0.8, rng.random()])),
                         "limits": bool(rng.random() < 0.8)}
        if rng.random() < 0.3:
            p["breakaway"] = rng.uniform(0, 5, n).tolist()
    return p


N_TREE = 20
BAXTER_FRAMES = ["left_gripper", "right_gripper", "left_lower_elbow", "right_wrist", "head", "torso",
                 "l_gripper_l_finger", "r_gripper_r_finger_tip"]


def random_tree_problem(rng):
    """A random problem on the Baxter tree (mimic fingers locked), constraints relative to another frame or not."""
    n = 17
    p = {"model": str(BAXTER), "lock_mimic": True, "gravity": [0.0, 0.0, -9.81]}
    p["q"] = rng.uniform(-1.0, 1.0, n).tolist()
    qd = rng.uniform(-1, 1, n)
    qd[rng.random(n) < 0.6] = 0.0
    p["qd"] = qd.tolist()
    p["tau"] = rng.uniform(-10, 10, n).tolist()
    constraints = []
    for _ in range(rng.integers(1, 4)):
        m = int(rng.integers(1, 4))
        frame, reference = (str(f) for f in rng.choice(BAXTER_FRAMES, 2, replace=False))
        c = {"frame": frame, "directions": rng.normal(size=(m, 6)).tolist(), "acceleration": rng.normal(size=m).tolist()}
        if rng.random() < 0.6:
            c["relative_to"] = reference
            c["expressed_in"] = str(rng.choice(["local", "world", "reference"]))
        else:
            c["expressed_in"] = str(rng.choice(["local", "world", "aligned"]))
        constraints.append(c)
    p["constraints"] = constraints
    p["wrenches"] = [{"frame": str(rng.choice(BAXTER_FRAMES)), "expressed_in": str(rng.choice(["local", "world"])),
                      "force": rng.normal(0, 5, 3).tolist(), "torque": rng.normal(0, 1, 3).tolist()}
                     for _ in range(rng.integers(0, 3))]
    if rng.random() < 0.5:
        p["friction"] = {"velocity_tolerance": 1e-6, "margin": 1.0, "limits": False}
        p["breakaway"] = rng.uniform(0, 3, n).tolist()
    return p


def cli_solve(problem, path):
    path.write_text(json.dumps(problem))
    out = subprocess.run([CLI, "solve", str(path)], capture_output=True, text=True)
    assert out.returncode in (0, 3), out.stderr
    return json.loads(out.stdout)


def python_solve(problem, model=None, ws=None):
    """The same problem through the Python API; returns (result copy, infeasible, frame accelerations)."""
    if model is None:
        model = zwang.load_urdf(problem["model"], root=problem.get("root", ""), tip=problem.get("tip", ""),
                                lock_mimic=problem.get("lock_mimic", False))
    if "rotor_inertia" in problem:
        model = model.with_rotor_inertia(problem["rotor_inertia"])
    constraints = [zwang.Constraint(c["frame"], np.array(c["directions"]).T, b=c["acceleration"],
                                    expressed=c["expressed_in"], relative_to=c.get("relative_to"))
                   for c in problem["constraints"]]
    wrenches = [zwang.Wrench(w["frame"], force=w["force"], torque=w["torque"], expressed=w["expressed_in"])
                for w in problem["wrenches"]]
    friction = None
    if "friction" in problem:
        f = problem["friction"]
        friction = zwang.Friction(margin=f["margin"], velocity_tolerance=f["velocity_tolerance"],
                                  joint_limits=f["limits"], breakaway=problem.get("breakaway"))
    rows = sum(len(c["directions"]) for c in problem["constraints"])
    if ws is None:
        ws = zwang.Workspace(model, max_constraint_rows=rows)  # as the CLI: sized for the task
    try:
        res = zwang.solve(model, ws, np.array(problem["q"]), np.array(problem["qd"]), np.array(problem["tau"]),
                          constraints=constraints, wrenches=wrenches, friction=friction,
                          gravity=problem["gravity"])
        infeasible = False
    except zwang.InfeasibleError as e:
        res, infeasible = e.result, True
    frames = []  # as the CLI reports them: constrained (and reference) frames, then loaded ones
    for item in problem["constraints"] + problem["wrenches"]:
        for name in [item["frame"], item.get("relative_to")]:
            if name is not None and name not in frames:
                frames.append(name)
    accelerations = {f: res.frame_acceleration(f, "world").tolist() for f in frames}
    return res.copy(), infeasible, accelerations


def same(python_values, cli_values, what):
    a = np.asarray(python_values, dtype=float)
    b = np.asarray(cli_values, dtype=float)
    assert a.shape == b.shape, what
    diff = np.flatnonzero(a != b)
    assert diff.size == 0, f"{what}: differs at {diff.tolist()}: python {a[diff].tolist()} vs C++ {b[diff].tolist()}"


def compare(problem, cli, res, infeasible, accelerations):
    same(res.qdd, cli["qdd"], "qdd")
    same(res.tau_constraint, cli["tau_constraint"], "tau_constraint")
    same(res.tau_control, cli["tau_control"], "tau_control")
    same(res.nu, cli["nu"], "nu")
    assert res.gauss == cli["gauss"]
    assert res.singular == cli["status"]["singular"] and res.rank == cli["status"]["rank"]
    assert res.rows == cli["status"]["rows"] and res.nu_unique == cli["status"]["nu_unique"]
    assert infeasible == cli["status"]["infeasible"]
    assert ("friction" in cli) == res.with_friction
    if res.with_friction:
        f = cli["friction"]
        same(res.mu, f["mu"], "mu")
        assert res.state == f["state"]
        assert res.indeterminate == f["indeterminate"] and res.iterations == f["iterations"]
        assert res.kkt_residual == f["kkt_residual"]
    assert set(accelerations) == set(cli["frames"])
    for name, acc in accelerations.items():
        same(acc, cli["frames"][name]["acceleration_world"], f"frames.{name}")


@pytest.mark.parametrize("seed", range(N_PANDA))
def test_panda_random_bit_for_bit(seed, scratch):
    rng = np.random.default_rng(1000 + seed)
    problem = random_problem(rng, seed, panda=True)
    cli = cli_solve(problem, scratch / "problem.json")
    compare(problem, cli, *python_solve(problem))


@pytest.mark.parametrize("seed", range(N_ARM))
def test_arm_random_bit_for_bit(seed, scratch):
    rng = np.random.default_rng(5000 + seed)
    problem = random_problem(rng, seed, panda=False)
    cli = cli_solve(problem, scratch / "problem.json")
    compare(problem, cli, *python_solve(problem))


@pytest.mark.parametrize("seed", range(N_TREE))
def test_tree_random_bit_for_bit(seed, scratch):
    rng = np.random.default_rng(9000 + seed)
    problem = random_tree_problem(rng)
    cli = cli_solve(problem, scratch / "problem.json")
    with pytest.warns(zwang.ModelWarning):  # Baxter's placeholder inertias and the locked mimic joints
        compare(problem, cli, *python_solve(problem))


def test_reference_problem_files_bit_for_bit():
    """The CLI's golden problems (the report's scenarios, Fig. 5.5, Panda) through both paths."""
    problems = pathlib.Path(__file__).resolve().parents[1] / "cli" / "problems"
    checked = 0
    for name in ["arm_stick.json", "arm_slip.json", "arm_fig55.json", "panda_hold.json", "panda_everything.json",
                 "tree_two_arms.json", "relative_hands.json", "baxter_hold_box.json"]:
        file = problems / name
        if not file.exists():
            continue
        raw = json.loads("\n".join(line.split("//")[0] for line in file.read_text().splitlines()))
        out = subprocess.run([CLI, "solve", str(file)], capture_output=True, text=True)
        assert out.returncode in (0, 3), out.stderr
        cli = json.loads(out.stdout)
        problem = {"model": str((file.parent / raw["model"]).resolve()), "root": raw.get("root", ""),
                   "tip": raw.get("tip", ""), "gravity": raw.get("gravity", [0.0, 0.0, -9.81])}
        problem["lock_mimic"] = raw.get("lock_mimic", False)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", zwang.ModelWarning)
            model = zwang.load_urdf(problem["model"], root=problem["root"], tip=problem["tip"],
                                    lock_mimic=problem["lock_mimic"])
        n = model.dof
        problem.update(q=raw.get("q", [0.0] * n), qd=raw.get("qd", [0.0] * n), tau=raw.get("tau", [0.0] * n))
        if "rotor_inertia" in raw:
            problem["rotor_inertia"] = raw["rotor_inertia"]
        if "breakaway" in raw:
            problem["breakaway"] = raw["breakaway"]
        problem["constraints"] = [{"expressed_in": "reference" if "relative_to" in c else "local",
                                   "acceleration": [0.0] * len(c["directions"]), **c}
                                  for c in raw.get("constraints", [])]
        problem["wrenches"] = [{"expressed_in": "local", "force": [0, 0, 0], "torque": [0, 0, 0], **w}
                               for w in raw.get("wrenches", [])]
        if "friction" in raw and raw["friction"].get("enabled", True):
            f = raw["friction"]
            problem["friction"] = {"margin": f.get("margin", 1.0), "velocity_tolerance": f.get("velocity_tolerance", 1e-6),
                                   "limits": f.get("limits", True)}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", zwang.ModelWarning)
            compare(problem, cli, *python_solve(problem))
        checked += 1
    assert checked >= 6


def test_reused_workspace(scratch):
    """One workspace for every problem (grown as needed, tasks rebuilt): same values as the CLI.
    Bit-for-bit is not promised here (a workspace with more constraint capacity can change
    Eigen's summation order); measured here: 20/20 bit-for-bit."""
    rng = np.random.default_rng(99)
    model = zwang.load_urdf(PANDA, root="panda_link0", tip="tool0")
    ws = model.workspace(max_constraint_rows=9)
    exact = 0
    for seed in range(20):
        problem = random_problem(rng, seed)
        problem.pop("rotor_inertia", None)
        cli = cli_solve(problem, scratch / "problem.json")
        res, infeasible, _ = python_solve(problem, model=model, ws=ws)
        assert infeasible == cli["status"]["infeasible"]
        scale = 1.0 + np.max(np.abs(cli["qdd"]))
        np.testing.assert_allclose(res.qdd, cli["qdd"], rtol=1e-12, atol=1e-12 * scale)
        np.testing.assert_allclose(res.tau_control, cli["tau_control"], rtol=1e-12, atol=1e-10)
        exact += bool(np.all(res.qdd == np.asarray(cli["qdd"])))
    print(f"reused workspace: {exact}/20 problems bit-for-bit")
