#!/usr/bin/env bash
# Rounds of the two-thread figure at 100,000 balls, each with how far apart the host keeps
# the two cores: a cache line's round trip between cpu 0 and cpu 1 (pingpong.c, ns) before
# and after the round, one thread pinned to core 0, then two threads (ms a step, medians of
# 200 steps). Usage, from the repository's root:
#   gcc -O2 -pthread docs/experiments/pingpong.c -o /tmp/pingpong
#   docs/experiments/two_thread_rounds.sh BINARY MODE ROUNDS   (MODE: discrete or continuous)
# A/B of two builds: BINARY_B=other docs/experiments/two_thread_rounds.sh BINARY MODE ROUNDS
# adds that build's two-thread step after each round's.
set -euo pipefail
bin=$1 mode=$2 rounds=$3
median() { python3 -c "import json,sys; print(round(json.load(sys.stdin)['ms_per_step_median'],3))"; }
for _ in $(seq 1 "$rounds"); do
    before=$(/tmp/pingpong)
    one=$(taskset -c 0 "$bin" bench-one --balls 100000 --steps 200 --threads 1 --collisions "$mode" | median)
    two=$("$bin" bench-one --balls 100000 --steps 200 --threads 2 --collisions "$mode" | median)
    other=""
    if [ -n "${BINARY_B:-}" ]; then
        other=" two_b $("$BINARY_B" bench-one --balls 100000 --steps 200 --threads 2 --collisions "$mode" | median)"
    fi
    after=$(/tmp/pingpong)
    echo "$(date -u +%H:%M:%S) trip $before $after one $one two $two$other"
done
