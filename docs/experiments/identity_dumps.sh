#!/usr/bin/env bash
# The identity dumps: 14 runs whose final states (`run --dump`) a change that claims the same
# physics to the bit must leave byte-identical. Usage, from the repository's root:
#   docs/experiments/identity_dumps.sh BINARY OUT_DIR
# then `diff -r` two OUT_DIRs (or `cmp` file by file). About 3 minutes with a release build.
set -euo pipefail
bin=$1
out=$2
mkdir -p "$out"
run() {
    local name=$1
    shift
    "$bin" run --quiet --dump "$out/$name.json" "$@" > /dev/null
}
s=assets/scenes
for mode in continuous discrete; do
    for threads in 1 2; do
        run "gas30k-$mode-$threads" --scene $s/gas.ron --balls 30000 --steps 120 \
            --collisions $mode --threads $threads
    done
    run "pile3k-$mode" --scene $s/pile.ron --balls 3000 --steps 600 --collisions $mode
    run "mixed-$mode" --scene $s/mixed.ron --steps 600 --collisions $mode
done
run gas2k --scene $s/gas.ron --balls 2000 --steps 600
run pile30k-2 --scene $s/pile.ron --balls 30000 --steps 300 --threads 2
for scene in billiards demo newtons_cradle maxwell; do
    run "$scene" --scene $s/$scene.ron --steps 600
done
ls "$out" | wc -l
