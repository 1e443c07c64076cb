#!/usr/bin/env bash
# Golden outputs of the host tool: runs a set of representative host-sim
# commands (the README's, a tied-in lateral with its depth log, replay,
# survey, the studies in small, the papers, the noise tools, decode, the
# dashboard's state) and prints one line per output, `<sha256>  <name>`,
# sorted (LC_ALL=C), then `golden: N outputs`. Run it with the binary
# before and after a refactor that should not change behaviour (code
# moves): the texts must be identical.
#
#   scripts/golden-outputs.sh [--keep DIR] [HOST_SIM_BINARY]
#
# Without a binary it builds `cargo build --release -p host-sim` and uses
# ${CARGO_TARGET_DIR:-target}/release/host-sim. Everything runs in a
# `mktemp -d` directory, removed on exit; `--keep DIR` (a new or empty
# directory) keeps it there: DIR/golden holds exactly what was hashed
# (`diff -r` two kept runs to see what moved), DIR/run what the commands
# wrote (DIR/run/cmd: each command's stdout, then its stderr if any, then
# `exit=N`), DIR/hashes.txt the printed lines.
#
# What is hashed: every file the commands write and every command's
# stdout + stderr + exit status (a command expected to fail is run with
# its expected status, which is part of the hashed text). Binary outputs
# (.bin captures, PNG plots) as they are; text after normalisation
# (normalise() below): the temporary directory's path becomes <TMP>, the
# repository's <REPO>, the binary's <HOST_SIM>, the dashboard's port
# <PORT>, and what is not deterministic becomes <T>: wall-clock and CPU
# times, speeds (epochs per core-second, microseconds per filter step,
# the dashboard's frame rate), in the texts, the JSON (keys) and the CSV
# (columns). Progress bars are hidden (stderr is not a terminal) and
# dropped if any shows anyway. Nothing else needed stripping: two runs
# with the same binary give the same hashes (checked at the time of
# writing; the studies with 2 threads too).
#
# Needs python3 (the normalisation, and the HTTP client that reads the
# dashboard's state over loopback: no Rust code is added for it). Not
# covered: what needs a serial port, a probe or QEMU (`replay --port`,
# `dashboard --port`, `probe ...` beyond its help, `simulate
# --sensor-stream` replayed by the QEMU probe), and the long runs (the
# studies' 200-run defaults, the 1000 m lateral).
#
# About 2 min with a release binary on 2 shared cores (1m50-2m15 measured,
# load average 5-7 from other builds; 66 s of CPU).
set -euo pipefail

usage() { sed -n '10p' "$0" | sed 's/^#   /usage: /' >&2; }

keep=""
bin=""
while [ $# -gt 0 ]; do
  case "$1" in
    --keep) [ $# -ge 2 ] || { usage; exit 2; }; keep="$2"; shift 2 ;;
    --keep=*) keep="${1#--keep=}"; shift ;;
    -h | --help) usage; exit 0 ;;
    -*) echo "golden: unknown option $1" >&2; usage; exit 2 ;;
    *) [ -z "$bin" ] || { usage; exit 2; }; bin="$1"; shift ;;
  esac
done
if [ -n "$bin" ]; then
  [ -x "$bin" ] || { echo "golden: $bin is not an executable" >&2; exit 2; }
  bin="$(realpath "$bin")"
fi
if [ -n "$keep" ]; then
  keep="$(realpath -m "$keep")"
  if [ -e "$keep" ] && [ -n "$(ls -A "$keep")" ]; then
    echo "golden: --keep $keep is not empty" >&2
    exit 2
  fi
fi

cd "$(dirname "$0")/.."
repo="$(pwd -P)"
if [ -z "$bin" ]; then
  cargo build --release -p host-sim >&2
  bin="$(realpath "${CARGO_TARGET_DIR:-target}/release/host-sim")"
fi
H="$bin"

work="$(mktemp -d)"
dash_pid=""
cleanup() {
  local status=$?
  if [ -n "$dash_pid" ]; then kill "$dash_pid" 2>/dev/null || true; fi
  if [ -n "$keep" ]; then
    mkdir -p "$keep"
    cp -a "$work/." "$keep/"
    echo "golden: outputs kept in $keep" >&2
  fi
  rm -rf "$work"
  exit "$status"
}
trap cleanup EXIT
R="$work/run"
mkdir -p "$R"/{cmd,static,noise,calibration,paper,capture,lateral,tiein,survey,study,dashboard}
# Fixed surroundings: no terminal (no colour, no progress bar, clap's
# fixed help width), C locale.
export LC_ALL=C
unset COLUMNS LINES

# run NAME EXPECTED_EXIT ARGS...: host-sim ARGS; its stdout, stderr and
# exit status go to cmd/NAME.txt. Any other exit status fails the script.
run() {
  local name="$1" expect="$2" rc=0
  shift 2
  "$H" "$@" <"/dev/null" >"$R/cmd/$name.stdout" 2>"$R/cmd/$name.stderr" || rc=$?
  if [ "$rc" -ne "$expect" ]; then
    echo "golden: $name: host-sim $* exited $rc (expected $expect); stderr:" >&2
    cat "$R/cmd/$name.stderr" >&2
    exit 1
  fi
  {
    cat "$R/cmd/$name.stdout"
    if [ -s "$R/cmd/$name.stderr" ]; then
      printf -- '--- stderr ---\n'
      cat "$R/cmd/$name.stderr"
    fi
    printf 'exit=%d\n' "$rc"
  } >"$R/cmd/$name.txt"
  rm "$R/cmd/$name.stdout" "$R/cmd/$name.stderr"
}

# --- the command line itself: every subcommand's help ------------------
run help 0 --help
for sub in drill demo simulate decode replay align allan arfit calibrate observability survey \
  dashboard study paper probe "study drilling-coverage" "study rins-probe" "study lateral" \
  "paper tls" "paper mgwd" "paper rins" "probe configure" "probe status"; do
  # shellcheck disable=SC2086 # the subcommand's words
  run "help-${sub// /-}" 0 $sub --help
done

# --- README: static simulation, toolface indexing, coarse alignment ----
run demo 0 demo
run simulate-static 0 simulate -o "$R/static/static.csv"
run simulate-indexed 0 simulate --motion toolface --dwell 600 -o "$R/static/indexed.csv"
run align-indexed 0 align "$R/static/indexed.csv" --prior-heading -120
run align-static-5s 0 align "$R/static/static.csv" --first 5
run simulate-stdout 0 simulate --duration 2 --seed 9 -o -
run simulate-sensor-model 0 simulate --print-sensor-model

# --- README: noise analysis, AR models, six-position calibration -------
run simulate-long 0 simulate --duration 3000 -o "$R/noise/long.csv"
run allan 0 allan "$R/noise/long.csv" --rate 20
run allan-json 0 allan "$R/noise/long.csv" --rate 20 --json --no-plot
run arfit 0 arfit "$R/noise/long.csv" --rate 20
run arfit-json-burg 0 arfit "$R/noise/long.csv" --rate 20 --method burg --json \
  --output "$R/noise/long.burg.ar.json"
run simulate-six 0 simulate --motion six-position --dwell 60 -o "$R/calibration/six.csv"
run calibrate 0 calibrate "$R/calibration/six.csv"
run simulate-calibrated 0 simulate --calibration-file "$R/calibration/six.cal.json" \
  -o "$R/calibration/calibrated.csv"
run align-calibrated 0 align "$R/calibration/calibrated.csv" \
  --calibration-file "$R/calibration/six.cal.json"

# --- README's main job: the example lateral drilled and surveyed -------
run drill 0 drill --out "$R/drill"

# --- the papers (`paper mgwd` as it is) -------------------------------
run paper-mgwd 0 paper mgwd
run paper-mgwd-plots 0 paper mgwd --plots "$R/paper/mgwd-plots"
run paper-mgwd-ar-models 0 paper mgwd --ar-models "$R/noise/long.ar.json" --paper-derived-rate
run paper-tls 0 paper tls
run paper-tls-json 0 paper tls --json --runs 50
run paper-rins-plot 0 paper rins --plot "$R/paper/rins-plots"
run paper-rins-arw 0 paper rins --gyro-arw 0.0001
run paper-rins-json 0 paper rins --json --hours 40
run paper-rins-strapdown 0 paper rins --strapdown-check
run observability 0 observability
run observability-indexing 0 observability --toolfaces 0,90,180,270

# --- captures: simulate to .bin, decode, replay ------------------------
run simulate-bin 0 simulate --duration 60 -o "$R/capture/run.bin"
run decode-run 0 decode "$R/capture/run.bin" --csv "$R/capture/run-frames.csv"
run align-bin 0 align "$R/capture/run.bin" --calibration none
run decode-qemu 0 decode tests/data/qemu-static-6s.bin --csv "$R/capture/qemu-frames.csv"
run decode-qemu-summary 0 decode tests/data/qemu-static-6s.bin
run replay-qemu 0 replay tests/data/qemu-static-6s.bin --csv "$R/capture/qemu-replay.csv"

# --- README: the 100 m lateral, its replay and survey ------------------
run lateral-simulate 0 simulate --motion lateral --plan host-sim/data/plans/lateral-100m.json \
  --seed 7 -o "$R/lateral/run.bin" --truth "$R/lateral/truth.csv" --depth-log "$R/lateral/depth.csv"
run lateral-replay 0 replay "$R/lateral/run.bin"
run lateral-survey 0 survey "$R/lateral/run.bin" --depth "$R/lateral/depth.csv" \
  --tie-on-md 3000 --tie-on-tvd 2450 --tie-on-north 420 --tie-on-east 310 \
  --csv "$R/lateral/stations.csv" --trajectory "$R/lateral/trajectory.csv"

# --- a short lateral drilled by a probe tied in by a job ---------------
# (the job of host-sim/tests/drilling_survey.rs)
cat >"$R/tiein/job.json" <<'EOF'
{ "format": "mwd-job", "version": 1,
  "site": { "latitude_deg": 45.77755, "longitude_deg": 126.687898, "height_m": 124.0 },
  "tie_in": { "inclination_deg": 90.0, "azimuth_deg": 120.0, "toolface_deg": 0.0,
              "inclination_sigma_deg": 0.1, "azimuth_sigma_deg": 0.5, "toolface_sigma_deg": 0.3 },
  "survey": { "tie_on": { "md": 3000.0, "tvd": 2450.0, "north": 420.0, "east": 310.0 } } }
EOF
T="$R/tiein"
run tiein-simulate 0 simulate --motion lateral --plan host-sim/data/plans/qemu-short.json \
  --seed 3 -o "$T/run.bin" --truth "$T/truth.csv" --truth-every 1 \
  --depth-log "$T/depth.csv" --tie-in-job "$T/job.json"
run tiein-replay 0 replay "$T/run.bin" --job "$T/job.json"
run tiein-replay-csv 0 replay "$T/run.bin" --job "$T/job.json" --csv "$T/replay.csv"
# without its job the replay has no tie-in: solutions differ, exit 3
run tiein-replay-without-job 3 replay "$T/run.bin"
run tiein-decode 0 decode "$T/run.bin" --csv "$T/frames.csv"
run tiein-survey 0 survey "$T/run.bin" --depth "$T/depth.csv" --job "$T/job.json" \
  --csv "$T/stations.csv" --trajectory "$T/trajectory.csv"
run tiein-survey-unlinked 0 survey "$T/run.bin" --depth "$T/depth.csv" --tie-on-md 3000
# a capture survey's exports through the station-file writers; another
# error model is refused (the capture's uncertainty is the probe's own)
run tiein-survey-exports 0 survey "$T/run.bin" --depth "$T/depth.csv" --job "$T/job.json" \
  --json "$T/survey.json" --witsml "$T/survey.xml" --plot "$T/plots"
run tiein-survey-model-refused 1 survey "$T/run.bin" --depth "$T/depth.csv" --job "$T/job.json" \
  --error-model "GYRO-MWD"

# --- station surveys: README's ISCWSA well #1, the probe's model with an offset
S="$R/survey"
run survey-well1 0 survey tests/data/iscwsa/well1_stations.csv \
  --lat 60 --error-model "ISCWSA MWD Rev5" \
  --b-total-nt 50000 --dip-deg 72 --declination-deg -4 \
  --vsec-azimuth-deg 75 --csv "$S/well1.csv" --json "$S/well1.json" --witsml "$S/well1.xml" \
  --plot "$S/well1-plots"
run survey-well1-gyro-offset 0 survey tests/data/iscwsa/well1_stations.csv \
  --lat 60 --error-model GYRO-MWD --tie-on-md 0 \
  --offset tests/data/iscwsa/well1_stations.csv --offset-tie-on-north 30 \
  --hole-radius-m 0.108 --offset-hole-radius-m 0.156 --csv "$S/well1-offset.csv" --json "$S/well1-offset.json"
run survey-tiein-stations-probe-model 0 survey "$T/stations.csv" --error-model PROBE-SCC1300 \
  --tie-on-md 3000 --tie-on-tvd 2450 --tie-on-north 420 --tie-on-east 310 --csv "$S/tiein-probe-model.csv"

# --- studies, in small --------------------------------------------------
run study-drilling-coverage 0 study drilling-coverage --runs 4 --threads 2 \
  --json "$R/study/drilling-coverage.json"
run study-lateral-covariance 0 study lateral --well 100m --covariance-only \
  --plots "$R/study/lateral-plots"
run study-lateral-runs 0 study lateral --well 100m --runs 2 --threads 2 \
  --json "$R/study/lateral.json" --csv "$R/study/lateral.csv" --stations-csv "$R/study/lateral-stations.csv"
run study-rins-probe 0 study rins-probe --runs 1 --threads 2 --grades scc1300,navigation \
  --json "$R/study/rins-probe.json"

# --- the dashboard's state for a replayed capture -----------------------
# Served from the tied-in capture at the fastest pace on 127.0.0.1, any
# free port; a new page's first update is the full state (the SSE stream
# at /events), taken once the replay has ended. Also the page's assets
# and a command refused while replaying.
D="$R/dashboard"
"$H" dashboard --file "$T/run.bin" --speed 1000000 --depth "$T/depth.csv" --job "$T/job.json" \
  --bind 127.0.0.1 --http-port 0 </dev/null >"$D/server.stdout" 2>"$D/server.stderr" &
dash_pid=$!
python3 - "$dash_pid" "$D" <<'EOF'
import json, os, re, socket, sys, time

pid, out = int(sys.argv[1]), sys.argv[2]
deadline = time.time() + 30
addr = None
while addr is None:
    text = open(os.path.join(out, "server.stdout")).read()
    m = re.search(r"http://(127\.0\.0\.1):(\d+)/", text)
    if m:
        addr = (m.group(1), int(m.group(2)))
        break
    try:
        os.kill(pid, 0)
    except OSError:
        sys.exit("golden: the dashboard stopped before serving")
    if time.time() > deadline:
        sys.exit("golden: no URL from the dashboard in 30 s")
    time.sleep(0.1)

# The dashboard answers only to its own address (Host).
host = f"Host: {addr[0]}:{addr[1]}\r\n"

def request(method, path, headers=""):
    with socket.create_connection(addr, timeout=20) as s:
        s.sendall(f"{method} {path} HTTP/1.0\r\n{host}{headers}\r\n".encode())
        data = b""
        while chunk := s.recv(65536):
            data += chunk
    head, _, body = data.partition(b"\r\n\r\n")
    return int(head.split(b" ")[1]), body

def first_update():
    """The first update a new page gets (no Last-Event-ID): the full state."""
    with socket.create_connection(addr, timeout=20) as s:
        s.sendall(f"GET /events HTTP/1.0\r\n{host}\r\n".encode())
        data = b""
        while True:
            chunk = s.recv(1 << 20)
            if not chunk:
                sys.exit("golden: the event stream ended")
            data += chunk
            start = data.find(b"\ndata:")
            if start >= 0:
                end = data.find(b"\n", start + 1)
                if end >= 0:
                    return data[start + 6:end].strip().decode()

while True:
    update = first_update()
    state = json.loads(update)
    if state["rest"]["finished"]:
        break
    if time.time() > deadline + 60:
        sys.exit("golden: the dashboard's replay did not end in 90 s")
    time.sleep(0.2)
with open(os.path.join(out, "state.json"), "w") as f:
    f.write(update + "\n")
token = None
for path, name in [("/", "index.html"), ("/dashboard.js", "dashboard.js"),
                   ("/dashboard.css", "dashboard.css"), ("/uPlot.js", "uPlot.js"),
                   ("/uPlot.css", "uPlot.css")]:
    status, body = request("GET", path)
    if status != 200:
        sys.exit(f"golden: GET {path}: {status}")
    if path == "/":
        # The page holds the run's random access token: kept as <TOKEN>.
        m = re.search(rb'name="probe-token" content="([0-9a-f]{64})"', body)
        if not m:
            sys.exit("golden: no access token in the page")
        token = m.group(1).decode()
        body = body.replace(m.group(1), b"<TOKEN>")
    with open(os.path.join(out, "asset-" + name), "wb") as f:
        f.write(body)
with open(os.path.join(out, "commands-refused.txt"), "w") as f:
    for path in ["/api/align", "/api/station", "/api/index/1/30", "/api/configure"]:
        status, body = request("POST", path, f"X-Probe-Token: {token}\r\n")
        f.write(f"POST {path}: {status} {body.decode()}\n")
    status, body = request("POST", "/api/align")
    f.write(f"POST /api/align without the page's token: {status} {body.decode()}\n")
EOF
kill "$dash_pid"
wait "$dash_pid" || true
dash_pid=""
# its output: the URL (port normalised), and whatever it says on stopping
cat "$D/server.stdout" "$D/server.stderr" >"$R/cmd/dashboard.txt"
rm "$D/server.stdout" "$D/server.stderr"

# --- normalise, hash -----------------------------------------------------
python3 - "$work" "$repo" "$H" <<'EOF'
import os, re, shutil, sys

work, repo, binary = sys.argv[1:4]
run, golden = os.path.join(work, "run"), os.path.join(work, "golden")
T = "<T>"
NUM = r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"
# JSON keys and CSV columns whose values are times or speeds.
TIMING_KEYS = {"wall_s", "run_wall_s", "run_cpu_s", "cpu_s", "epochs_per_core_second",
               "epochs_per_thread_wall_second", "micros_per_step", "rate_per_s"}
json_timing = re.compile(r'("(?:%s)"\s*:\s*)(?:%s|null)' % ("|".join(TIMING_KEYS), NUM))
line_rules = [
    # paper rins: "(43200 steps), 1.02 s wall."; --strapdown-check: "; 1.6 s wall."
    (re.compile(r"%s s wall\b" % NUM), T + " s wall"),
    # simulate --motion lateral: "... samples to FILE in 3.6 s; ..."
    (re.compile(r" in %s s;" % NUM), " in " + T + " s;"),
    # study drilling-coverage: "wall time   11.0 s"
    (re.compile(r"^(wall time\s+)%s s$" % NUM), r"\g<1>" + T + " s"),
    # study lateral's first line: "...; filter f64; 12.8 s"
    (re.compile(r"^(lateral study: .*); %s s$" % NUM), r"\1; " + T + " s"),
    # study rins-probe: "...; 0 failed runs, 6 s"
    (re.compile(r"(failed runs?), %s s$" % NUM), r"\1, " + T + " s"),
    # paper rins: "cost per step, reduced / full filter (us, this build)   2.8 / 15.4 | ..."
    (re.compile(r"^(cost per step.*?\))\s+%s / %s \|" % (NUM, NUM)), r"\1 " + T + " |"),
    # the dashboard's URL
    (re.compile(r"127\.0\.0\.1:\d+"), "127.0.0.1:<PORT>"),
]
progress = re.compile(r"\(eta [^)]*\)|\r")


def normalise_text(text, name, is_cmd):
    text = text.replace(work, "<TMP>").replace(repo, "<REPO>").replace(binary, "<HOST_SIM>")
    text = json_timing.sub(r'\1"' + T + '"', text)
    out, timing_table = [], False
    for line in text.split("\n"):
        if is_cmd and progress.search(line):
            continue  # a progress bar's line (none while stderr is not a terminal)
        for rule, repl in line_rules:
            line = rule.sub(repl, line)
        # study lateral's tables whose last column is a speed or a CPU time
        if line.rstrip().endswith(("epochs/s/core (CPU)", "CPU (s)")):
            timing_table = True
        elif not line.strip():
            timing_table = False
        elif timing_table and not line.startswith("-"):
            line = re.sub(r"\s+%s$" % NUM, " " + T, line)
        out.append(line)
    text = "\n".join(out)
    if name.endswith(".csv"):
        text = blank_csv_columns(text)
    return text


def blank_csv_columns(text):
    lines = text.split("\n")
    header = lines[0].split(",")
    cols = [i for i, h in enumerate(header) if h in TIMING_KEYS]
    if not cols:
        return text
    for n in range(1, len(lines)):
        if not lines[n] or '"' in lines[n]:
            if '"' in lines[n]:
                sys.exit("golden: a quoted CSV row in a file with timing columns")
            continue
        cells = lines[n].split(",")
        for i in cols:
            if i < len(cells):
                cells[i] = T
        lines[n] = ",".join(cells)
    return "\n".join(lines)


BINARY_EXT = (".bin", ".png")
for dirpath, _, files in os.walk(run):
    for f in files:
        src = os.path.join(dirpath, f)
        rel = os.path.relpath(src, run)
        dst = os.path.join(golden, rel)
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        data = open(src, "rb").read()
        if f.endswith(BINARY_EXT) or b"\0" in data:
            shutil.copyfile(src, dst)
        else:
            text = data.decode("utf-8", "surrogateescape")
            open(dst, "wb").write(normalise_text(text, f, rel.startswith("cmd/")).encode("utf-8", "surrogateescape"))
EOF

(
  cd "$work/golden"
  find . -type f -printf '%P\n' | LC_ALL=C sort | while IFS= read -r f; do sha256sum -- "$f"; done
) >"$work/hashes.txt"
cat "$work/hashes.txt"
echo "golden: $(wc -l <"$work/hashes.txt") outputs"
