#!/usr/bin/env bash
# The bad-input matrix: runs host-sim over bad files and bad
# arguments and counts, per case, a panic (exit 101), a silent acceptance
# (exit 0 where the input must be refused), an unbounded error (more than
# 4 KiB on standard error) and, for the good controls, a refusal of good
# input. Each run is limited to 1 GiB of output file and 120 s. Prints one line per failing case and the counts; exits 1 if any
# count is not zero.
#   scripts/bad-input-matrix.sh [path/to/host-sim]   (default: builds target/debug/host-sim)
set -uo pipefail
cd "$(dirname "$0")/.."
bin="${1:-}"
if [ -z "$bin" ]; then
  cargo build -q -p host-sim || exit 1
  bin="${CARGO_TARGET_DIR:-target}/debug/host-sim"
fi
bin="$(realpath "$bin")"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"

cases=0 panics=0 silent=0 noisy=0 refused_good=0
# expect fail|ok, then the arguments.
run() {
  local expect="$1"; shift
  cases=$((cases + 1))
  # A run without bound (a file past 1 GiB, more than 120 s) is stopped
  # and counted as accepted: it should have been refused at once.
  (ulimit -f 1048576; exec timeout 120 "$bin" "$@") >out.txt 2>err.txt </dev/null
  local code=$? size
  size=$(wc -c <err.txt)
  if [ "$code" = 124 ] || [ "$code" = 153 ]; then
    silent=$((silent + 1)); echo "UNBOUNDED  $* (stopped: exit $code)"
  elif [ "$code" = 101 ]; then
    panics=$((panics + 1)); echo "PANIC      $*"
  elif [ "$expect" = fail ] && [ "$code" = 0 ]; then
    silent=$((silent + 1)); echo "ACCEPTED   $*"
  elif [ "$expect" = ok ] && [ "$code" != 0 ]; then
    refused_good=$((refused_good + 1)); echo "REFUSED    $*: $(head -c 200 err.txt)"
  fi
  if [ "$size" -gt 4096 ]; then
    noisy=$((noisy + 1)); echo "NOISY      $* ($size bytes on stderr)"
  fi
}

# Good inputs the bad ones are made from.
"$bin" simulate --duration 30 -o good.csv 2>/dev/null
"$bin" simulate --duration 30 -o good.bin 2>/dev/null
"$bin" simulate --print-sensor-model >model.json
"$bin" arfit good.csv --rate 20 --output good.ar.json >/dev/null 2>&1

# --- calibration files (align, simulate, replay load them) ---
cal() { # bias scale axis correction-rows triads-count
  local triad="{\"columns\":[\"ax\",\"ay\",\"az\"],\"bias\":[$1,0,0],\"correction\":[$4]}"
  local triads="" i
  for ((i = 0; i < $6; i++)); do triads="${triads:+$triads,}$triad"; done
  printf '{"format":"mwd-calibration","version":1,"method":"ls","latitude_deg":45,"gravity":9.806,"accel":[%s],"gyro":[{"column":"gz","axis":"%s","bias":%s,"scale":%s}]}\n' \
    "$triads" "$3" "$5" "$2"
}
I='[1,0,0],[0,1,0],[0,0,1]'
cal 0.01 1.0 z "$I" 1e-5 1 >cal-good.json
cal 0.01 -1 z "$I" 1e-5 1 >cal-scale-neg.json
cal 0.01 1e-300 z "$I" 1e-5 1 >cal-scale-tiny.json
cal 0.01 1.0 z '[1,1,0],[1,1,0],[0,0,1]' 1e-5 1 >cal-singular.json
cal 0.01 1.0 z '[1e300,0,0],[0,1e300,0],[0,0,1e300]' 1e-5 1 >cal-huge-matrix.json
cal 1e308 1.0 z "$I" 1e-5 1 >cal-accel-bias.json
cal 0.01 1.0 z "$I" 1e308 1 >cal-gyro-bias.json
cal 0.01 1.0 q "$I" 1e-5 1 >cal-axis.json
cal 0.01 1.0 z "$I" 1e-5 3 >cal-extra-triads.json
cal 0.01 1.0 z "$I" 1e-5 0 >cal-no-triads.json
: >empty.json
printf 'not json' >text.json
head -c 4096 /dev/urandom >random.json
head -c 2097152 /dev/zero | tr '\0' ' ' >big.json
for f in cal-scale-neg cal-scale-tiny cal-singular cal-huge-matrix cal-accel-bias cal-gyro-bias \
  cal-axis cal-extra-triads cal-no-triads empty text random big; do
  run fail align good.csv --calibration-file "$f.json"
  run fail simulate --duration 1 -o sim.csv --calibration-file "$f.json"
  run fail replay good.bin --calibration-file "$f.json"
done
run ok align good.csv --calibration-file cal-good.json

# --- AR model files (paper mgwd --ar-models) ---
ar() { # the first model's variance and coefficients; four good models after it
  local entry='{"sensor":"%s","quantity":"%s","method":"yule-walker","order":%s,"sample_rate_hz":20.0,"coefficients":[%s],"noise_variance":%s,"noise_variance_unit":"SI"}'
  local first rest="" s
  # shellcheck disable=SC2059
  first=$(printf "$entry" accel_x_m_s2 specific-force "$(($(tr -cd , <<<"$2" | wc -c) + 1))" "$2" "$1")
  for s in accel_y_m_s2:specific-force:0.003 accel_z_m_s2:specific-force:0.003 \
    gyro_x_rad_s:angular-rate:1e-6 gyro_z_rad_s:angular-rate:1e-6; do
    IFS=: read -r name quantity variance <<<"$s"
    # shellcheck disable=SC2059
    rest="$rest,$(printf "$entry" "$name" "$quantity" 4 0.1,0,0,0 "$variance")"
  done
  printf '{"format":"mwd-ar-models","version":1,"models":[%s%s]}\n' "$first" "$rest"
}
ar 0.003 0.1,0,0,0 >ar-good.json
ar 1e300 0.1,0,0,0 >ar-huge-variance.json
ar 0 0.1,0,0,0 >ar-zero-variance.json
ar -1 0.1,0,0,0 >ar-negative-variance.json
ar 0.003 -0.9999999,0,0,0 >ar-near-unit-root.json
ar 0.003 0,0,0,-1.5 >ar-not-stationary.json
ar 0.003 null,0,0,0 >ar-null.json
for f in ar-huge-variance ar-zero-variance ar-negative-variance ar-near-unit-root ar-not-stationary \
  ar-null empty text random big; do
  run fail paper mgwd --ar-models "$f.json" --paper-derived-rate
done
run ok paper mgwd --ar-models ar-good.json --paper-derived-rate

# --- sensor-model files (simulate, align) ---
sed 's/"correlation_time_s": 100.0/"correlation_time_s": 0.0/' model.json >model-tau0.json
sed 's/"arw_deg_per_sqrt_h": [0-9.e-]*/"arw_deg_per_sqrt_h": 1e300/' model.json >model-arw.json
sed 's/"residual_bias_mg": [0-9.e-]*/"residual_bias_mg": -1/' model.json >model-negative.json
for f in model-tau0 model-arw model-negative empty text random big; do
  run fail simulate --duration 1 -o sim.csv --sensor-model "$f.json"
  run fail align good.csv --sensor-model "$f.json"
done
run ok simulate --duration 1 -o sim.csv --sensor-model model.json

# --- text tables (allan, arfit, calibrate, align) ---
: >empty.csv
head -1 good.csv >header-only.csv
head -c 8388608 /dev/zero | tr '\0' '1' >one-line.csv
head -c 1048576 /dev/zero >nul.csv
head -c 65536 /dev/urandom >random.csv
printf 'time_s,gyro_x_rad_s\n0,1\n0.05,x\n' >not-number.csv
printf 'time_s,gyro_x_rad_s\n0,1\n0.05,NaN\n' >nan.csv
printf 'time_s,gyro_x_rad_s\n0,1\n0.05,inf\n' >inf.csv
printf 'time_s,gyro_x_rad_s\n0,1\n0.05\n' >ragged.csv
for f in empty header-only one-line nul random not-number nan inf ragged; do
  run fail allan "$f.csv" --rate 20 --no-plot
  run fail arfit "$f.csv" --rate 20 --output out.ar.json
  run fail calibrate "$f.csv"
  run fail align "$f.csv"
done
awk 'NR == 1 { print; next } { printf "%s,%.17g\n", $1, 1e200 * (1 + ((NR * 7919) % 13 - 6) / 10) }' \
  FS=, good.csv | cut -d, -f1,2 >huge.csv
run fail arfit huge.csv --rate 20 --output out.ar.json
run ok allan huge.csv --rate 20 --no-plot
printf '\xef\xbb\xbf' >bom.csv
head -1 good.csv | sed 's/[^,]*/"&"/g' >>bom.csv
tail -n +2 good.csv >>bom.csv
run ok align bom.csv
run ok allan bom.csv --rate 20 --no-plot

# --- captures given to align ---
: >empty.bin
cp random.csv random.bin
cp good.csv csv.bin
for f in empty random csv; do run fail align "$f.bin"; done
run ok align good.bin

# --- arguments ---
for a in "--lat 95" "--lat nan" "--lat -91" "--lon 1e9" "--lon nan" "--height nan" "--height 1e9" \
  "--duration 1e9" "--duration 0" "--duration -1" "--duration nan" "--duration inf" \
  "--motion rotate --body-rate 0,3" "--motion rotate --body-rate 0,0,nan" \
  "--motion rotate --body-rate 0,0,1e6" "--motion toolface --dwell 1e9"; do
  # shellcheck disable=SC2086
  run fail simulate -o sim.csv $a
done
run fail replay --site nan 0 0 good.bin
run fail replay --site 95 0 0 good.bin
run fail align good.csv --lat 95
for r in 0 -1 nan inf; do
  run fail allan good.csv --rate "$r" --no-plot
  run fail arfit good.csv --rate "$r" --output out.ar.json
done
run ok simulate --motion rotate --body-rate 0,0,3 --duration 1 -o sim.csv

echo "bad-input matrix: $cases cases, $panics panics (exit 101), $silent silent acceptances," \
  "$noisy with more than 4 KiB on stderr, $refused_good good inputs refused"
[ $((panics + silent + noisy + refused_good)) = 0 ]
