#!/usr/bin/env bash
# The dashboard in a real browser: headless Chromium (Debian's package,
# installed here if absent) loads the page that `host-sim dashboard`
# serves from a capture made by `host-sim simulate` (a short lateral with
# two stations whose azimuth is undetermined), waits until the replay has
# ended, and checks the DOM against `host-sim decode` of the same capture:
# mode, an inclination with its sigma, the undetermined azimuth shown as
# the word (never a number), the frame counters, the stations, the page's
# bounded arrays; that the page's token is what commands need (curl).
# Then a run tied in, with a job's well plan: the plan view and the
# vertical section drawn (plan, stations, ellipses), the toolface curve
# through its wrap at 0 deg without a jump. Then it saves a screenshot of
# that run.
#   scripts/dashboard-browser-test.sh [path/to/host-sim]
# (default: builds target/debug/host-sim). Screenshot:
# $DASHBOARD_SCREENSHOT, default target/dashboard.png.
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${1:-}"
if [ -z "$bin" ]; then
  cargo build -q -p host-sim
  bin="${CARGO_TARGET_DIR:-target}/debug/host-sim"
fi
bin="$(realpath "$bin")"
screenshot="$(realpath -m "${DASHBOARD_SCREENSHOT:-${CARGO_TARGET_DIR:-target}/dashboard.png}")"
if ! command -v chromium >/dev/null; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
fi

work="$(mktemp -d)"
server=""
cleanup() {
  if [ -n "$server" ]; then kill "$server" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT

"$bin" simulate --motion lateral --plan host-sim/data/plans/qemu-short.json \
  -o "$work/run.bin" --depth-log "$work/depth.csv" >/dev/null 2>"$work/simulate.err" \
  || { cat "$work/simulate.err"; exit 1; }
"$bin" decode "$work/run.bin" >"$work/decode.txt"

# Serves a capture (the arguments after the dashboard's) on a free port,
# stopping the one served before: sets $server and $url.
serve() {
  if [ -n "$server" ]; then kill "$server" 2>/dev/null || true; fi
  "$bin" dashboard "$@" --http-port 0 >"$work/server.out" 2>&1 &
  server=$!
  url=""
  for _ in $(seq 100); do
    url="$(grep -o 'http://[^ ]*' "$work/server.out" || true)"
    [ -n "$url" ] && break
    sleep 0.1
  done
  [ -n "$url" ] || { echo "the dashboard did not start:"; cat "$work/server.out"; exit 1; }
}
serve --file "$work/run.bin" --speed 100 --depth "$work/depth.csv"

browse() {
  # The page closes its event stream once the replay has ended; until then
  # Chromium's virtual time waits for the stream, then runs the budget.
  timeout 60 chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --user-data-dir="$(mktemp -d -p "$work")" --virtual-time-budget=5000 "$@" "$url" \
    2>>"$work/chromium.err"
}
browse --dump-dom >"$work/dom.html" || { echo "chromium failed:"; tail -20 "$work/chromium.err"; exit 1; }

passed=0 failed=0
check() {
  local what="$1" ok="$2"
  if [ "$ok" = yes ]; then
    passed=$((passed + 1)); echo "ok: $what"
  else
    failed=$((failed + 1)); echo "FAIL: $what"
  fi
}
is() { if [ "$1" = "$2" ]; then echo yes; else echo no; fi; }
# The text of the element with this id.
cell() { sed -n "s/.*id=\"$1\"[^>]*>\([^<]*\)<.*/\1/p" "$work/dom.html" | head -1; }
# A number from host-sim decode's summary.
decoded() { sed -n "$1" "$work/decode.txt" | head -1; }

good="$(decoded 's/^frames *\([0-9]*\) good.*/\1/p')"
stations="$(decoded 's/.*station survey \([0-9]*\).*/\1/p')"
raw="$(decoded 's/.*raw sample \([0-9]*\),.*/\1/p')"
lost="$(decoded 's/^sequence gaps *\([0-9]*\) frames lost.*/\1/p')"
restarts="$(decoded 's/^sequence gaps.*, \([0-9]*\) restarts.*/\1/p')"
crc="$(decoded 's/^corrupt *\([0-9]*\) CRC failures.*/\1/p')"
malformed="$(decoded 's/^corrupt.*, \([0-9]*\) malformed.*/\1/p')"
undetermined_stations="$(grep -c '^probe station.*azimuth undetermined' "$work/decode.txt" || true)"

check "the replay reached its end in the page" "$(grep -q 'data-finished="true"' "$work/dom.html" && echo yes || echo no)"
check "mode is nav ($(cell mode))" "$(is "$(cell mode)" nav)"
check "inclination with its sigma ($(cell inclination))" \
  "$(echo "$(cell inclination)" | grep -Eq '^[0-9]+\.[0-9]+ \+- [0-9]+\.[0-9]+ deg$' && echo yes || echo no)"
check "toolface with its sigma ($(cell toolface))" \
  "$(echo "$(cell toolface)" | grep -Eq '^[0-9]+\.[0-9]+ \+- [0-9]+\.[0-9]+ deg$' && echo yes || echo no)"
check "azimuth shown as undetermined ($(cell azimuth))" "$(is "$(cell azimuth)" undetermined)"
check "good frames as decoded ($good)" "$(cell frames | grep -q "^$good (raw $raw," && echo yes || echo no)"
check "lost as decoded ($lost)" "$(is "$(cell lost)" "$lost")"
check "CRC failures as decoded ($crc)" "$(is "$(cell crc)" "$crc")"
check "malformed as decoded ($malformed)" "$(is "$(cell malformed)" "$malformed")"
check "restarts as decoded ($restarts)" "$(is "$(cell restarts)" "$restarts")"
rows="$(grep -o '<td class="station-azimuth[^"]*">[^<]*</td>' "$work/dom.html" || true)"
check "$stations stations listed" "$(is "$(echo "$rows" | grep -c station-azimuth)" "$stations")"
check "$undetermined_stations station azimuths shown as undetermined, none as a number" \
  "$(is "$(echo "$rows" | grep -c '>undetermined<')" "$undetermined_stations")"
check "the page holds every sample, within its bound ($(cell held))" \
  "$(cell held | grep -q "^$raw samples, $raw solutions (at most 12000)" && echo yes || echo no)"

# The page holds this run's token; commands need it, and another site's
# name (DNS rebinding) gets nothing.
token="$(sed -n 's/.*<meta name="probe-token" content="\([0-9a-f]*\)".*/\1/p' "$work/dom.html" | head -1)"
check "the page holds a 64-digit token" "$(is "${#token}" 64)"
status() { curl -s -o /dev/null -w '%{http_code}' "$@"; }
check "a command without the token is refused (403)" "$(is "$(status -X POST "${url}api/align")" 403)"
check "a command with a wrong token is refused (403)" \
  "$(is "$(status -X POST -H "X-Probe-Token: ${token//?/0}" "${url}api/align")" 403)"
check "the page's command gets past the token (409: replaying, nothing to command)" \
  "$(is "$(status -X POST -H "X-Probe-Token: $token" "${url}api/align")" 409)"
check "another site's name gets nothing (421)" \
  "$(is "$(status -H 'Host: attacker.example' "$url")" 421)"

# The well drawn: a run tied in (azimuth determined) whose job has a well
# plan, replayed with its depth log: the plan view and the vertical
# section hold the plan, the stations placed and their ellipses; the
# toolface curve (crossing 0 deg in this run) never jumps across the chart.
cat >"$work/job.json" <<EOF
{ "format": "mwd-job", "version": 1,
  "site": { "latitude_deg": 45.77755, "longitude_deg": 126.687898, "height_m": 124.0 },
  "plan": "$PWD/host-sim/data/plans/qemu-short.json",
  "tie_in": { "inclination_deg": 90.0, "azimuth_deg": 120.0, "toolface_deg": 0.0,
              "inclination_sigma_deg": 0.1, "azimuth_sigma_deg": 0.5, "toolface_sigma_deg": 0.3 },
  "survey": { "tie_on": { "md": 3000.0, "tvd": 2450.0, "north": 420.0, "east": 310.0 } } }
EOF
"$bin" simulate --motion lateral --plan host-sim/data/plans/qemu-short.json --seed 3 \
  -o "$work/tied.bin" --depth-log "$work/tied.csv" --tie-in-job "$work/job.json" \
  >/dev/null 2>"$work/simulate.err" || { cat "$work/simulate.err"; exit 1; }
serve --file "$work/tied.bin" --speed 100 --depth "$work/tied.csv" --job "$work/job.json"
browse --dump-dom >"$work/well.html" || { echo "chromium failed:"; tail -20 "$work/chromium.err"; exit 1; }
# The drawing inside the svg with this id; how many of an element it has.
svg() { sed -n "s/.*\(<svg id=\"$1\".*\)/\1/p" "$work/well.html" | sed 's#</svg>.*##'; }
count() { grep -o "$2" <<<"$1" | wc -l; }
placed="$(grep -o '<td>N [-0-9.]* +- ' "$work/well.html" | wc -l)"
check "the tied-in run's stations are placed ($placed)" "$([ "$placed" -ge 2 ] && echo yes || echo no)"
for view in plan-view section-view; do
  drawn="$(svg "$view")"
  plan_points="$(sed -n 's/.*class="well-plan" points="\([^"]*\)".*/\1/p' <<<"$drawn" | wc -w)"
  check "$view: the well plan drawn ($plan_points points)" "$([ "$plan_points" -ge 2 ] && echo yes || echo no)"
  check "$view: every placed station drawn" "$(is "$(count "$drawn" '<circle class="station"')" "$placed")"
  check "$view: the stations joined" "$(is "$(count "$drawn" '<polyline class="stations"')" 1)"
  check "$view: an ellipse per placed station" "$(is "$(count "$drawn" '<ellipse class="ellipse"')" "$placed")"
  check "$view: axes with numbers" "$([ "$(count "$drawn" '<text')" -ge 6 ] && echo yes || echo no)"
done
wraps="$(sed -n 's/.*data-toolface-wraps="\([0-9]*\)".*/\1/p' "$work/well.html")"
max_step="$(sed -n 's/.*data-toolface-max-step="\([0-9.]*\)".*/\1/p' "$work/well.html")"
check "the toolface crosses 0 deg in this run ($wraps times)" "$([ "${wraps:-0}" -gt 0 ] && echo yes || echo no)"
check "no toolface step drawn across the chart (largest $max_step deg)" \
  "$(awk -v m="${max_step:-999}" 'BEGIN { print (m < 180) ? "yes" : "no" }')"

mkdir -p "$(dirname "$screenshot")"
rm -f "$screenshot"
browse --hide-scrollbars --window-size=1400,1900 --screenshot="$screenshot" >/dev/null \
  || { echo "chromium failed:"; tail -20 "$work/chromium.err"; exit 1; }
check "screenshot saved ($screenshot)" \
  "$(head -c 8 "$screenshot" 2>/dev/null | od -An -c | grep -q 'P   N   G' && echo yes || echo no)"

echo "dashboard browser test: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
