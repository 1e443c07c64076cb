#!/usr/bin/env bash
# Budget figures of the QEMU probe (docs/budgets.md): flash and static RAM
# (arm-none-eabi-size), and from one simulated static minute under
# `-icount shift=0,sleep=off` the stack high-water mark (stack painting),
# instructions per 20 Hz cycle (SysTick counts, 40 instructions each) and
# the UART bytes per second; then the drilling run (the short plan drilled
# by the simulator, its sensor stream played to the probe's parts: the
# busiest cycles, a station's block and the drilling constraints); then
# flash and static RAM of the real board's build (`probe-stm32`, linked with
# the top-level memory.x).
set -euo pipefail
cd "$(dirname "$0")/.."

target=thumbv7em-none-eabihf
# absolute: the drilling run starts QEMU from its own scratch directory
target_dir="$(realpath -m "${CARGO_TARGET_DIR:-target}")/qemu-probe"
CARGO_TARGET_DIR="$target_dir" cargo build -q -p firmware --profile probe --target "$target" \
  --features board-qemu --bin probe-qemu
elf="$target_dir/$target/probe/probe-qemu"

# The sections of ELF $1, then flash (vector table + text + rodata + data)
# and static RAM (data + bss + uninit), each followed by $2 and $3 (the budget).
sizes() {
  arm-none-eabi-size -A "$1" | grep -E '^\.(vector_table|text|rodata|data|bss|uninit) '
  arm-none-eabi-size -A "$1" | awk -v flash_of="$2" -v ram_of="$3" '
    $1 ~ /^\.(vector_table|text|rodata|data)$/ { flash += $2 }
    $1 ~ /^\.(data|bss|uninit)$/ { ram += $2 }
    END { printf "flash %d B (%.1f KiB)%s, static RAM %d B (%.1f KiB)%s\n", flash, flash/1024, flash_of, ram, ram/1024, ram_of }'
}

echo "== sections (arm-none-eabi-size -A $elf)"
sizes "$elf" "" ""

serial="$(mktemp)"
trap 'rm -f "$serial"' EXIT
echo "== one simulated minute in QEMU"
qemu-system-arm -M mps2-an386 -cpu cortex-m4 -nographic \
  -semihosting-config enable=on,target=native -serial "file:$serial" \
  -icount shift=0,sleep=off -kernel "$elf" | grep -o 'probe-qemu: .*' | tr ' ' '\n'
bytes=$(stat -c %s "$serial")
echo "uart_bytes=$bytes uart_bytes_per_s=$((bytes / 60)) (of 11520 at 115200 baud 8N1)"

echo "== the drilling run in QEMU (host-sim/data/plans/qemu-short.json, seed 1)"
run_dir="$(mktemp -d)"
trap 'rm -f "$serial"; rm -rf "$run_dir"' EXIT
cargo build -q --release -p host-sim
"${CARGO_TARGET_DIR:-target}/release/host-sim" simulate --motion lateral --seed 1 \
  --plan host-sim/data/plans/qemu-short.json --sensor-stream "$run_dir/sensor-stream.bin" \
  --output "$run_dir/host.bin" >/dev/null
CARGO_TARGET_DIR="$target_dir" cargo build -q -p firmware --profile probe --target "$target" \
  --features qemu-drilling --bin probe-qemu
(cd "$run_dir" && qemu-system-arm -M mps2-an386 -cpu cortex-m4 -nographic \
  -semihosting-config enable=on,target=native -serial null \
  -icount shift=0,sleep=off -kernel "$elf") | grep -o 'probe-qemu: .*' | tr ' ' '\n' |
  grep -E '^(samples|cycle_|stack_|frames_dropped|nav_samples_dropped)'

stm32_dir="${CARGO_TARGET_DIR:-target}"
cargo build -q -p firmware --profile probe --target "$target" --features board-stm32 --bin probe-stm32
elf="$stm32_dir/$target/probe/probe-stm32"
echo "== real board (arm-none-eabi-size -A $elf)"
sizes "$elf" " of 256 KiB" " of 32 KiB"
