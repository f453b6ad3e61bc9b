#!/bin/bash
# What the discrete step moves between the last-level cache and memory, by valgrind's cache
# model (callgrind, an LL cache of LL_BYTES, 16-way, 64-B lines): the three systems' LL misses
# and instructions a ball-step, by function. Two runs, 3 and 8 steps after bench-one's five
# warm-up steps, differenced, so the first steps' allocations fall out.
# Usage: discrete-traffic.sh BALLS LL_BYTES   (e.g. 1000000 33554432; BALLPIT=binary)
set -euo pipefail
balls=$1 ll=$2 out=$(mktemp -d)
for steps in 3 8; do
  valgrind --tool=callgrind --cache-sim=yes --D1=32768,8,64 --LL="$ll",16,64 \
    --collect-atstart=no \
    --toggle-collect='ballpit::sim::ball::BallSnapshot::fill_then' \
    --toggle-collect='ballpit::sim::discrete::detect::detect_contacts' \
    --toggle-collect='ballpit::sim::discrete::resolve::resolve_contacts' \
    --callgrind-out-file="$out/$steps.out" \
    "${BALLPIT:-target/release/ballpit}" bench-one --balls "$balls" --steps "$steps" \
    --threads 1 --collisions discrete > /dev/null 2> "$out/$steps.err"
  callgrind_annotate --inclusive=no --threshold=100 --show=DLmr,DLmw,Ir "$out/$steps.out" \
    2> /dev/null | grep -E '^ *[0-9,]+ ' > "$out/$steps.fn"
done
python3 - "$out/3.fn" "$out/8.fn" "$((5 * balls))" <<'PY'
import re, sys
from collections import defaultdict
def load(path):
    seen, rows = defaultdict(int), {}
    for line in open(path):
        m = re.match(r"\s*([\d,]+) (?:\([^)]*\))?\s*([\d,]+) (?:\([^)]*\))?\s*([\d,]+) (?:\([^)]*\))?\s*(.*)$", line)
        if m:
            name = re.sub(r"\?\?\?:| \[.*\]$|ballpit::sim::", "", m.group(4))
            rows[(name, seen[name])] = [int(m.group(i).replace(",", "")) for i in (1, 2, 3)]
            seen[name] += 1
    return rows
before, after, ball_steps = load(sys.argv[1]), load(sys.argv[2]), float(sys.argv[3])
print("lines a ball-step: read-miss write-miss (bytes)  instructions  function")
rows = []
for key, counts in after.items():
    was = before.get(key, [0, 0, 0])
    rows.append([(counts[i] - was[i]) / ball_steps for i in range(3)] + [key[0]])
for r, w, ir, name in sorted(rows, key=lambda row: -(row[0] + row[1]))[:12]:
    print("%5.2f %5.2f (%4.0f B) %6.1f  %s" % (r, w, 64 * (r + w), ir, name[:90]))
PY
rm -rf "$out"
