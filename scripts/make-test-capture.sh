#!/usr/bin/env bash
# Records tests/data/qemu-static-6s.bin, the small capture committed for
# replay (tests/tests/capture_replay.rs, README): the QEMU probe, built for a
# 6-simulated-second run (5 s of coarse alignment, then the first second
# of the fine alignment), with
# its UART captured through QEMU's `-serial file:`. Deterministic under
# `-icount shift=0`: the same tree records the same bytes. Run it again when
# the probe's navigation or wire format changes on purpose.
set -euo pipefail
cd "$(dirname "$0")/.."

target=thumbv7em-none-eabihf
# Its own directory: the run length is compiled in, and the end-to-end
# tests' 60 s build in .../qemu-probe should not be rebuilt back and forth.
target_dir="${CARGO_TARGET_DIR:-target}/qemu-capture"
PROBE_QEMU_RUN_SECONDS=6 CARGO_TARGET_DIR="$target_dir" cargo build -q -p firmware \
  --profile probe --target "$target" --features board-qemu --bin probe-qemu
out=tests/data/qemu-static-6s.bin
rm -f "$out"
qemu-system-arm -M mps2-an386 -cpu cortex-m4 -nographic \
  -semihosting-config enable=on,target=native -serial "file:$out" \
  -icount shift=0,sleep=off -kernel "$target_dir/$target/probe/probe-qemu"
echo "wrote $out ($(stat -c %s "$out") bytes)"
