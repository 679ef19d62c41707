"""Cost of one zwang.solve() call from Python against the same C++ solve looped in C++.

The Panda (models/panda.urdf) in its ready pose, at rest. Three calls:
  plain       zwang.solve(model, ws, q, qd, tau)                     (no constraint, no friction)
  hold        ... constraints=[tool0 held, 6 rows]                   (the plain solver)
  hold+fric   ... constraints=[...], friction=zwang.Friction(margin=0.8)
The C++ time is zwang._time_cpp_solve (the same Task and Workspace, the C++ call in a C++
loop); the Python time is timeit of the call with float64 NumPy arrays. Best of 7 runs each.

    PYTHONPATH=build/python python3 docs/python/overhead.py [--number N]
"""
import argparse
import pathlib
import timeit

import numpy as np

import zwang

MODEL = pathlib.Path(__file__).resolve().parents[2] / "models" / "panda.urdf"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--number", type=int, default=20000, help="calls per run")
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()

    model = zwang.load_urdf(MODEL, root="panda_link0", tip="tool0")
    ws = model.workspace()
    q = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
    qd, tau = np.zeros(7), np.zeros(7)
    hold = [zwang.Constraint("tool0", np.eye(6), expressed="world")]
    friction = zwang.Friction(margin=0.8)
    cases = {"plain": dict(), "hold": dict(constraints=hold), "hold+fric": dict(constraints=hold, friction=friction)}

    print(f"{'call':10} {'C++ [us]':>9} {'Python [us]':>12} {'overhead [us]':>14} {'+ read qdd [us]':>16}")
    for name, kw in cases.items():
        cpp = min(zwang._time_cpp_solve(model, ws, q, qd, tau, repeat=args.number, **kw) for _ in range(args.repeat))
        call = lambda: zwang.solve(model, ws, q, qd, tau, **kw)
        read = lambda: zwang.solve(model, ws, q, qd, tau, **kw).qdd
        py = min(timeit.repeat(call, number=args.number, repeat=args.repeat)) / args.number
        py_read = min(timeit.repeat(read, number=args.number, repeat=args.repeat)) / args.number
        print(f"{name:10} {cpp * 1e6:9.2f} {py * 1e6:12.2f} {(py - cpp) * 1e6:14.2f} {(py_read - cpp) * 1e6:16.2f}")
    lists = [list(q), list(qd), list(tau)]
    py = min(timeit.repeat(lambda: zwang.solve(model, ws, *lists), number=args.number, repeat=args.repeat))
    print(f"plain with Python lists instead of arrays: {py / args.number * 1e6:.2f} us per call")


if __name__ == "__main__":
    main()
