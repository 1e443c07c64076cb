#!/bin/sh
# README's grade table and docs/results/grade-table.csv, regenerated in
# one command: the lateral study of every gyro grade on both built-in
# wells (`host-sim study grade-table`, its options passed on), from the
# repository's root. Nothing is written unless every run succeeded.
#
#   scripts/grade-table.sh --runs 20 --runs-1000m 10 --threads 2
set -eu
cd "$(dirname "$0")/.."
cargo build --release --quiet -p host-sim
exec "${CARGO_TARGET_DIR:-target}/release/host-sim" study grade-table "$@"
