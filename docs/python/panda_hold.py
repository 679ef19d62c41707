"""The Panda holding its tool still under gravity: motor effort with and without static friction.

The tool frame is held (six world-axis acceleration rows set to zero) in the ready pose, at
rest. Every joint is stuck; the friction-aware solve finds the friction reactions mu* that
carry as much of the gravity load as the breakaway torques allow (mu* is not unique here,
zwang picks the one with the least effort |tau_control|^2, using at most margin * f_j of each
breakaway torque). The figure compares the motor torques per joint and the effort over the
margin.

    PYTHONPATH=build/python python3 docs/python/panda_hold.py [--out DIR]
"""
import argparse
import pathlib

import numpy as np

import zwang

HERE = pathlib.Path(__file__).resolve().parent
MODEL = HERE.parents[1] / "models" / "panda.urdf"
READY = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, default=HERE, help="where panda_hold.png goes")
    args = parser.parse_args()

    model = zwang.load_urdf(MODEL, root="panda_link0", tip="tool0")
    ws = model.workspace()
    hold = [zwang.Constraint("tool0", np.eye(6), expressed="world")]
    q, qd, tau = READY, np.zeros(7), np.zeros(7)

    plain = zwang.solve(model, ws, q, qd, tau, constraints=hold).copy()
    margins = np.linspace(0.0, 1.0, 21)
    effort = []
    by_margin = {}
    for margin in margins:
        res = zwang.solve(model, ws, q, qd, tau, constraints=hold, friction=zwang.Friction(margin=margin))
        effort.append(float(res.tau_control @ res.tau_control))
        by_margin[round(margin, 2)] = res.copy()
    full, eighty = by_margin[1.0], by_margin[0.8]

    e_plain = float(plain.tau_control @ plain.tau_control)
    print("joint            f_j   tau plain   tau friction(1.0)   tau friction(0.8)   mu*(1.0)  state")
    for j, name in enumerate(model.joint_names):
        print(f"{name:14} {model.breakaway_friction[j]:5.2f}   {plain.tau_control[j]:9.4f}   "
              f"{full.tau_control[j]:17.4f}   {eighty.tau_control[j]:17.4f}   {full.mu[j]:8.4f}  {full.state[j]}")
    print(f"effort |tau|^2 [N^2 m^2]: plain {e_plain:.1f}, friction-aware {effort[-1]:.1f} (margin 1), "
          f"{by_margin[0.8].tau_control @ by_margin[0.8].tau_control:.1f} (margin 0.8); "
          f"indeterminate: {full.indeterminate}")
    assert full.indeterminate and all(s == "stick" for s in full.state)
    assert effort[-1] < e_plain and np.all(np.diff(effort) <= 1e-9)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5), gridspec_kw={"width_ratios": [1.6, 1]})
    x = np.arange(7)
    width = 0.27
    ax1.bar(x - width, plain.tau_control, width, label=f"plain solver  (|tau|^2 = {e_plain:.1f})")
    ax1.bar(x, eighty.tau_control, width, label=f"with friction, margin 0.8  ({effort[16]:.1f})")
    ax1.bar(x + width, full.tau_control, width, label=f"with friction, margin 1  ({effort[-1]:.1f})")
    ax1.errorbar(x + width, np.zeros(7), yerr=model.breakaway_friction, fmt="none", ecolor="gray", capsize=3,
                 lw=0.8, label="+/- breakaway torque f_j")
    ax1.set_xticks(x, [f"J{j + 1}" for j in range(7)])
    ax1.set_ylabel("motor torque tau_control [N m]")
    ax1.axhline(0, color="black", lw=0.6)
    ax1.legend(fontsize=8)
    ax1.set_title("Panda, ready pose, tool held still under gravity", fontsize=10)
    ax2.plot(margins, effort, "o-", ms=3)
    ax2.axhline(e_plain, color="tab:blue", ls="--", lw=1, label="plain solver")
    ax2.set_xlabel("margin (fraction of each breakaway torque friction may carry)")
    ax2.set_ylabel("effort |tau_control|^2 [N^2 m^2]")
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "panda_hold.png", dpi=90)
    print(f"wrote {args.out / 'panda_hold.png'}")


if __name__ == "__main__":
    main()
