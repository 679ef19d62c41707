#!/usr/bin/env bash
# Where one benchmark spends its time: perf (sampling) when it works here,
# otherwise valgrind's callgrind restricted to the timed function.
#
#   bash bench/profile.sh '^ours_hd_m6/N=7$'                       # perf
#   bash bench/profile.sh '^ours_hd_m6/N=7$' '*solveHybridDynamics*' # callgrind, collecting inside that function
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
  callgrind_annotate --auto=no "$tmp/cg.out" | sed -n '/file:function/,$p' | head -25
fi
