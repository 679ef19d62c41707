#!/usr/bin/env bash
# Instructions per call (callgrind) of two builds of libzwang.a, case by case,
# and the ratio new/old: repeatable on a busy machine, where timings are not.
#
#   bash bench/instructions/compare.sh OLD_CHECKOUT NEW_CHECKOUT
#
# Each checkout needs its Release library at build-bench/src/libzwang.a (what
# bench/run.sh builds; for an old commit: git worktree add DIR COMMIT, then
# cmake -S DIR -B DIR/build-bench -DCMAKE_BUILD_TYPE=Release && cmake --build
# DIR/build-bench --target zwang). count.cpp (this folder, public API only) is
# compiled against each, with each checkout's own headers; the models are
# this checkout's. Needs valgrind (valgrind/callgrind.h).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
old=${1:?usage: compare.sh OLD_CHECKOUT NEW_CHECKOUT}
new=${2:?usage: compare.sh OLD_CHECKOUT NEW_CHECKOUT}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for side in old new; do
  checkout=${!side}
  g++ -O3 -DNDEBUG -std=c++17 -I"$checkout/include" -isystem /usr/include/eigen3 "$here/count.cpp" \
    "$checkout/build-bench/src/libzwang.a" -lurdfdom_model -lconsole_bridge -ltinyxml -o "$tmp/count_$side"
  mkdir "$tmp/$side"
  valgrind --tool=callgrind --instr-atstart=no --callgrind-out-file="$tmp/$side/cg.%p" \
    "$tmp/count_$side" "$root/models" >/dev/null 2>"$tmp/$side.log"
done
python3 - "$tmp" <<'PY'
import glob, re, sys
def counts(folder):
    out = {}
    for path in glob.glob(folder + "/cg.*"):
        text = open(path).read()
        name = re.search(r"^desc: Trigger: Client Request: (\S+)", text, re.M)
        total = re.search(r"^totals: (\d+)", text, re.M)
        if name and total:
            out[name.group(1)] = int(total.group(1)) / 100  # count.cpp's kCalls
    return out
old, new = counts(sys.argv[1] + "/old"), counts(sys.argv[1] + "/new")
print("| case | old | new | new/old |\n|---|---|---|---|")
for name in sorted(new):
    if name in old:
        print(f"| {name} | {old[name]:.0f} | {new[name]:.0f} | {new[name] / old[name]:.3f} |")
PY
