#!/usr/bin/env bash
# Where one benchmark spends its time: perf (sampling) when it works here,
# otherwise valgrind's callgrind restricted to the timed function.
#
#   bash bench/profile.sh '^ours_hd_m6/N=7$'                       # perf
#   bash bench/profile.sh '^ours_hd_m6/N=7$' '*solveHybridDynamics*' # callgrind, collecting inside that function
#     (its last line: the instructions per call of that function, the binary's own checks subtracted)
#
# Uses the binary bench/run.sh builds (build-bench/, Release).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bench=${ZWANG_BENCH_BUILD_DIR:-$root/build-bench}/bench/zwang_bench
filter=${1:?usage: profile.sh <benchmark filter regex> [callgrind toggle-collect pattern]}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if [[ $# -lt 2 ]] && command -v perf >/dev/null && perf record -q -o "$tmp/probe" true 2>/dev/null; then
  perf record -q -F 4000 -o "$tmp/perf.data" -- "$bench" --benchmark_filter="$filter" --benchmark_min_time=1
  perf report -i "$tmp/perf.data" --no-children --sort symbol --stdio 2>/dev/null | grep -v '^#' | grep -v '^$' | head -25
else
  collect=${2:-*}
  valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" --toggle-collect="$collect" \
    "$bench" --benchmark_filter="$filter" --benchmark_min_time=0.02
  # awk, not head: head would stop reading early, and pipefail end the script
  callgrind_annotate --auto=no "$tmp/cg.out" | sed -n '/file:function/,$p' | awk 'NR <= 25'
  # Per call: the collected total over the calls into the functions the
  # pattern names (callgrind writes a function's name once, then its number),
  # less what the binary's own checks before the benchmarks (main(): ours
  # against KDL on every problem) spend in them: a run that times nothing.
  per_call() {
    awk -v name="${collect//\*/}" '
      /^c?fn=\(/ {
        match($0, /^c?fn=\([0-9]+\)/)
        id = substr($0, index($0, "("), RLENGTH - index($0, "(") + 1)
        if (length($0) > RLENGTH) names[id] = substr($0, RLENGTH + 2)
        if ($0 ~ /^cfn=/) callee = names[id]
        next
      }
      /^calls=/ { split($1, a, "="); if (index(callee, name)) calls += a[2] }
      /^(summary|totals):/ { total = $2 }
      END { print total + 0, calls + 0 }' "$1"
  }
  if [[ $collect != '*' ]]; then
    valgrind --tool=callgrind --callgrind-out-file="$tmp/checks.out" --toggle-collect="$collect" \
      "$bench" --benchmark_filter='^$' >/dev/null 2>&1 || true  # no benchmark matches: the checks alone
    read -r total calls < <(per_call "$tmp/cg.out")
    read -r checks_total checks_calls < <(per_call "$tmp/checks.out")
    awk -v t="$total" -v c="$calls" -v t0="$checks_total" -v c0="$checks_calls" 'BEGIN {
      if (c > c0) printf "%d instructions in %d calls: %.0f per call\n", t - t0, c - c0, (t - t0) / (c - c0) }'
  fi
fi
