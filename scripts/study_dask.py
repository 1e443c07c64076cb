#!/usr/bin/env python3
"""A lateral (or drilling-coverage) study on a Dask cluster
(docs/study-scale-out.md).

One task per shard: each runs `HOST_SIM study STUDY STUDY_ARGS --shard
K/N --shard-file ...` on a worker and sends the shard file back; a failed
shard is run again (Dask's `retries`). When every shard is in, `HOST_SIM
study merge` writes the study's outputs into OUT_DIR, the same as the study
in one process: study.txt (its standard output) and study.json; for the
lateral study also study.csv, stations.csv and plots/.

    study_dask.py HOST_SIM SHARDS OUT_DIR [options] -- STUDY_ARGS...

By default a LocalCluster of --workers processes on 127.0.0.1, without a
dashboard; --scheduler tcp://HOST:8786 uses a running cluster instead (its
workers must see HOST_SIM at the same path, and the grade or plan files the
study arguments name). Dependencies: scripts/requirements-dask.txt.
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time
import uuid


def run_shard(host_sim, study, study_args, index, count):
    """On a worker: shard INDEX/COUNT of the study; the shard file's bytes
    and the shard's own summary line."""
    with tempfile.TemporaryDirectory(prefix="host-sim-shard-") as tmp:
        path = os.path.join(tmp, "shard.json")
        cmd = [host_sim, "study", study, *study_args,
               "--shard", f"{index}/{count}", "--shard-file", path]
        done = subprocess.run(cmd, capture_output=True, text=True)
        if done.returncode != 0:
            tail = "\n".join(done.stderr.strip().splitlines()[-5:])
            raise RuntimeError(
                f"shard {index}/{count} failed (exit {done.returncode}): {tail}")
        with open(path, "rb") as f:
            return f.read(), done.stdout.strip()


def write_atomically(path, data):
    """DATA into PATH whole or not at all (a temporary file renamed)."""
    folder = os.path.dirname(path) or "."
    fd, tmp = tempfile.mkstemp(dir=folder, prefix="." + os.path.basename(path) + ".")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def parse_args(argv):
    p = argparse.ArgumentParser(
        description="Run a host-sim study in shards on Dask distributed, then merge.",
        epilog="Everything after -- goes to `host-sim study STUDY` (no --shard, "
               "--shard-file or outputs: the merge writes those).")
    p.add_argument("host_sim", help="the host-sim binary (the same path on every worker)")
    p.add_argument("shards", type=int, help="how many shards (tasks)")
    p.add_argument("out_dir", help="the shard files and the study's outputs go here")
    p.add_argument("--scheduler", metavar="tcp://HOST:8786",
                   help="a running Dask scheduler (default: a LocalCluster on 127.0.0.1)")
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                   help="LocalCluster worker processes (default: the cores)")
    p.add_argument("--shard-threads", type=int, default=1,
                   help="host-sim threads per shard when the study arguments give no "
                        "--threads (default 1: one shard a worker thread)")
    p.add_argument("--retries", type=int, default=2,
                   help="times a failed shard is run again (default 2)")
    p.add_argument("--no-plots", action="store_true", help="merge without plots/")
    p.add_argument("--study", choices=("lateral", "drilling-coverage"), default="lateral",
                   help="which study (default lateral; drilling-coverage writes "
                        "study.txt and study.json only)")
    if "--" not in argv:
        p.parse_args(argv)  # --help, or what is missing
        p.error("the study's arguments go after -- (e.g. -- --well 100m --runs 100)")
    split = argv.index("--")
    args = p.parse_args(argv[:split])
    args.study_args = argv[split + 1:]
    if args.shards < 1:
        p.error("the shard count must be at least 1")
    for own in ("--shard", "--shard-file", "--json", "--csv", "--stations-csv", "--plots"):
        if any(a == own or a.startswith(own + "=") for a in args.study_args):
            p.error(f"{own} is the runner's to give, not a study argument")
    if not any(a == "--threads" or a.startswith("--threads=") for a in args.study_args):
        args.study_args += ["--threads", str(args.shard_threads)]
    args.host_sim = os.path.abspath(args.host_sim)
    return args


def main(argv):
    args = parse_args(argv)
    from dask.distributed import Client, LocalCluster, as_completed

    os.makedirs(os.path.join(args.out_dir, "shards"), exist_ok=True)
    if args.scheduler:
        cluster, client = None, Client(args.scheduler)
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1,
                               processes=True, host="127.0.0.1",
                               dashboard_address=None)
        client = Client(cluster)
    n = args.shards
    print(f"study_dask: {n} shards on {len(client.scheduler_info()['workers'])} workers "
          f"({args.scheduler or 'LocalCluster on 127.0.0.1'})", flush=True)
    started = time.monotonic()
    try:
        run = uuid.uuid4().hex[:8]  # keys of their own on a shared scheduler
        futures = {
            client.submit(run_shard, args.host_sim, args.study, args.study_args, k, n,
                          key=f"host-sim-shard-{k}-of-{n}-{run}", pure=False,
                          retries=args.retries): k
            for k in range(1, n + 1)
        }
        paths, failed = {}, []
        for done, future in enumerate(as_completed(futures), start=1):
            k = futures[future]
            try:
                data, line = future.result()
            except Exception as e:  # the task's own error, after its retries
                failed.append(k)
                print(f"[{done}/{n}] shard {k}/{n} FAILED: {e}", file=sys.stderr, flush=True)
                continue
            path = os.path.join(args.out_dir, "shards", f"shard-{k}-of-{n}.json")
            write_atomically(path, data)
            paths[k] = path
            line = line.rsplit("; wrote ", 1)[0]  # the worker's temporary file
            print(f"[{done}/{n}] {line}; {path} ({time.monotonic() - started:.1f} s in all)",
                  flush=True)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    if failed:
        print(f"study_dask: shard(s) {', '.join(map(str, sorted(failed)))} failed "
              f"after {args.retries} retries: nothing merged", file=sys.stderr)
        return 1
    out = args.out_dir
    merge = [args.host_sim, "study", "merge", *[paths[k] for k in sorted(paths)],
             "--json", os.path.join(out, "study.json")]
    if args.study == "lateral":
        merge += ["--csv", os.path.join(out, "study.csv"),
                  "--stations-csv", os.path.join(out, "stations.csv")]
        if not args.no_plots:
            merge += ["--plots", os.path.join(out, "plots")]
    done = subprocess.run(merge, capture_output=True, text=True)
    sys.stderr.write(done.stderr)
    if done.returncode != 0:
        print(f"study_dask: the merge failed (exit {done.returncode})", file=sys.stderr)
        return done.returncode
    write_atomically(os.path.join(out, "study.txt"), done.stdout.encode())
    sys.stdout.write(done.stdout)
    print(f"study_dask: {n} shards merged into {out} in {time.monotonic() - started:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
