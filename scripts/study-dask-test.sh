#!/usr/bin/env bash
# The Dask runner (scripts/study_dask.py) on a 2-worker LocalCluster on
# 127.0.0.1: a small lateral study in 3 shards, one of which fails on its
# first try (a wrapper around the binary) and is run again, merged; its
# outputs compared with the same study in one process, byte for byte
# (`cmp`): stations.csv and every plot as written; study.txt, study.json
# and study.csv with their timings (wall and CPU times, speeds) blanked
# first, the only fields two processes' runs of a study differ in. Then a
# drilling-coverage study (`--study drilling-coverage`): table and JSON.
# The venv (target/study-dask/venv) comes from scripts/requirements-dask.txt.
# Usage: scripts/study-dask-test.sh HOST_SIM
set -euo pipefail
cd "$(dirname "$0")/.."
HS=$(realpath "${1:?usage: $0 HOST_SIM}")
WORK=target/study-dask
VENV=$WORK/venv
if [ ! -x "$VENV/bin/python" ] || ! cmp -s scripts/requirements-dask.txt "$VENV/requirements.txt"; then
  rm -rf "$VENV"
  python3 -m venv "$VENV"
  "$VENV/bin/pip" install -q --disable-pip-version-check -r scripts/requirements-dask.txt
  cp scripts/requirements-dask.txt "$VENV/requirements.txt"
fi
RUN=$(mktemp -d "${TMPDIR:-/tmp}/study-dask-test.XXXXXX")
trap 'rm -rf "$RUN"' EXIT

STUDY=(--well 100m --grades scc1300 --runs 3 --first-seed 5 --rop 300 --connection-still 120 --threads 2)

# the study in one process
mkdir -p "$RUN/single"
"$HS" study lateral "${STUDY[@]}" --json "$RUN/single/study.json" \
  --csv "$RUN/single/study.csv" --stations-csv "$RUN/single/stations.csv" \
  --plots "$RUN/single/plots" >"$RUN/single/study.txt"

# a binary whose shard 2 fails once: the runner must run it again
cat >"$RUN/flaky-host-sim" <<EOF
#!/usr/bin/env bash
case " \$* " in
  *" --shard 2/"*) if [ ! -e "$RUN/failed-once" ]; then touch "$RUN/failed-once"; echo "flaky: failing once" >&2; exit 3; fi ;;
esac
exec "$HS" "\$@"
EOF
chmod +x "$RUN/flaky-host-sim"

"$VENV/bin/python" scripts/study_dask.py "$RUN/flaky-host-sim" 3 "$RUN/dask" \
  --workers 2 --retries 1 -- "${STUDY[@]}"
test -e "$RUN/failed-once" || { echo "study-dask-test: shard 2 never failed" >&2; exit 1; }

# timings blanked: JSON keys and CSV columns by name, the first line's wall
# time, the last column of the tables ending in a speed or a CPU time; the
# plot paths the merge prints are its own
untimed() {
  python3 - "$1" "$2" <<'EOF'
import json, re, sys
path, kind = sys.argv[1:3]
TIMING = {"wall_s", "run_wall_s", "run_cpu_s", "cpu_s",
          "epochs_per_core_second", "epochs_per_thread_wall_second"}
text = open(path).read()
if kind == "json":
    def strip(v):
        if isinstance(v, dict):
            return {k: ("<T>" if k in TIMING else strip(x)) for k, x in v.items()}
        if isinstance(v, list):
            return [strip(x) for x in v]
        return v
    sys.stdout.write(json.dumps(strip(json.loads(text)), indent=1, sort_keys=False) + "\n")
elif kind == "csv":
    lines = text.split("\n")
    head = lines[0].split(",")
    cols = [i for i, h in enumerate(head) if h in TIMING]
    for n in range(1, len(lines)):
        cells = lines[n].split(",")
        for i in cols:
            if i < len(cells):
                cells[i] = "<T>"
        lines[n] = ",".join(cells)
    sys.stdout.write("\n".join(lines))
else:
    table = False
    for n, line in enumerate(text.split("\n")):
        if n == 0:
            line = line[: line.rfind("; ")]
        elif line.startswith("wrote "):
            line = "wrote " + line.rsplit("/", 1)[-1]
        elif line.endswith(("epochs/s/core (CPU)", "CPU (s)")):
            table = True
        elif not line.strip():
            table = False
        elif table and not line.startswith("-"):
            line = re.sub(r"\s+\S+$", "", line)
        print(line)
EOF
}
for f in study.json:json study.csv:csv study.txt:txt; do
  name=${f%%:*}
  untimed "$RUN/single/$name" "${f##*:}" >"$RUN/single.$name"
  untimed "$RUN/dask/$name" "${f##*:}" >"$RUN/dask.$name"
  cmp "$RUN/single.$name" "$RUN/dask.$name"
done
cmp "$RUN/single/stations.csv" "$RUN/dask/stations.csv"
n=0
for p in "$RUN/single/plots"/*; do
  cmp "$p" "$RUN/dask/plots/$(basename "$p")"
  n=$((n + 1))
done
[ "$n" -ge 4 ] || { echo "study-dask-test: only $n plots" >&2; exit 1; }
echo "study-dask-test: 3 shards on 2 Dask workers (one retried) = one process: JSON, CSV, table (timings aside), stations.csv and $n plots byte for byte"

# the drilling-coverage study the same way (--study drilling-coverage):
# its table and JSON, the wall time the only figure that differs
COVERAGE=(--runs 3 --first-seed 5 --scalar f64 --threads 1)
"$HS" study drilling-coverage "${COVERAGE[@]}" --json "$RUN/coverage.json" >"$RUN/coverage.txt"
"$VENV/bin/python" scripts/study_dask.py "$HS" 3 "$RUN/coverage-dask" \
  --workers 2 --study drilling-coverage -- "${COVERAGE[@]}" >/dev/null
cmp <(grep -v '^wall time' "$RUN/coverage.txt") <(grep -v '^wall time' "$RUN/coverage-dask/study.txt")
cmp <(grep -v '"wall_s":' "$RUN/coverage.json") <(grep -v '"wall_s":' "$RUN/coverage-dask/study.json")
echo "study-dask-test: a drilling-coverage study in 3 shards on Dask = one process: table and JSON (wall time aside)"
