#!/usr/bin/env python3
"""Two builds of zwang_bench in the same run: each benchmark's median (or
minimum) CPU time over `--rounds` alternating runs of the two binaries, and the
ratio new/old.

  python3 bench/compare.py OLD/zwang_bench NEW/zwang_bench --filter 'REGEX' [--rounds 5] [--min-time 0.1] [--stat min]

On a shared machine whose load comes and goes, the minimum over many rounds
is the steadier measure of what the code costs (a neighbour only ever adds).

Build the old one from the commit to compare against (e.g. a clone at that
commit: cmake -DZWANG_BUILD_BENCHMARKS=ON, target zwang_bench). Alternating
the binaries spreads a busy machine's noise over both alike.
"""
import argparse
import json
import statistics
import subprocess


def run(binary, pattern, min_time):
    out = subprocess.run([binary, f"--benchmark_filter={pattern}", f"--benchmark_min_time={min_time}",
                          "--benchmark_format=json"], check=True, capture_output=True, text=True).stdout
    return {b["name"]: b["cpu_time"] for b in json.loads(out)["benchmarks"] if b.get("run_type") == "iteration"}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--filter", default=".")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--min-time", type=float, default=0.1)
    parser.add_argument("--stat", choices=("median", "min"), default="median")
    a = parser.parse_args()
    times = {"old": {}, "new": {}}
    for _ in range(a.rounds):
        for side, binary in (("old", a.old), ("new", a.new)):
            for name, t in run(binary, a.filter, a.min_time).items():
                times[side].setdefault(name, []).append(t)
    stat = statistics.median if a.stat == "median" else min
    print(f"{a.stat} CPU time over {a.rounds} rounds of {a.min_time} s\n")
    print(f"| benchmark | old [µs] | new [µs] | new/old |\n|---|---|---|---|")
    for name in times["new"]:
        if name not in times["old"]:
            continue
        old, new = stat(times["old"][name]) / 1e3, stat(times["new"][name]) / 1e3
        print(f"| {name} | {old:.3f} | {new:.3f} | {new / old:.3f} |")


if __name__ == "__main__":
    main()
