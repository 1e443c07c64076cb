#!/bin/sh
# Builds and runs the QEMU instruction-count benchmark of one filter cycle.
set -e
cd "$(dirname "$0")"
CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-target}" cargo run --release
