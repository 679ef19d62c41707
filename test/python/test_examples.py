"""The examples of docs/python/ run (Agg backend, figures into a scratch directory) and
check their own results (the reference values of docs/theory.md, the effort saving)."""
import os
import pathlib
import subprocess
import sys

import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "docs" / "python"


@pytest.mark.parametrize("script, args, output", [
    ("scenarios.py", [], "scenarios.png"),
    ("panda_hold.py", [], "panda_hold.png"),
    ("overhead.py", ["--number", "200", "--repeat", "1"], None),
])
def test_example_runs(script, args, output, tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    out_args = ["--out", str(tmp_path)] if output else []
    run = subprocess.run([sys.executable, str(EXAMPLES / script), *out_args, *args], capture_output=True,
                         text=True, env=env, timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    if output:
        png = tmp_path / output
        assert png.exists() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert (EXAMPLES / output).exists(), f"the committed figure docs/python/{output} is missing"
