#!/usr/bin/env bash
# Instruction count of one filter cycle on a Cortex-M4F, in QEMU
# (mps2-an386, `-icount shift=0`: SysTick counts instructions), fast vs
# dense, f32 vs f64, 33 and 39 states (docs/filter-benchmarks.md). The bench
# is the firmware crate's `qemu-cycle-bench` binary (feature of the same
# name, `firmware/src/bin/cycle_bench/`), built with the `cycle-bench`
# profile: the filters at opt-level 3 with fat LTO.
set -euo pipefail
cd "$(dirname "$0")/.."

target=thumbv7em-none-eabihf
cargo build -q -p firmware --profile cycle-bench --target "$target" \
  --features qemu-cycle-bench --bin qemu-cycle-bench
elf="${CARGO_TARGET_DIR:-target}/$target/cycle-bench/qemu-cycle-bench"
qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic \
  -semihosting-config enable=on,target=native -icount shift=0 -kernel "$elf"
