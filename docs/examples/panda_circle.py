"""docs/controller.md: panda_circle.cpp in Python, the same controller and numbers.

The Panda's tool draws a circle at 1 kHz: a PD law on the tool's position and
pointing direction sets the task's true accelerations, joint 7 is prescribed
(the solver returns its torque), a posture torque acts in the null space,
solve(..., friction=...) finds the motion and the motor torques, and
semi-implicit Euler integrates it.

    PYTHONPATH=build/python python3 docs/examples/panda_circle.py [--duration S] [--csv PATH] [--max-error M]
"""
import argparse
import math
import os
import sys
import tempfile
import time

import numpy as np
import zwang


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="models/panda.urdf")
    parser.add_argument("--csv", default=os.path.join(tempfile.gettempdir(), "panda_circle_py.csv"))
    parser.add_argument("--duration", type=float, default=4.0)
    parser.add_argument("--max-error", type=float, default=math.inf,
                        help="exit 1 when the position error after 0.2 s exceeds it [m]")
    args = parser.parse_args()

    model = zwang.load_urdf(args.model)
    ws, ws_gravity = model.workspace(), model.workspace()  # g(q) must not replace the state ws holds
    dt = 1e-3

    # Rows on the tool: position (3 rows, world axes) and the direction of its
    # z axis (angular x and y, the tool's own axes); the spin about it is free,
    # so 7 joints - 1 prescribed - 5 rows leave one DOF for the posture.
    a_pos = np.zeros((6, 3))
    a_pos[:3, :3] = np.eye(3)
    a_dir = np.zeros((6, 2))
    a_dir[3, 0] = a_dir[4, 1] = 1.0
    pos = zwang.Constraint("tool0", a_pos, expressed="world")
    direction = zwang.Constraint("tool0", a_dir, expressed="local")
    friction = zwang.Friction()  # the URDF's <dynamics friction damping>

    q = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
    qd = np.zeros(7)
    q_rest = q.copy()
    lower, upper = model.lower, model.upper

    start_pose = zwang.frame_pose(model, ws, q, "tool0")
    center = start_pose[:3, 3] + np.array([0.0, 0.05, 0.0])
    r_desired = start_pose[:3, :3]
    r, w, ramp, a7, w7, q7_0 = 0.05, 2 * math.pi * 0.5, 0.5, 0.2, 2 * math.pi * 0.25, q[6]
    kp, kd, kp7, kd7, k_rest, d_rest = 400.0, 40.0, 900.0, 60.0, 20.0, 5.0

    steps = round(args.duration / dt)
    max_error = max_dir_error = effort_sum = 0.0
    cycle_us = []
    violations = 0
    with open(args.csv, "w") as csv:
        csv.write("t,position_error,direction_error,effort\n")
        for k in range(steps):
            t = k * dt
            t0 = time.perf_counter()
            pose = zwang.frame_pose(model, ws, q, "tool0")
            v = zwang.frame_velocity(model, ws, q, qd, "tool0", expressed="world")  # [v; w], world axes
            g = zwang.inverse_dynamics(model, ws_gravity, q, np.zeros(7), np.zeros(7))
            rot = pose[:3, :3]

            # Set point + feedback = the rows' true accelerations (the solver adds J-dot q-dot).
            # The phase speeds up smoothly to w over the first `ramp` seconds.
            x = min(t / ramp, 1.0)
            th = w * ramp * (x**3 - 0.5 * x**4) if t < ramp else w * (t - 0.5 * ramp)
            thd, thdd = w * x * x * (3 - 2 * x), w / ramp * 6 * x * (1 - x)
            radial = np.array([0.0, -math.cos(th), math.sin(th)])
            tangent = np.array([0.0, math.sin(th), math.cos(th)])
            p_d, v_d = center + r * radial, r * thd * tangent
            a_d = r * thdd * tangent - r * thd * thd * radial
            e_p = p_d - pose[:3, 3]
            e_o = zwang.orientation_error(rot, r_desired)  # world axes
            pos.b = a_d + kp * e_p + kd * (v_d - v[:3])
            direction.b = (rot.T @ (kp * e_o - kd * v[3:]))[:2]

            q7_d = q7_0 + a7 * (1 - math.cos(w7 * t))
            qd7_d = a7 * w7 * math.sin(w7 * t)
            qdd7 = a7 * w7 * w7 * math.cos(w7 * t) + kp7 * (q7_d - q[6]) + kd7 * (qd7_d - qd[6])
            tau = g - d_rest * qd - k_rest * (q - q_rest)  # acts in the null space

            res = zwang.solve(model, ws, q, qd, tau, constraints=[pos, direction], friction=friction,
                              modes={"panda_joint7": qdd7})
            cycle_us.append((time.perf_counter() - t0) * 1e6)

            dir_error = float(np.linalg.norm((rot.T @ e_o)[:2]))
            effort = float(res.tau_control @ res.tau_control)
            csv.write(f"{t:.3f},{np.linalg.norm(e_p):.6e},{dir_error:.6e},{effort:.6e}\n")
            if t >= 0.2:
                max_error = max(max_error, float(np.linalg.norm(e_p)))
                max_dir_error = max(max_dir_error, dir_error)
            effort_sum += effort

            qd = qd + res.qdd * dt  # semi-implicit Euler
            q = zwang.integrate(model, q, qd, dt)
            violations += int(np.sum((q < lower) | (q > upper)))

    print(f"{steps} cycles at 1 kHz ({steps * dt:.1f} s); data in {args.csv}")
    print(f"max tracking error after 0.2 s: position {max_error:.3e} m, tool axis {max_dir_error:.3e} rad")
    print(f"RMS effort |tau_control|: {math.sqrt(effort_sum / steps):.2f} N m")
    print(f"whole cycle in Python: mean {np.mean(cycle_us):.1f} us, max {np.max(cycle_us):.1f} us")
    print(f"joint samples outside their limits: {violations}")
    if violations or max_error > args.max_error:
        print("FAILED a bound", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
