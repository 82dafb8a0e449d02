#!/usr/bin/env python3
"""Benchmark: a batch on Dask against the local batch, and Dask's overhead per task
(docs/collections.md, "Dask against the local batch, and Dask's cost per task").

Runs the same pairs, each run from an empty cache (eigenbases included), in one script:
1. `shapecorr batch` (the reference: the Rust batch, pairs in parallel on this machine);
2. `shapecorr.batch.match_pairs(client=None)` (Python threads);
3. `match_pairs(client=...)` on a `LocalCluster` of 2 worker processes, 1 thread each
   (started before the clock: a cluster is long-lived);
4. on a `LocalCluster` of 4 worker processes with 1 thread each, Dask's own cost per task
   from its task stream (`overhead_per_task`).
In Dask workers the library's pool has one thread (`shapecorr.batch` sets
RAYON_NUM_THREADS=1 there, as Dask sets OMP_NUM_THREADS=1).
Every result must equal the reference's (pair for pair, timings aside).

Usage: python tests/bench/batch_dask.py [--shapes N] [--data DIR]
(default: the first N = 12 FAUST shapes of ../shared/data, 66 pairs; generated humanoids
when the data is absent). Needs `pip install ./bindings/python[dask]`.
"""
import argparse
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BINARY = ROOT / "target" / "release" / "shapecorr"


def shapes(args, scratch):
    faust = Path(args.data) / "faust"
    if faust.is_dir():
        files = sorted(faust.glob("*.ply"))[: args.shapes]
        return files, f"FAUST {files[0].stem}..{files[-1].stem}"
    import shapecorr

    folder = scratch / "figures"
    folder.mkdir()
    for i in range(args.shapes):
        shape = shapecorr.Shape.figure("humanoid", i % 7, 6000)
        v, t = shape.vertices, shape.triangles
        text = [f"OFF\n{len(v)} {len(t)} 0"] + [f"{x!r} {y!r} {z!r}" for x, y, z in v.tolist()]
        text += [f"3 {a} {b} {c}" for a, b, c in t.tolist()]
        (folder / f"h{i:02d}.off").write_text("\n".join(text) + "\n")
    files = sorted(folder.glob("*.off"))
    return files, "generated humanoids, 6K vertices (no FAUST data found)"


def results(out):
    found = {}
    for line in (Path(out) / "pairs.jsonl").read_text().splitlines():
        r = json.loads(line)
        found[(r["a"], r["b"])] = {k: v for k, v in r.items() if k not in ("seconds", "stages")}
    return found


def timed(label, run):
    start = time.perf_counter()
    run()
    seconds = time.perf_counter() - start
    print(f"{label:<44} {seconds:8.1f} s", flush=True)
    return seconds


def overhead_per_task(stream):
    """Dask's cost per task: on each worker, the gap between one task's end and the next
    one's start, counted where the next task could have started at once (its shape tasks
    had ended): sending the task, its inputs and the result, the worker's bookkeeping."""
    runs = []  # (worker, key, start, stop)
    for task in stream:
        for part in task["startstops"]:
            if part["action"] == "compute":
                runs.append((task["worker"], str(task["key"]), part["start"], part["stop"]))
    shape_end = {key.split("-")[2]: stop for _, key, _, stop in runs if key.startswith("shapecorr-shape-")}

    def ready(key):
        if not key.startswith("shapecorr-pair-"):
            return 0.0
        _, _, i, j, _ = key.split("-")
        return max(shape_end[i], shape_end[j])

    gaps = []
    for worker in {r[0] for r in runs}:
        mine = sorted((start, stop, key) for w, key, start, stop in runs if w == worker)
        for (_, stop, _), (start, _, key) in zip(mine, mine[1:]):
            if ready(key) <= stop:
                gaps.append(start - stop)
    return gaps


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shapes", type=int, default=12)
    parser.add_argument("--data", default=str(ROOT.parent / "shared" / "data"))
    args = parser.parse_args()
    import distributed

    from shapecorr import batch

    scratch = Path(tempfile.mkdtemp(prefix="shapecorr-batch-dask-"))
    try:
        files, what = shapes(args, scratch)
        n = len(files)
        print(f"{what}: {n} shapes, {n * (n - 1) // 2} pairs; {os.cpu_count()} cores "
              f"({platform.processor() or platform.machine()}), Python {platform.python_version()}, "
              f"dask {distributed.__version__}")
        cores = os.cpu_count() or 1
        local = timed("shapecorr batch (reference)", lambda: subprocess.run(
            [str(BINARY), "batch", *map(str, files), "--out", str(scratch / "cli"), "--quiet"],
            check=True, stdout=subprocess.DEVNULL))
        reference = results(scratch / "cli")
        python = timed("match_pairs, threads", lambda: batch.match_pairs(files, scratch / "py", workers=cores))
        assert results(scratch / "py") == reference, "Python threads differ from the reference"

        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                      dashboard_address=None, silence_logs=50) as cluster, \
                distributed.Client(cluster) as client:
            dask2 = timed("match_pairs, Dask LocalCluster 2 x 1 thread", lambda: batch.match_pairs(
                files, scratch / "dask2", client=client))
        assert results(scratch / "dask2") == reference, "Dask differs from the reference"

        with distributed.LocalCluster(n_workers=4, threads_per_worker=1, processes=True, host="127.0.0.1",
                                      dashboard_address=None, silence_logs=50) as cluster, \
                distributed.Client(cluster) as client:
            client.get_task_stream()  # start recording
            dask4 = timed("match_pairs, Dask LocalCluster 4 x 1 thread", lambda: batch.match_pairs(
                files, scratch / "dask4", client=client))
            stream = client.get_task_stream()
        assert results(scratch / "dask4") == reference, "Dask (4 workers) differs from the reference"
        gaps = overhead_per_task(stream)
        print(f"\nDask 2 workers / shapecorr batch: {dask2 / local:.2f}x (target at most 1.1x); "
              f"Python threads / shapecorr batch: {python / local:.2f}x; 4 workers: {dask4:.1f} s")
        gaps.sort()
        p90 = gaps[min(len(gaps) - 1, int(0.9 * len(gaps)))]
        print(f"Dask overhead per task, 4 workers ({len(gaps)} gaps between tasks): "
              f"median {1000 * statistics.median(gaps):.2f} ms, 90th percentile {1000 * p90:.2f} ms, "
              f"mean {1000 * statistics.mean(gaps):.2f} ms, max {1000 * max(gaps):.1f} ms (target below 5 ms)")
        print("every run's pairs equal the reference's")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
