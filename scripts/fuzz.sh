#!/usr/bin/env bash
# The readers' fuzz targets (host-sim/tests/fuzz_readers.rs) at volume:
# CASES cases per target (default 75,000: over a million over the 14
# targets), release build. Prints the targets, the total number of cases
# run and the test result; exits non-zero on any failure (a panic, or an
# error without a message).
#   scripts/fuzz.sh [CASES]
set -euo pipefail
cd "$(dirname "$0")/.."
cases="${1:-75000}"
cargo test -q --release -p host-sim --test fuzz_readers --no-run
targets=$(cargo test -q --release -p host-sim --test fuzz_readers -- --list 2>/dev/null | grep -c ': test$')
start=$(date +%s)
PROPTEST_CASES="$cases" cargo test -q --release -p host-sim --test fuzz_readers
echo "fuzz: $targets targets x $cases cases = $((targets * cases)) cases in $(($(date +%s) - start)) s, no panic"
