#!/usr/bin/env python3
"""The library's layers (docs/architecture.md): an internal header may be
included only from its own folder or from a layer above it, and a public
header names no internal header or namespace. Exits 1 naming every include
that points the wrong way."""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
# folder -> the folders whose internal headers it may include
allowed = {
    "linalg": {"linalg"},
    "qp": {"linalg", "qp"},
    "model": {"model"},
    "dynamics": {"linalg", "model", "dynamics"},  # model/task_layout.hpp: the task's constraints as the solver reads them
    "friction": {"linalg", "qp", "model", "dynamics", "friction"},
    # Motion over time: the library's public API only (solveWithFriction, integrate, …).
    "simulation": {"simulation"},
    # The MJCF loader (zwang_mujoco, optional): above the model layer through its public API and
    # model/loader_messages.hpp, the messages it spells as the URDF loader does.
    "mujoco": {"mujoco", "model"},
    # The front ends' problem layer: above the library (which never includes it), below the front ends.
    "problem": {"problem", "model"},  # model/urdf_option_names.hpp: the front ends' spelling of the URDF options
    "cli": {"problem"},
    "python": {"problem"},
}
include = re.compile(r'#include\s+"(\w+)/[\w.]+\.hpp"')
bad = []
for folder, may in allowed.items():
    for path in sorted((root / "src" / folder).glob("*.[ch]pp")):
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            m = include.search(line)
            if m and m.group(1) != "zwang" and m.group(1) not in may:
                bad.append(f"{path.relative_to(root)}:{number}: {folder} includes {m.group(1)}/ ({line.strip()})")
# Public headers hold the public API only: no internal header, and no internal namespace.
internal_name = re.compile(r"\b(internal|detail)::|namespace\s+(internal|detail)\b")
for path in sorted((root / "include").rglob("*.hpp")):
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        m = include.search(line)
        if m and m.group(1) != "zwang":
            bad.append(f"{path.relative_to(root)}:{number}: a public header includes {m.group(1)}/")
        if internal_name.search(line):
            bad.append(f"{path.relative_to(root)}:{number}: a public header names an internal namespace")
print("\n".join(bad) if bad else f"layers: every include points one way ({', '.join(allowed)})")
sys.exit(1 if bad else 0)
