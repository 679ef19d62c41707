"""docs/controller.md: humanoid_weight_shift.cpp in Python, the same controller and numbers.

The humanoid, standing on both feet, shifts its weight over its right foot at
1 kHz, plain and friction-aware, and prints the motor effort of both. The feet
are contacts; the right leg's hip and ankle roll are prescribed together (a
parallelogram) with the acceleration a PD law on the centre of mass asks for;
the other leg joints are held by joint rows except the left leg's two roll
joints, which the closed loop through the ground moves; the upper body is
prescribed, held where it started.

    PYTHONPATH=build/python python3 docs/examples/humanoid_weight_shift.py [--duration S] [--check]
"""
import argparse
import math
import sys
import time

import numpy as np
import zwang


def breakaway(joint):
    """Breakaway friction per joint (the URDF has none): docs/evaluation.md, section 4."""
    if "WRIST" in joint:
        return 0.5
    if "SHOULDER" in joint or "ELBOW" in joint:
        return 2.0
    return 5.0


def upright(model, roll):
    """The standing posture of docs/evaluation.md ("upright"), on the ground."""
    q = zwang.neutral_configuration(model)
    values = {"LARM_SHOULDER_R": 0.1, "RARM_SHOULDER_R": 0.1, "LARM_ELBOW": -0.1, "RARM_ELBOW": -0.1,
              "LARM_WRIST_Y": -0.1, "RARM_WRIST_Y": -0.1}
    for leg in ("LLEG_", "RLEG_"):
        values.update({leg + "HIP_P": -0.12, leg + "KNEE": 0.06, leg + "ANKLE_P": 0.06, leg + "HIP_R": roll,
                       leg + "ANKLE_R": -roll})
    for name, value in values.items():
        q[model.joint(name).q_index] = value
    return zwang.place_on_plane(model, q, ["l_ankle", "r_ankle"], 0.0, all=True)[0]


def com_over_foot(model, ws, q, qd=None):
    """The COM's sideways position relative to the right foot (and its velocity with qd)."""
    c = zwang.center_of_mass(model, ws, q)
    foot = zwang.frame_pose(model, ws, q, "r_ankle")[1, 3]
    if qd is None:
        return c[1] - foot
    return c[1] - foot, zwang.center_of_mass_velocity(model, ws, q, qd)[1]


def simulate(model, duration, with_friction):
    ws = model.workspace(max_constraint_rows=24)
    feet = ["l_ankle", "r_ankle"]
    prescribed = [j.name for j in model.joints if "LEG" not in j.name]  # the upper body, off the loop
    free = {"RLEG_HIP_R", "RLEG_ANKLE_R", "LLEG_HIP_R", "LLEG_ANKLE_R"}
    held = [zwang.Constraint.on_joint(j.name) for j in model.joints if "LEG" in j.name and j.name not in free]
    contacts = [zwang.Constraint(f, np.eye(6), expressed="world", contact=True) for f in feet]
    friction = zwang.Friction(breakaway=[breakaway(j.name) for j in model.joints]) if with_friction else None
    joint = {j.name: j for j in model.joints}

    q = upright(model, 0.0)
    eps = 1e-6
    c0 = com_over_foot(model, ws, q)
    gain = (com_over_foot(model, ws, upright(model, eps)) - c0) / eps  # dc_y/dphi of the parallelogram
    q_start = q.copy()
    qd, tau = np.zeros(model.nv), np.zeros(model.nv)
    starts = [zwang.frame_pose(model, ws, q, f) for f in feet]

    dt, shift_time, kp, kd, kp_joint, kd_joint, kp_foot, kd_foot = 1e-3, 1.5, 100.0, 20.0, 400.0, 40.0, 400.0, 40.0
    effort, foot_acc, violations, times = 0.0, 0.0, 0, []
    steps = round(duration / dt)
    for k in range(steps):
        t = k * dt
        s = min(t / shift_time, 1.0)
        c_ref = c0 * (1 - (10 * s**3 - 15 * s**4 + 6 * s**5))  # minimum jerk to over the right foot
        v_ref = -c0 * (30 * s**2 - 60 * s**3 + 30 * s**4) / shift_time if t < shift_time else 0.0
        a_ref = -c0 * (60 * s - 180 * s**2 + 120 * s**3) / shift_time**2 if t < shift_time else 0.0
        c_y, cd_y = com_over_foot(model, ws, q, qd)

        for contact, frame, start in zip(contacts, feet, starts):  # zero, plus a pull back to the start
            pose = zwang.frame_pose(model, ws, q, frame)
            v = zwang.frame_velocity(model, ws, q, qd, frame, expressed="world")
            e = np.concatenate([start[:3, 3] - pose[:3, 3], zwang.orientation_error(pose[:3, :3], start[:3, :3])])
            contact.b = kp_foot * e - kd_foot * v
        for row in held:
            j = joint[row.joint]
            row.b = [kp_joint * (q_start[j.q_index] - q[j.q_index]) - kd_joint * qd[j.v_index]]
        modes = {name: kp_joint * (q_start[joint[name].q_index] - q[joint[name].q_index])
                 - kd_joint * qd[joint[name].v_index] for name in prescribed}
        phi_dd = (a_ref + kp * (c_ref - c_y) + kd * (v_ref - cd_y)) / gain
        modes.update({"RLEG_HIP_R": phi_dd, "RLEG_ANKLE_R": -phi_dd})

        t0 = time.perf_counter()
        res = zwang.solve(model, ws, q, qd, tau, constraints=contacts + held, friction=friction, modes=modes)
        times.append((time.perf_counter() - t0) * 1e6)
        effort += float(res.tau_control @ res.tau_control) * dt
        for contact, frame in zip(contacts, feet):
            foot_acc = max(foot_acc, float(np.max(np.abs(res.frame_acceleration(frame, "world") - contact.b))))

        qd = qd + res.qdd * dt  # semi-implicit Euler
        q = zwang.integrate(model, q, qd, dt)
        violations += sum(1 for j in model.joints if not j.lower <= q[j.q_index] <= j.upper)

    drift = max(float(np.linalg.norm(zwang.frame_pose(model, ws, q, f)[:3, 3] - s0[:3, 3]))
                for f, s0 in zip(feet, starts))
    return dict(effort=effort, com_error=abs(com_over_foot(model, ws, q)), drift=drift, foot_acc=foot_acc,
                violations=violations, mean_us=float(np.mean(times)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="models/simple_humanoid.urdf")
    parser.add_argument("--duration", type=float, default=2.5)
    parser.add_argument("--check", action="store_true",
                        help="exit 1 unless the feet stayed still, the COM reached its target, no joint left its limits")
    args = parser.parse_args()
    model = zwang.load_urdf(args.model, base="free")
    runs = {"plain": simulate(model, args.duration, False), "friction-aware": simulate(model, args.duration, True)}
    for name, r in runs.items():
        print(f"{name:14s}: effort {r['effort']:.1f} N^2 m^2 s, COM {r['com_error']:.2e} m from over the right foot, "
              f"feet moved {r['drift']:.2e} m, contact rows met to {r['foot_acc']:.1e}, "
              f"{r['violations']} joint samples outside limits, solve in Python mean {r['mean_us']:.0f} us")
    plain, fric = runs["plain"]["effort"], runs["friction-aware"]["effort"]
    print(f"friction saves {100 * (1 - fric / plain):.1f} % of the effort")
    if args.check:
        ok = fric <= plain and all(r["com_error"] < 5e-3 and r["drift"] < 1e-4 and r["foot_acc"] < 1e-6
                                   and r["violations"] == 0 for r in runs.values())
        if not ok:
            print("FAILED a bound", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
