#!/usr/bin/env bash
# The real board on the bench (README, "The real board"): flash probe-stm32
# through a debug probe (probe-rs), capture its UART with
# `host-sim replay --port DEV --save FILE` across a reset, and check the
# capture: one boot event (reset cause, configuration source and version
# decoded), raw frames at 20 Hz with consecutive sample counters, no
# corrupt frame. With --job, the configuration's round trip:
# `host-sim probe configure`, `probe status`, `probe reboot`, `probe status`
# again (the same version), then a second capture across a reset whose boot
# event must say "flash" and that version.
#
#   scripts/bench-probe.sh --port /dev/ttyUSB0 [--baud 115200] [--seconds 30]
#                          [--job JOB.json] [--no-flash] [--out DIR]
#   scripts/bench-probe.sh --check-capture FILE --seconds N
#                          [--expect-source defaults|flash] [--expect-version V]
#
# The second form only checks a capture already made (for example a QEMU
# probe's: the checks are the same). Exit status 0 when every check held,
# 1 when one failed, 2 on a usage or set-up problem (no probe-rs, no port).
# HOST_SIM may name a host-sim binary (default: a release build of it).
set -euo pipefail
cd "$(dirname "$0")/.."

chip=STM32F411CEUx
target=thumbv7em-none-eabihf
port="" baud=115200 seconds=30 job="" flash=1 out="" check_only=""
expect_source="" expect_version=""

usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2; exit 2; }
die() { echo "bench-probe: $*" >&2; exit 2; }
fail() { echo "bench-probe: FAILED: $*" >&2; exit 1; }

while [[ $# -gt 0 ]]; do
  case "$1" in
    --port) port="${2:?}"; shift 2 ;;
    --baud) baud="${2:?}"; shift 2 ;;
    --seconds) seconds="${2:?}"; shift 2 ;;
    --job) job="${2:?}"; shift 2 ;;
    --no-flash) flash=0; shift ;;
    --out) out="${2:?}"; shift 2 ;;
    --check-capture) check_only="${2:?}"; shift 2 ;;
    --expect-source) expect_source="${2:?}"; shift 2 ;;
    --expect-version) expect_version="${2:?}"; shift 2 ;;
    -h|--help) usage ;;
    *) echo "bench-probe: unknown argument $1" >&2; usage ;;
  esac
done
[[ "$seconds" =~ ^[0-9]+$ && "$seconds" -ge 5 ]] || die "--seconds must be a whole number >= 5"
[[ -z "$expect_version" || "$expect_version" =~ ^[0-9]+$ ]] || die "--expect-version must be a number"
case "$expect_source" in ""|defaults|flash) ;; *) die "--expect-source is defaults or flash" ;; esac

host_sim() {
  if [[ -z "${HOST_SIM:-}" ]]; then
    cargo build -q --release -p host-sim --bin host-sim
    HOST_SIM="${CARGO_TARGET_DIR:-target}/release/host-sim"
  fi
  "$HOST_SIM" "$@"
}

# The boot event's value (firmware/src/app/boot.rs): reset cause in bits
# 0-7, configuration source 8-15, version 16-31.
cause_name() {
  case "$1" in
    0) echo "not reported" ;; 1) echo power-on ;; 2) echo watchdog ;;
    3) echo software ;; 4) echo pin ;; 5) echo brown-out ;; *) echo "unknown ($1)" ;;
  esac
}
source_name() { case "$1" in 1) echo defaults ;; 2) echo flash ;; *) echo "not reported" ;; esac; }

# check_capture FILE SECONDS: the capture's checks; prints the boot event
# and sets BOOT_SOURCE and BOOT_VERSION.
check_capture() {
  local file="$1" secs="$2" csv summary status=0
  [[ -s "$file" ]] || fail "empty capture $file (nothing on the port? wiring, baud)"
  csv="$(mktemp)"
  # 2: written, but frames were lost (said below)
  summary="$(host_sim decode "$file" --csv "$csv")" || status=$?
  [[ "$status" -eq 0 || "$status" -eq 2 ]] || { rm -f "$csv"; fail "host-sim decode $file"; }
  echo "$summary"
  grep -q '^corrupt          0 CRC failures, 0 malformed' <<<"$summary" || { rm -f "$csv"; fail "corrupt frames"; }
  grep -q '^sequence gaps    0 frames lost' <<<"$summary" || { rm -f "$csv"; fail "frames lost on the line"; }
  # One pass over the CSV by column name: boot events, raw frames, and
  # sample counters consecutive within each boot.
  local facts
  facts="$(awk -F, '
    NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
    $col["kind"] == "event" && $col["event"] == 1 {
      boots++; value = $col["event_value"]; prev = ""; next }
    $col["kind"] == "raw" {
      raws++; c = $col["sample_counter"]
      if (prev != "" && c != prev + 1) gaps++
      prev = c }
    END { printf "%d %d %d %s\n", boots, raws, gaps, (boots ? value : -1) }' "$csv")"
  rm -f "$csv"
  local boots raws gaps value
  read -r boots raws gaps value <<<"$facts"
  [[ "$boots" -eq 1 ]] || fail "$boots boot events in the capture (one reset expected)"
  BOOT_SOURCE="$(source_name $(((value >> 8) & 255)))"
  BOOT_VERSION=$((value >> 16))
  echo "boot event       reset cause $(cause_name $((value & 255))), configuration $BOOT_SOURCE, version $BOOT_VERSION"
  # 20 Hz: every sample after the boot, allowing 2 s for the start-up.
  local least=$((20 * (secs - 2))) most=$((20 * secs + 1))
  echo "raw frames       $raws in $secs s (expected $least..$most at 20 Hz), $gaps counter gaps"
  [[ "$gaps" -eq 0 ]] || fail "sample counters not consecutive"
  [[ "$raws" -ge "$least" && "$raws" -le "$most" ]] || fail "not 20 Hz: $raws raw frames in $secs s"
  if [[ -n "$expect_source" && "$BOOT_SOURCE" != "$expect_source" ]]; then
    fail "configuration from $BOOT_SOURCE, expected $expect_source"
  fi
  if [[ -n "$expect_version" && "$BOOT_VERSION" -ne "$expect_version" ]]; then
    fail "configuration version $BOOT_VERSION, expected $expect_version"
  fi
}

if [[ -n "$check_only" ]]; then
  check_capture "$check_only" "$seconds"
  echo "bench-probe: capture checks passed"
  exit 0
fi

[[ -n "$port" ]] || die "give --port DEV (the USB-serial adapter on PA9/PA10), or --check-capture FILE"
[[ -e "$port" ]] || die "no serial port $port"
have_probe_rs=0
command -v probe-rs >/dev/null && have_probe_rs=1
if [[ "$flash" -eq 1 && "$have_probe_rs" -eq 0 ]]; then
  die "probe-rs is not installed (cargo install probe-rs-tools): install it, or flash the board \
another way and run again with --no-flash (then press the board's reset button when asked)"
fi
out="${out:-bench-$(date +%Y%m%d-%H%M%S)}"
mkdir -p "$out"

if [[ "$flash" -eq 1 ]]; then
  cargo build -q -p firmware --profile probe --target "$target" --features board-stm32 --bin probe-stm32
  elf="${CARGO_TARGET_DIR:-target}/$target/probe/probe-stm32"
  echo "== flashing $elf"
  probe-rs download --chip "$chip" "$elf"
fi

# capture FILE: the port for $seconds s across a reset of the board.
capture() {
  local file="$1"
  echo "== capturing $port for $seconds s into $file"
  host_sim replay --port "$port" --baud "$baud" --duration "$seconds" --save "$file" \
    >"$file.replay.txt" 2>&1 &
  local replay=$!
  sleep 1
  if [[ "$have_probe_rs" -eq 1 ]]; then
    probe-rs reset --chip "$chip"
  else
    echo "   press the board's reset button now"
  fi
  wait "$replay" || { cat "$file.replay.txt" >&2; fail "host-sim replay --port $port"; }
}

capture "$out/boot.bin"
check_capture "$out/boot.bin" "$seconds"

if [[ -n "$job" ]]; then
  echo "== configuration round trip ($job)"
  host_sim probe configure --job "$job" --port "$port" --baud "$baud" || fail "probe configure"
  status="$(host_sim probe status --port "$port" --baud "$baud")" || fail "probe status"
  echo "$status"
  version="$(sed -n 's/.*ACK, configuration version \([0-9]*\).*/\1/p' <<<"$status")"
  [[ -n "$version" ]] || fail "no configuration version in: $status"
  host_sim probe reboot --port "$port" --baud "$baud" || fail "probe reboot"
  sleep 3
  again="$(host_sim probe status --port "$port" --baud "$baud")" || fail "probe status after the reboot"
  echo "$again"
  grep -q "ACK, configuration version $version\b" <<<"$again" || fail "version $version not kept across the reboot"
  expect_source=flash expect_version="$version"
  capture "$out/after-configure.bin"
  check_capture "$out/after-configure.bin" "$seconds"
fi
echo "bench-probe: all checks passed (captures in $out)"
