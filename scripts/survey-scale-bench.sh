#!/usr/bin/env bash
# The survey at scale, measured (figures, not a test; docs/survey-benchmarks.md):
#  1. 10,001 stations with the ISCWSA MWD Rev 5 model, whole process against
#     whole process: `host-sim survey` (listing to /dev/null, CSV written)
#     and welleng 0.30 from PyPI (scripts/bench/welleng_survey.py: read,
#     position, covariance, CSV), alternated, 7 runs each; the medians'
#     ratio, and the two surveys' last station compared.
#  2. 1,000,000 stations with the same model: peak RSS and wall time
#     (/usr/bin/time -v) of `host-sim survey`, which streams the file.
# Usage: scripts/survey-scale-bench.sh [HOST_SIM]   (default: a release build)
set -euo pipefail
cd "$(dirname "$0")/.."
HS=${1:-}
if [ -z "$HS" ]; then
  cargo build --release -p host-sim >&2
  HS=target/release/host-sim
fi
WORK=target/survey-scale-bench
mkdir -p "$WORK"
VENV=$WORK/venv
if [ ! -x "$VENV/bin/python" ]; then
  python3 -m venv "$VENV"
  "$VENV/bin/pip" install -q -r scripts/bench/requirements-welleng.txt
fi
python3 scripts/bench/make_stations.py 10001 "$WORK/s10001.csv"
python3 scripts/bench/make_stations.py 1000001 "$WORK/s1m.csv"
SITE=(--error-model "ISCWSA MWD Rev5" --lat 60 --b-total-nt 50000 --dip-deg 72 --declination-deg -4)

seconds() { # wall seconds of a command, its output discarded
  local t0 t1
  t0=$(date +%s%N)
  "$@" > /dev/null
  t1=$(date +%s%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.4f\n", (b - a) / 1e9}'
}
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }

echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs); load: $(cut -d' ' -f1-3 /proc/loadavg)"
hs=(); wl=()
for _ in 1 2 3 4 5 6 7; do
  hs+=("$(seconds "$HS" survey "$WORK/s10001.csv" "${SITE[@]}" --csv "$WORK/hs.csv")")
  wl+=("$(seconds "$VENV/bin/python" scripts/bench/welleng_survey.py "$WORK/s10001.csv" "$WORK/wl.csv")")
done
hs_med=$(printf '%s\n' "${hs[@]}" | median)
wl_med=$(printf '%s\n' "${wl[@]}" | median)
awk -v h="$hs_med" -v w="$wl_med" 'BEGIN {
  printf "10,001 stations, whole process, median of 7: host-sim %.3f s, welleng 0.30 %.3f s: %.1fx\n", h, w, w / h }'
python3 - "$WORK/hs.csv" "$WORK/wl.csv" <<'PY'
import csv, math, sys
hs = list(csv.DictReader(open(sys.argv[1])))[-1]
wl = list(csv.DictReader(open(sys.argv[2])))[-1]
d = max(abs(float(hs[k]) - float(wl[k])) for k in ("north_m", "east_m", "tvd_m"))
s = max(abs(float(hs[a]) / math.sqrt(float(wl[b])) - 1)
        for a, b in (("sigma_north_m", "var_nn"), ("sigma_east_m", "var_ee")))
print(f"last station: positions differ by {d:.2e} m, north/east sigmas by {100 * s:.3f} %")
PY
/usr/bin/time -v "$HS" survey "$WORK/s1m.csv" "${SITE[@]}" --csv "$WORK/hs1m.csv" \
  > /dev/null 2> "$WORK/time-1m.txt"
rss=$(awk -F: '/Maximum resident/ {print $2}' "$WORK/time-1m.txt" | xargs)
wall=$(awk -F': ' '/Elapsed/ {print $2}' "$WORK/time-1m.txt")
echo "1,000,000 stations: peak RSS $((rss / 1024)) MB ($rss kB), wall $wall, $(($(wc -l < "$WORK/hs1m.csv") - 1)) CSV rows"
