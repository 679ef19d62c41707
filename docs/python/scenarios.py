"""The report's chapter 6 scenarios and its Fig. 5.5, from Python.

The 1-DOF arm (models/one_dof_arm.urdf: 2.25 kg m^2 about the joint, breakaway friction
10 N m, no gravity) at rest:
  scenario 1: -5 N at the tip along world y   -> sticks, mu* = -5, qdd = 0
  scenario 2: -11 N                           -> slips,  mu* = -10, qdd = -1/2.25
  Fig. 5.5:   link angular acceleration 5 rad/s^2 -> g linear, mu* = +10, tau_control = 21.25

For each, the exact friction-aware solve gives mu*; the report's sampling of g(mu) on a grid
(eq. 5.9: the plain solver with the friction reaction applied as the torque -mu) is drawn
with it. Sign (docs/conventions.md, "Signs of the outputs"): mu > 0 opposes positive motion;
the report plots magnitudes.

    PYTHONPATH=build/python python3 docs/python/scenarios.py [--out DIR]
"""
import argparse
import pathlib

import numpy as np

import zwang

HERE = pathlib.Path(__file__).resolve().parent
MODEL = HERE.parents[1] / "models" / "one_dof_arm.urdf"
NO_GRAVITY = [0.0, 0.0, 0.0]


def scenarios(model):
    """name -> (description, constraints, wrenches, velocity tolerance)"""
    tip = lambda fy: [zwang.Wrench("tip", force=[0.0, fy, 0.0], expressed="world")]
    spin = [zwang.Constraint("link1", [0, 0, 0, 0, 0, 1], b=[5.0], expressed="local")]
    return {
        "scenario 1 (-5 N)": ([], tip(-5.0)),
        "scenario 2 (-11 N)": ([], tip(-11.0)),
        "Fig. 5.5 (qdd = 5)": (spin, []),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=HERE, help="where scenarios.png goes")
    args = parser.parse_args()

    model = zwang.load_urdf(MODEL)
    ws = model.workspace()
    f = model.breakaway_friction[0]
    q = qd = tau0 = np.zeros(1)
    mus = np.linspace(-f, f, 201)

    rows = []
    curves = {}
    for name, (constraints, wrenches) in scenarios(model).items():
        exact = zwang.solve(model, ws, q, qd, tau0, constraints=constraints, wrenches=wrenches,
                            friction=zwang.Friction(velocity_tolerance=1e-9), gravity=NO_GRAVITY).copy()
        g, qdd, tau_control = [], [], []
        for mu in mus:  # the report's sampling method: the plain solver with tau = tau0 - mu
            res = zwang.solve(model, ws, q, qd, tau0 - mu, constraints=constraints, wrenches=wrenches,
                              gravity=NO_GRAVITY)
            g.append(res.gauss)
            qdd.append(res.qdd[0])
            tau_control.append(res.tau_control[0] + mu)  # the motor command tau0 + tau_c(mu), as at mu*
        curves[name] = (np.array(g), np.array(qdd), np.array(tau_control), exact)
        rows.append((name, exact.mu[0], exact.qdd[0], exact.tau_control[0], exact.state[0], exact.gauss_dual,
                     mus[int(np.argmax(g))]))

    print(f"{'':20} {'mu* [N m]':>10} {'qdd* [rad/s2]':>14} {'tau_control':>12} {'state':>6} {'g(mu*)':>10} "
          f"{'grid argmax':>11}")
    for name, mu, qdd, tc, state, g, grid in rows:
        print(f"{name:20} {mu:10.4g} {qdd:14.6g} {tc:12.6g} {state:>6} {g:10.6g} {grid:11.4g}")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 3, figsize=(12, 9.5), sharex=True)
    for r, (name, (g, qdd, tau_control, exact)) in enumerate(curves.items()):
        for c, (values, label, star) in enumerate([(g, "g(mu) [J/s^2]", exact.gauss_dual),
                                                   (qdd, "qdd(mu) [rad/s^2]", exact.qdd[0]),
                                                   (tau_control, "tau_control [N m]", exact.tau_control[0])]):
            ax = axes[r, c]
            ax.plot(mus, values, color="tab:blue", lw=1.6)
            ax.axvline(exact.mu[0], color="tab:red", ls="--", lw=1)
            ax.plot([exact.mu[0]], [star], "o", color="tab:red",
                    label=f"mu* = {exact.mu[0]:.3g} ({exact.state[0]})" if c == 0 else None)
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
            if c == 0:
                ax.set_title(name, loc="left", fontsize=10)
                ax.legend(loc="lower center", fontsize=8)
    for ax in axes[-1]:
        ax.set_xlabel("friction reaction mu [N m]")
    fig.suptitle("The report's scenarios: exact mu* (red) on the sampled g(mu) of eq. 5.9 (1-DOF arm, f = 10 N m)\n"
                 "mu > 0 opposes positive motion; tau_control = tau0 + tau_c, the motor command", fontsize=11)
    fig.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "scenarios.png", dpi=90)
    print(f"wrote {args.out / 'scenarios.png'}")

    # The reference values of docs/theory.md, "The reference cases" (the script fails loudly if not met).
    (_, mu1, qdd1, tc1, st1, _, _), (_, mu2, qdd2, _, st2, _, _), (_, mu3, qdd3, tc3, st3, _, _) = rows
    assert st1 == "stick" and abs(mu1 + 5) < 1e-12 and abs(qdd1) < 1e-12 and abs(tc1) < 1e-12
    assert st2 == "slip-" and mu2 == -10 and abs(qdd2 + 1 / 2.25) < 1e-14
    assert st3 == "slip+" and mu3 == 10 and abs(qdd3 - 5) < 1e-14 and abs(tc3 - 21.25) < 1e-12


if __name__ == "__main__":
    main()
