#!/usr/bin/env bash
# Builds zwang_bench (Release, in build-bench/), runs it once with repetitions
# and writes docs/benchmarks.md (tables, the issue's ratios) and the log-log
# plot bench/results/cost_vs_n.png from the JSON it leaves in bench/results/.
#
#   bash bench/run.sh                    # the documented run (from the repository root or anywhere)
#   bash bench/run.sh --benchmark_filter='N=7$'   # extra arguments go to zwang_bench
#
# Environment: ZWANG_BENCH_BUILD_DIR (default build-bench), ZWANG_BENCH_REPETITIONS
# (default 5), ZWANG_BENCH_MIN_TIME (seconds per repetition, default 0.2).
# Run it on a quiet machine: the numbers are medians of CPU time, but a busy
# machine still shifts them.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${ZWANG_BENCH_BUILD_DIR:-$root/build-bench}
repetitions=${ZWANG_BENCH_REPETITIONS:-5}
min_time=${ZWANG_BENCH_MIN_TIME:-0.2}
results=$root/bench/results

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DZWANG_BUILD_BENCHMARKS=ON \
      -DZWANG_BUILD_TESTS=OFF -DZWANG_BUILD_DEMO=OFF >/dev/null
cmake --build "$build" --target zwang_bench -j"$(nproc)"

mkdir -p "$results"
load_before=$(cut -d' ' -f1 /proc/loadavg)
echo "load average before the run: $(cut -d' ' -f1-3 /proc/loadavg)"
if awk -v l="$load_before" -v n="$(nproc)" 'BEGIN { exit !(l > 0.5 * n) }'; then
  echo "warning: the machine is busy (load $load_before on $(nproc) cores); the numbers will be noisy" >&2
fi
"$build/bench/zwang_bench" \
  --benchmark_repetitions="$repetitions" \
  --benchmark_report_aggregates_only=true \
  --benchmark_min_time="$min_time" \
  --benchmark_out="$results/zwang_bench.json" \
  --benchmark_out_format=json \
  "$@"
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
echo "load average after the run: $load_after"
# The JSON is committed: record the binary relative to the checkout, not this machine's path.
sed -i "s|\"executable\": \"$root/|\"executable\": \"|" "$results/zwang_bench.json"

python3 "$root/bench/report.py" \
  --json "$results/zwang_bench.json" \
  --markdown "$root/docs/benchmarks.md" \
  --plot "$results/cost_vs_n.png" \
  --command "bash bench/run.sh${*:+ $*}" \
  --settings "repetitions $repetitions, min time $min_time s per repetition" \
  --load-after "$load_after"
echo "wrote $root/docs/benchmarks.md"
