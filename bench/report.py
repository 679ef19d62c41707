#!/usr/bin/env python3
"""Writes docs/benchmarks.md (and a log-log plot) from zwang_bench's JSON output.

Standard library only. Called by bench/run.sh; can be rerun on an existing JSON:
  python3 bench/report.py --json bench/results/zwang_bench.json \
      --markdown docs/benchmarks.md --plot bench/results/cost_vs_n.png
"""
import argparse
import json
import math
import os
import platform
import shutil
import subprocess
import tempfile

SIZES = [1, 2, 4, 7, 16, 32, 64, 128]
MODELS = [f"N={n}" for n in SIZES] + ["panda"]
SLOPE_SIZES = [16, 32, 64, 128]
TREE_SIZES = [7, 16, 32, 64, 128]
TREE_BRANCHING = [2, 4]  # next to b = 1, the chain
TREE_LIMIT = 1.15  # issue 14: a tree's cost per body at most 15 % above the chain's
# Issue 15: floating bases, and the fixed-base chains of the same size (N = the robot's nv, N = its joints).
FLOATING_ROBOTS = [("humanoid", "humanoid (`simple_humanoid.urdf`)", 35, 29), ("solo12", "solo12 (`solo12.urdf`)", 18, 12)]
FLOATING_FRICTION_LIMIT = 4.0  # issue 15: friction with every joint stuck at most 4× the plain solve
FLOATING_FAMILIES = [  # floating_<family>/<model>, in the tables' column order
    ("hd_m0", "plain, no rows"),
    ("hd_m12", "plain, 12 rows"),
    ("fric_as_m0_kall", "friction, all stuck, no rows"),
    ("fric_as_m12_kall", "friction, all stuck, 12 rows"),
]

# Table rows, in order, with a description.
FAMILIES = [
    ("ours_hd_m0", "ours: solveHybridDynamics, no constraint"),
    ("ours_hd_m1", "ours: solveHybridDynamics, 1 end-effector row"),
    ("ours_hd_m6", "ours: solveHybridDynamics, 6 end-effector rows"),
    ("ours_hd_m6x2", "ours: solveHybridDynamics, 6 rows on 2 frames (3 last link, 3 middle link)"),
    ("ours_rnea", "ours: inverseDynamics (RNEA)"),
    ("ours_crba", "ours: jointSpaceInertia (CRBA)"),
    ("kdl_hd_m0", "KDL: ChainHdSolver_Vereshchagin, one zero column"),
    ("kdl_hd_m1", "KDL: ChainHdSolver_Vereshchagin, 1 row"),
    ("kdl_hd_m6", "KDL: ChainHdSolver_Vereshchagin, 6 rows"),
    ("kdl_rne", "KDL: ChainIdSolver_RNE"),
]
for method, method_text in (("as", "active set"), ("pg", "projected gradient")):
    for task, task_text in (("free", "no constraint"), ("ee6", "6 end-effector rows")):
        for k, k_text in (("k0", "k = 0"), ("k1", "k = 1"), ("k2", "k = 2"), ("khalf", "k = N/2"), ("kall", "k = N")):
            FAMILIES.append((f"fric_{method}_{task}_{k}", f"ours: solveWithFriction, {method_text}, {task_text}, {k_text}"))
for task, task_text in (("free", "no constraint"), ("ee6", "6 end-effector rows")):
    for k in (1, 2):
        FAMILIES.append((f"grid_{task}_k{k}", f"report's grid: 21^{k} full solves, {task_text}, k = {k}"))
for task, task_text in (("free", "no constraint"), ("ee6", "6 end-effector rows")):
    for k in (1, 2):
        FAMILIES.append((f"naivepg_{task}_k{k}",
                         f"projected gradient, one full solve per gradient, {task_text}, k = {k}"))

PLOT_SERIES = [
    ("ours_hd_m0", "ours hybrid, m = 0"),
    ("ours_hd_m6", "ours hybrid, m = 6"),
    ("kdl_hd_m0", "KDL Vereshchagin, m = 0"),
    ("kdl_hd_m6", "KDL Vereshchagin, m = 6"),
    ("ours_rnea", "ours RNEA"),
    ("kdl_rne", "KDL RNE"),
    ("ours_crba", "ours CRBA"),
    ("fric_as_ee6_k1", "ours friction, m = 6, k = 1"),
    ("fric_as_ee6_kall", "ours friction, m = 6, k = N"),
    ("grid_ee6_k1", "grid method, m = 6, k = 1"),
    ("grid_ee6_k2", "grid method, m = 6, k = 2"),
]


COLORS = ["#1f77b4", "#d62728", "#17becf", "#ff7f0e", "#2ca02c", "#8c564b", "#9467bd", "#000000", "#e377c2",
          "#7f7f7f", "#bcbd22"]


def load(path):
    with open(path) as f:
        data = json.load(f)
    medians, cvs, counters, errors, plain = {}, {}, {}, {}, {}
    for b in data["benchmarks"]:
        run = b.get("run_name", b["name"])
        if b.get("error_occurred"):
            errors[run] = b.get("error_message", "error")
            continue
        scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}[b.get("time_unit", "ns")]
        if b.get("run_type") == "aggregate":
            if b.get("aggregate_name") == "median":
                medians[run] = b["cpu_time"] * scale
                counters[run] = b
            elif b.get("aggregate_name") == "cv":
                cvs[run] = b["cpu_time"]
        else:  # no repetitions: the single run
            plain.setdefault(run, []).append(b["cpu_time"] * scale)
            counters.setdefault(run, b)
    for run, times in plain.items():
        if run not in medians:
            times.sort()
            medians[run] = times[len(times) // 2]
    return data["context"], medians, cvs, counters, errors


def fmt_ns(x):
    if x is None:
        return "—"
    return f"{x:,.0f}" if x >= 100 else f"{x:.1f}"


def fmt_ratio(x):
    if x is None:
        return "—"
    return f"{x:,.0f}×" if x >= 100 else f"{x:.2f}×"


def slope(medians, family, model="N={n}"):
    names = [(n, f"{family}/{model.format(n=n)}") for n in SLOPE_SIZES]
    pts = [(math.log(n), math.log(medians[name])) for n, name in names if name in medians]
    if len(pts) < 2:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx


def ratio(medians, num, den):
    if num in medians and den in medians and medians[den] > 0:
        return medians[num] / medians[den]
    return None


def tree_name(task, n, b):
    return f"tree_hd_{task}/N={n},b={b}"


def tree_ratios(medians, counters, task, b, full_rank_only=False):
    """(worst tree/chain ratio, the N it was at, the N compared) over TREE_SIZES; with full_rank_only only the
    sizes whose leaf task the tree meets in full (balance rank = rows)."""
    worst, at, sizes = None, None, []
    for n in TREE_SIZES:
        r = ratio(medians, tree_name(task, n, b), tree_name(task, n, 1))
        c = counters.get(tree_name(task, n, b), {})
        if r is None or (full_rank_only and c.get("rank", 0) < c.get("m", 0)):
            continue
        sizes.append(n)
        if worst is None or r > worst:
            worst, at = r, n
    return worst, at, sizes


def tree_section(w, medians, counters, ctx):
    if not any(tree_name("m0", n, b) in medians for n in TREE_SIZES for b in TREE_BRANCHING):
        return
    w("## Trees (issue 14)")
    w("")
    w("Each tree has exactly the bodies, joints and state of the chain of the same N (the chain benchmarks'")
    w("`randomChain`, same seed) with the joints re-hung as a **complete b-ary tree**: in heap order body v")
    w("hangs from body ⌊(v − 1)/b⌋ (0: the base, which has b children), the branching-factor trees of")
    w("Featherstone's benchmarks, numbered depth first as the model requires (`tree_hd_*/N=…,b=…`; b = 1 is")
    w("the chain itself, timed again in the same run). *6 rows*: the deepest leaf held still in world axes.")
    depths = []
    for b in TREE_BRANCHING:
        d = [counters[tree_name("m6", n, b)].get("depth", 0) for n in TREE_SIZES if tree_name("m6", n, b) in counters]
        if d:
            depths.append(f"b = {b} {min(d):.0f}–{max(d):.0f}")
    w("A leaf of a balanced tree has few joints above it (" + ", ".join(depths) + f" for N = {TREE_SIZES[0]}…"
      f"{TREE_SIZES[-1]}): with")
    w("fewer than 6 the six rows cannot all be met (balance rank = depth), and the solve takes the balance's")
    w("least-squares path (eigen-decomposition instead of Cholesky), which costs more than the tree saves on")
    w("small N. *Per body*: time / N. *ratio*: tree / chain at the same N (the same per body).")
    w("")
    for task, text in (("m0", "no constraint"), ("m6", "6 rows on the deepest leaf")):
        w(f"**solveHybridDynamics, {text}** (median CPU time [ns])")
        w("")
        head = "| N | chain | per body |"
        rule = "|---|---|---|"
        for b in TREE_BRANCHING:
            head += f" tree b = {b} | per body | ratio |"
            rule += "---|---|---|"
        w(head)
        w(rule)
        for n in TREE_SIZES:
            chain = medians.get(tree_name(task, n, 1))
            cells = [str(n), fmt_ns(chain), fmt_ns(chain / n if chain else None)]
            for b in TREE_BRANCHING:
                t = medians.get(tree_name(task, n, b))
                r = ratio(medians, tree_name(task, n, b), tree_name(task, n, 1))
                c = counters.get(tree_name(task, n, b), {})
                note = ""
                if task == "m6" and c:
                    rank = c.get("rank", 0)
                    note = f" (depth {c.get('depth', 0):.0f}" + (f", rank {rank:.0f})" if rank < 6 else ")")
                cells += [fmt_ns(t), fmt_ns(t / n if t else None), fmt_ratio(r) + note]
            w("| " + " | ".join(cells) + " |")
        w("")
    slopes = []
    for task in ("m0", "m6"):
        for b in [1] + TREE_BRANCHING:
            v = slope(medians, f"tree_hd_{task}", "N={n},b=" + str(b))
            if v is not None:
                slopes.append(f"{'chain' if b == 1 else f'b = {b}'} {task} {v:.2f}")
    if slopes:
        w("Log–log slopes of time against N (least squares over N = 16, 32, 64, 128; 1 = linear): "
          + ", ".join(slopes) + ".")
        w("")

    dual = {key: medians.get(f"{key}/dual_panda") for key in
            ("ours_hd_hands12", "ours_hd_rel6", "fric_as_hands12_kall", "fric_as_rel6_kall")}
    if any(v is not None for v in dual.values()):
        w("### Dual arm")
        w("")
        w("`models/dual_panda.urdf`: two Panda arms on a torso that turns about z (15 joints, docs in")
        w("models/README.md), in a two-handed grasp of a box 0.5 m in front of the torso (the pose")
        w("`python3 models/make_dual_panda.py --check` solves for); q̇ = ±0.5 rad/s alternating for the plain")
        w("solves, 0 (all 15 joints stuck, friction from the URDF) for the friction solves; τ = 0.")
        hands = ctx.get("zwang_dual_panda_hands", "?")
        w(f"Loaded as a whole tree (`loadUrdfFile`, no tip). Hands in that pose: {hands}.")
        w("")
        w("| median CPU time [ns] | 12 hand rows (6 per hand, world axes) | "
          "6 relative rows (left hand to right hand) |")
        w("|---|---|---|")
        w(f"| plain: solveHybridDynamics | {fmt_ns(dual['ours_hd_hands12'])} | {fmt_ns(dual['ours_hd_rel6'])} |")
        w(f"| friction, all 15 joints stuck: solveWithFriction (active set) | "
          f"{fmt_ns(dual['fric_as_hands12_kall'])} | {fmt_ns(dual['fric_as_rel6_kall'])} |")
        rel = [fmt_ratio(ratio(medians, f"fric_as_{t}_kall/dual_panda", f"ours_hd_{t}/dual_panda"))
               for t in ("hands12", "rel6")]
        w(f"| friction / plain | {rel[0]} | {rel[1]} |")
        its = [counters.get(f"fric_as_{t}_kall/dual_panda", {}).get("iterations") for t in ("hands12", "rel6")]
        w("| maximiser iterations | " + " | ".join("—" if i is None else f"{i:.0f}" for i in its) + " |")
        w("")


def floating_name(family, model):
    return f"floating_{family}/{model}"


def floating_models(medians):
    """The robots and chains that have a floating benchmark, robots first, each robot followed by its chains."""
    out = []
    for robot, _, nv, dof in FLOATING_ROBOTS:
        for model in (robot, f"chain_N={nv}", f"chain_N={dof}"):
            if model not in out and any(floating_name(f, model) in medians for f, _ in FLOATING_FAMILIES):
                out.append(model)
    return out


def floating_per_dof(medians, counters, family, model):
    t = medians.get(floating_name(family, model))
    nv = counters.get(floating_name(family, model), {}).get("nv")
    return t / nv if t is not None and nv else None


def floating_section(w, medians, counters, ctx):
    models = floating_models(medians)
    if not models:
        return
    w("## Floating bases (issue 15)")
    w("")
    w("Two robots on a free base (`UrdfOptions::base = BaseType::Free`), standing at rest (q̇ = 0, τ = 0: the")
    w("motors off) with the base upright at the height that puts the feet on the ground:")
    w("`models/simple_humanoid.urdf` (29 joints, nv = 35) on both feet, each foot a 6-row `Task::addContact` in")
    w("world axes (its ankle link: the file has no soles), and `models/solo12.urdf` (12 joints, nv = 18) on its")
    w("four point feet, 3 linear rows each: **12 rows** either way; *no rows*: the same robot in free fall.")
    w(f"Poses: {ctx.get('zwang_floating_poses', '?')}.")
    w("*Friction, all stuck*: `solveWithFriction` (active set) with every joint stuck (q̇ = 0) and every breakaway")
    w(f"friction set to {ctx.get('zwang_floating_breakaway', '?')} N·m (`ModelBuilder::setFriction`), so that all")
    w("joints stay stuck (the bench checks it before timing): the maximiser works on all of them.")
    w("*The chain of the same size*: the chain benchmarks' `randomChain` (same seed and pose, q̇ = 0, the same")
    w("friction) on a fixed base with N = the robot's nv (as many velocity coordinates: q̈ of the same length) or")
    w("N = its joints (the same joints without the base); its 12 rows hold the last link and the middle link")
    w("(6 each, contacts in world axes). Cost per DOF: time / nv (a chain's nv is N).")
    w("")
    w("**Time per solve** (median CPU time [ns])")
    w("")
    w("| model | joints | nv | " + " | ".join(text for _, text in FLOATING_FAMILIES)
      + " | friction / plain, 12 rows | maximiser iterations (12 rows) |")
    w("|---|---|---|" + "---|" * len(FLOATING_FAMILIES) + "---|---|")
    for model in models:
        c = next((counters[floating_name(f, model)] for f, _ in FLOATING_FAMILIES
                  if floating_name(f, model) in counters), {})
        cells = [f"`{model}`", f"{c.get('N', 0):.0f}", f"{c.get('nv', 0):.0f}"]
        cells += [fmt_ns(medians.get(floating_name(f, model))) for f, _ in FLOATING_FAMILIES]
        cells.append(fmt_ratio(ratio(medians, floating_name("fric_as_m12_kall", model),
                                     floating_name("hd_m12", model))))
        it = counters.get(floating_name("fric_as_m12_kall", model), {})
        cells.append("—" if "iterations" not in it else f"{it['iterations']:.0f}"
                     + (" (μ* not unique)" if it.get("indeterminate") else ""))
        w("| " + " | ".join(cells) + " |")
    w("")
    w("**Cost per DOF** (time / nv [ns]), and the robot's against the chain with N = its nv")
    w("")
    w("| model | " + " | ".join(text for _, text in FLOATING_FAMILIES) + " |")
    w("|---|" + "---|" * len(FLOATING_FAMILIES))
    for model in models:
        w(f"| `{model}` | " + " | ".join(fmt_ns(floating_per_dof(medians, counters, f, model))
                                         for f, _ in FLOATING_FAMILIES) + " |")
    for robot, _, nv, dof in FLOATING_ROBOTS:
        for n, what in ((nv, "per DOF, the same nv"), (dof, "per DOF, the same joints")):
            chain = f"chain_N={n}"
            cells = []
            for f, _ in FLOATING_FAMILIES:
                a = floating_per_dof(medians, counters, f, robot)
                b = floating_per_dof(medians, counters, f, chain)
                cells.append(fmt_ratio(a / b if a is not None and b else None))
            if any(c != "—" for c in cells):
                w(f"| {robot} / `{chain}` ({what}) | " + " | ".join(cells) + " |")
    w("")


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def git_revision(root):
    try:
        return subprocess.run(["git", "-C", root, "describe", "--always", "--dirty"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def make_plot(medians, png):
    gnuplot = shutil.which("gnuplot")
    if not gnuplot:
        return "gnuplot not found: no plot (Debian: gnuplot-nox)."
    with tempfile.TemporaryDirectory() as tmp:
        plots = []
        for i, (family, title) in enumerate(PLOT_SERIES):
            rows = [(n, medians[f"{family}/N={n}"]) for n in SIZES if f"{family}/N={n}" in medians]
            if not rows:
                continue
            path = os.path.join(tmp, f"{family}.dat")
            with open(path, "w") as f:
                for n, t in rows:
                    f.write(f"{n} {t}\n")
            dash = "" if family.startswith(("ours", "fric")) else " dt 2"
            color = COLORS[i % len(COLORS)]
            plots.append(f"'{path}' using 1:2 with linespoints lw 2 pt {i % 13 + 1} lc rgb '{color}'{dash} "
                         f"title '{title}'")
        script = "\n".join([
            "set terminal pngcairo size 1100,750 font ',11'",
            f"set output '{png}'",
            "set logscale xy",
            "set xrange [0.85:150]",
            "set xlabel 'N (revolute joints)'",
            "set ylabel 'median CPU time per call [ns]'",
            "set title 'zwang vs KDL vs the grid method: cost per call against chain length'",
            "set key outside right top",
            "set grid",
            "set xtics (1, 2, 4, 7, 16, 32, 64, 128)",
            "set format y '10^{%L}'",
            "plot " + ", \\\n     ".join(plots),
        ])
        result = subprocess.run([gnuplot], input=script, capture_output=True, text=True)
        if result.returncode != 0:
            return "gnuplot failed: " + result.stderr.strip()
    return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--json", required=True)
    ap.add_argument("--markdown", required=True)
    ap.add_argument("--plot", required=True)
    ap.add_argument("--command", default="bash bench/run.sh")
    ap.add_argument("--settings", default="")
    ap.add_argument("--load-after", default="")
    args = ap.parse_args()

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ctx, med, cvs, counters, errors = load(args.json)
    md_dir = os.path.dirname(os.path.abspath(args.markdown))
    plot_rel = os.path.relpath(os.path.abspath(args.plot), md_dir)
    json_rel = os.path.relpath(os.path.abspath(args.json), md_dir)

    out = []
    w = out.append
    w("# Benchmarks")
    w("")
    w("Cost per call of zwang's solvers, KDL's on the same chains, and the report's way of finding the")
    w("static friction torques, measured in one run of `zwang_bench` (issue 5). This file is generated by")
    w("`bench/report.py`; do not edit it by hand.")
    w("")
    w("## Reproduce")
    w("")
    w("```sh")
    w(args.command)
    w("```")
    w("")
    w("(from the repository root: builds `zwang_bench` in Release in `build-bench/` if needed, runs it once with")
    w(f"repetitions, writes this file, `{json_rel}` and the plot.)")
    w("")
    w("To see where one benchmark spends its time: `bash bench/profile.sh '<benchmark regex>'` (perf), or")
    w("`bash bench/profile.sh '<regex>' '*solveHybridDynamics*'` (callgrind, collecting inside that function).")
    w("")
    w("## Machine and build")
    w("")
    load_before = ", ".join(f"{x:.2f}" for x in ctx.get("load_avg", []))
    w("| | |")
    w("|---|---|")
    w(f"| CPU | {cpu_model()} ({ctx.get('num_cpus', os.cpu_count())} logical cores, {ctx.get('mhz_per_cpu', '?')} MHz) |")
    caches = ", ".join(f"L{c['level']} {c['type'].lower()} {c['size'] // 1024} KiB" for c in ctx.get("caches", []))
    w(f"| caches | {caches} |")
    w(f"| OS | {platform.system()} {platform.release()} |")
    w(f"| compiler | {ctx.get('zwang_compiler', '?')} |")
    w(f"| flags | `{ctx.get('zwang_cxx_flags', '?')}` ({ctx.get('zwang_build_type', '?')}; library and bench alike; "
      f"warnings `-Wall -Wextra -Wpedantic -Werror`) |")
    w(f"| Google Benchmark | Debian libbenchmark-dev (its own build type: {ctx.get('library_build_type', '?')}; "
      "this only concerns the timing harness) |")
    w(f"| run | {ctx.get('date', '?')}, {args.settings or 'see the command'}; source `{git_revision(root)}` |")
    w(f"| load average | {load_before or '?'} before the run{', ' + args.load_after + ' after' if args.load_after else ''} |")
    w("")
    w("Times are the **median CPU time per call** over the repetitions, in nanoseconds (CPU time rather than wall")
    w("time, so that other processes on a shared machine do not count; with a quiet machine the two agree).")
    w("Chains: `randomChain` (test/support) with a fixed seed, N revolute joints with limits, rotor inertias on,")
    w("no fixed or prismatic joints; the Panda is `models/panda.urdf`. Every joint moves (0.1 ≤ |q̇| ≤ 2 rad/s);")
    w("for the friction rows the k stuck joints (spread evenly along the chain) have q̇ = 0. Constraints hold")
    w("the end effector still in world axes (m = 1: the vertical force row). Ours and KDL are given the same")
    w("problem; before timing, the bench checks that they agree (largest relative error of q̈ over m = 0, 1, 6")
    w(f"where m ≤ N, and of the RNEA torques): {ctx.get('zwang_check_vs_kdl_max_rel_err', 'not recorded')}.")
    w("")

    # ---- The ratios
    rows = []

    def target_row(text, value, target_text, ok, fmt=fmt_ratio):
        if value is None:
            status = "—"
        elif ok is None:
            status = "(info)"
        else:
            status = "**met**" if ok(value) else "**not met**"
        rows.append(f"| {text} | {fmt(value) if value is not None else '—'} | {target_text} | {status} |")

    for n, t in ((7, 4.0), (64, 3.0)):
        target_row(f"KDL Vereshchagin / ours, 6 end-effector rows, N = {n}",
                   ratio(med, f"kdl_hd_m6/N={n}", f"ours_hd_m6/N={n}"), f"≥ {t:g}×", lambda v, t=t: v >= t)
    target_row("KDL Vereshchagin / ours, 6 end-effector rows, Panda",
               ratio(med, "kdl_hd_m6/panda", "ours_hd_m6/panda"), "—", None)
    for n in (7, 64):
        target_row(f"KDL Vereshchagin / ours, no constraint, N = {n}",
                   ratio(med, f"kdl_hd_m0/N={n}", f"ours_hd_m0/N={n}"), "—", None)
        target_row(f"KDL RNE / ours RNEA, N = {n}", ratio(med, f"kdl_rne/N={n}", f"ours_rnea/N={n}"), "—", None)
    for n in (7, 64):
        target_row(f"ours hybrid (no constraint) / ours RNEA, N = {n}",
                   ratio(med, f"ours_hd_m0/N={n}", f"ours_rnea/N={n}"), "≤ 2×", lambda v: v <= 2.0)
    target_row("Panda, all 7 joints stuck, 6 end-effector rows: friction (active set) / plain solve",
               ratio(med, "fric_as_ee6_kall/panda", "ours_hd_m6/panda"), "≤ 2.5×", lambda v: v <= 2.5)
    target_row("the same with the projected-gradient maximiser",
               ratio(med, "fric_pg_ee6_kall/panda", "ours_hd_m6/panda"), "≤ 2.5×", lambda v: v <= 2.5)
    fmt_slope = lambda v: f"{v:.2f}"
    for method, mtext in (("as", "active set"), ("pg", "projected gradient")):
        for task, ttext in (("free", "no constraint"), ("ee6", "6 rows")):
            for k in ("k0", "k1"):
                if method == "pg" and k == "k0":
                    continue  # k = 0 does not reach the maximiser
                target_row(f"log–log slope N = 16…128, friction ({mtext}, {ttext}), {k.replace('k', 'k = ')}",
                           slope(med, f"fric_{method}_{task}_{k}"), "1.0 ± 0.1", lambda v: abs(v - 1.0) <= 0.1,
                           fmt_slope)
    for method, mtext in (("as", "active set"), ("pg", "projected gradient")):
        for task, ttext in (("free", "no constraint"), ("ee6", "6 rows")):
            target_row(f"log–log slope N = 16…128, friction ({mtext}, {ttext}), k = N",
                       slope(med, f"fric_{method}_{task}_kall"), "≤ 2", lambda v: v <= 2.0, fmt_slope)
    for model, mtext in (("N=7", "N = 7"), ("panda", "Panda")):
        for k in (1, 2):
            target = "> 1× (beats it)" if k == 1 else "≥ 100× (orders of magnitude)"
            limit = 1.0 if k == 1 else 100.0
            target_row(f"grid method / ours (active set), 6 rows, k = {k}, {mtext}",
                       ratio(med, f"grid_ee6_k{k}/{model}", f"fric_as_ee6_k{k}/{model}"), target,
                       lambda v, limit=limit: v > limit if limit == 1.0 else v >= limit)
    # Issue 14: a tree's cost per body within 15 % of the chain's. With 6 rows on a leaf, only the trees whose
    # leaf has at least 6 joints above it are compared against the target (the others cannot meet the task:
    # rank < 6, the balance's least-squares path); every N is listed for information.
    for task, ttext in (("m0", "no constraint"), ("m6", "6 rows on the deepest leaf")):
        for b in TREE_BRANCHING:
            worst, at, sizes = tree_ratios(med, counters, task, b, full_rank_only=(task == "m6"))
            if sizes:
                where = f"worst over N = {', '.join(map(str, sizes))} (at N = {at})"
                if task == "m6":
                    where += ", the trees whose leaf task has full rank"
                target_row(f"tree cost per body within 15 % of the chain's: tree b = {b} / chain, {ttext}, {where}",
                           worst, f"≤ {TREE_LIMIT:g}× (within 15 %)", lambda v: v <= TREE_LIMIT)
            if task == "m6":
                worst_all, at_all, sizes_all = tree_ratios(med, counters, task, b)
                if sizes_all and sizes_all != sizes:
                    target_row(f"tree b = {b} / chain, {ttext}, worst over every N = 7…128 (at N = {at_all}; "
                               "a leaf with fewer than 6 joints above it: rank < 6, the least-squares path)",
                               worst_all, "—", None)
    # Issue 15: friction with every joint stuck at most 4× the plain solve, on the two floating robots; their
    # cost per DOF against the fixed-base chain with as many DOF, for information.
    for robot, _, nv, dof in FLOATING_ROBOTS:
        r = ratio(med, floating_name("fric_as_m12_kall", robot), floating_name("hd_m12", robot))
        if r is not None:
            target_row(f"{robot} (free base, {dof} joints, 12 foot rows), all joints stuck: friction (active set) / "
                       "plain solve", r, f"≤ {FLOATING_FRICTION_LIMIT:g}×", lambda v: v <= FLOATING_FRICTION_LIMIT)
        for family, text in (("hd_m0", "plain, no rows"), ("hd_m12", "plain, 12 rows")):
            a = floating_per_dof(med, counters, family, robot)
            b = floating_per_dof(med, counters, family, f"chain_N={nv}")
            if a is not None and b:
                target_row(f"{robot} cost per DOF / fixed-base chain N = {nv} (its nv), {text}", a / b, "—", None)
    # Issue 27: a solve with half the joints prescribed (every other joint) costs what a plain solve costs (± 10 %)
    # and less than the same task with those joints held by joint rows.
    for task, ttext in (("m0", "no constraint"), ("m1", "1 end-effector row")):
        for n in (4, 7, 16, 64):
            target_row(f"half the joints prescribed / plain solve, {ttext}, N = {n}",
                       ratio(med, f"ours_hd_{task}_halfprescribed/N={n}", f"ours_hd_{task}/N={n}"), "≤ 1.1×",
                       lambda v: v <= 1.1)
            target_row(f"half the joints prescribed / the same as joint rows, {ttext}, N = {n}",
                       ratio(med, f"ours_hd_{task}_halfprescribed/N={n}", f"ours_hd_{task}_halfrows/N={n}"), "< 1×",
                       lambda v: v < 1.0)
    w("## The issue's targets")
    w("")
    w("| ratio | measured | target | |")
    w("|---|---|---|---|")
    out.extend(rows)
    w("")
    w("Slopes are least-squares fits of log(time) against log(N) over N = 16, 32, 64, 128. Other slopes (no")
    w("target): " + ", ".join(
        f"{fam} {slope(med, fam):.2f}" for fam in ("ours_hd_m0", "ours_hd_m6", "ours_rnea", "ours_crba", "kdl_hd_m0",
                                                   "kdl_hd_m6", "kdl_rne", "fric_as_ee6_khalf", "fric_pg_ee6_khalf",
                                                   "grid_ee6_k1", "grid_ee6_k2")
        if slope(med, fam) is not None) + ".")
    w("")

    # ---- Friction versus the report's methods, at every size
    worst = [(name, counters[name]) for name in sorted(counters) if name.startswith("worst_")]
    if worst:
        w("## Worst case over 10⁶ calls")
        w("")
        w("Each friction solve timed on its own (steady_clock, its ~20 ns overhead included), Panda with all 7")
        w("joints stuck; the same workspace throughout (median of the repetitions for each statistic).")
        w("")
        w("| benchmark | calls | median [ns] | 99 % [ns] | 99.99 % [ns] | max [ns] |")
        w("|---|---|---|---|---|---|")
        for name, c in worst:
            w(f"| `{name}` | {c.get('calls', 0):,.0f} | {fmt_ns(c.get('median_ns'))} | {fmt_ns(c.get('p99_ns'))} | "
              f"{fmt_ns(c.get('p99.99_ns'))} | {fmt_ns(c.get('max_ns'))} |")
        w("")
    tree_section(w, med, counters, ctx)
    floating_section(w, med, counters, ctx)
    w("## Friction solve versus the report's methods")
    w("")
    w("Time of the method divided by the time of `solveWithFriction` (active set) on the same problem.")
    w("*grid*: 21 friction values per stuck joint, one full `solveHybridDynamics` per grid point (21 or 441")
    w("calls), keep the largest g(μ) (with the torques τ − Wᵀμ passed in, `Solution::gauss` is g(μ)).")
    w("*naive PG*: projected gradient on g with one full solve per gradient ∇g = q̈_Θ(μ), step 1/L with")
    w("L = λ_max(K_ΘΘ) estimated once per call from k unit-torque solves, stopped at the tolerance")
    w("`solveWithFriction` uses (no ∂q̈/∂μ reuse). Below the table: how many solver calls the naive method")
    w("needed, and how far the grid's μ is from μ* (the grid is exact only when μ* lies on the grid, e.g. when")
    w("the joint slips at ±f).")
    w("")
    w("| method | " + " | ".join(m.replace("N=", "N = ") for m in MODELS) + " |")
    w("|---|" + "---|" * len(MODELS))
    for prefix in ("grid", "naivepg"):
        for task in ("free", "ee6"):
            for k in (1, 2):
                cells = [fmt_ratio(ratio(med, f"{prefix}_{task}_k{k}/{m}", f"fric_as_{task}_k{k}/{m}")) for m in MODELS]
                name = "grid" if prefix == "grid" else "naive PG"
                w(f"| {name}, {'no constraint' if task == 'free' else '6 rows'}, k = {k} | " + " | ".join(cells) + " |")
    for task in ("free", "ee6"):
        for k in (1, 2):
            cells = []
            for m in MODELS:
                c = counters.get(f"naivepg_{task}_k{k}/{m}")
                cells.append("—" if c is None else f"{c.get('solves', float('nan')):.0f}")
            w(f"| naive PG solver calls, {'no constraint' if task == 'free' else '6 rows'}, k = {k} | "
              + " | ".join(cells) + " |")
    for task in ("free", "ee6"):
        for k in (1, 2):
            cells = []
            for m in MODELS:
                c = counters.get(f"grid_{task}_k{k}/{m}")
                cells.append("—" if c is None else f"{c.get('mu_err', float('nan')):.2g}")
            w(f"| grid: max abs(μ − μ*) [N·m], {'no constraint' if task == 'free' else '6 rows'}, k = {k} | "
              + " | ".join(cells) + " |")
    w("")

    # ---- The full table
    w("## Median CPU time per call [ns]")
    w("")
    w("| benchmark | " + " | ".join(m.replace("N=", "N = ") for m in MODELS) + " |")
    w("|---|" + "---|" * len(MODELS))
    for family, text in FAMILIES:
        cells = [fmt_ns(med.get(f"{family}/{m}")) for m in MODELS]
        if all(c == "—" for c in cells):
            continue
        w(f"| `{family}` {text} | " + " | ".join(cells) + " |")
    w("")
    w("— : not run (k > N, or the same problem as another row: k = N/2 is listed only when it differs from")
    w("0, 1, 2 and N; k = N only for N > 1).")
    iters = []
    for family in ("fric_as_ee6_kall", "fric_pg_ee6_kall", "fric_as_free_kall", "fric_pg_free_kall"):
        cells = [f"{m.replace('N=', '')}: {counters[f'{family}/{m}'].get('iterations', float('nan')):.0f}"
                 for m in MODELS if f"{family}/{m}" in counters]
        if cells:
            iters.append(f"`{family}` " + ", ".join(cells))
    if iters:
        w("Maximiser iterations with k = N: " + "; ".join(iters) + ".")
    if cvs:
        worst = max(cvs.items(), key=lambda kv: kv[1])
        noisy = sum(1 for v in cvs.values() if v > 0.05)
        w(f"Spread over the repetitions: the largest coefficient of variation is {100 * worst[1]:.1f} % "
          f"(`{worst[0]}`); {noisy} of {len(cvs)} benchmarks are above 5 %.")
    if errors:
        w("")
        w("Benchmarks that reported an error: " + "; ".join(f"`{k}`: {v}" for k, v in sorted(errors.items())) + ".")
    w("")

    # ---- Plot
    w("## Cost against N")
    w("")
    problem = make_plot(med, os.path.abspath(args.plot))
    if problem:
        w(f"({problem})")
    else:
        w(f"![median CPU time per call against N, log-log]({plot_rel})")
        w("")
        w("Solid lines: zwang; dashed: KDL and the grid method.")
    w("")

    with open(args.markdown, "w") as f:
        f.write("\n".join(out))


if __name__ == "__main__":
    main()
