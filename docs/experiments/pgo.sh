#!/usr/bin/env bash
# Experiment (twenty-eighth session, not kept): a profile-guided build of the headless binary
# against a plain one, each in a target directory of its own under /tmp. Needs the toolchain's
# llvm-profdata (`rustup component add llvm-tools`); about 2 minutes a build here.
# Usage: docs/experiments/pgo.sh   (then compare the two binaries it names, alternately)
set -euo pipefail
cd "$(dirname "$0")/../.."
profdata=$(ls "$(rustc --print sysroot)"/lib/rustlib/*/bin/llvm-profdata)
rm -rf /tmp/pgo-data && mkdir -p /tmp/pgo-data
RUSTFLAGS="-Cprofile-generate=/tmp/pgo-data" \
    cargo build --release --no-default-features --target-dir /tmp/pgo-gen
train=/tmp/pgo-gen/release/ballpit
# The training: both modes at the bench's sizes, one and two threads, and a pile.
for mode in continuous discrete; do
    $train bench-one --balls 100000 --steps 60 --threads 1 --collisions $mode > /dev/null
    $train bench-one --balls 100000 --steps 30 --threads 2 --collisions $mode > /dev/null
    $train bench-one --balls 1000000 --steps 8 --threads 1 --collisions $mode > /dev/null
    $train bench-one --balls 1000 --steps 300 --threads 1 --collisions $mode > /dev/null
done
$train run --scene assets/scenes/pile.ron --balls 3000 --steps 300 --quiet --json > /dev/null
"$profdata" merge -o /tmp/pgo.profdata /tmp/pgo-data
RUSTFLAGS="-Cprofile-use=/tmp/pgo.profdata" \
    cargo build --release --no-default-features --target-dir /tmp/pgo-use
cargo build --release --no-default-features --target-dir /tmp/pgo-base
echo "profile-guided: /tmp/pgo-use/release/ballpit   plain: /tmp/pgo-base/release/ballpit"
