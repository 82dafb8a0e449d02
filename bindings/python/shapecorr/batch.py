"""Collections: many pairs of a shape collection, each shape's work done once, on this
machine or on a Dask cluster (docs/collections.md).

    from shapecorr import batch
    log = batch.match_pairs("shapes/", "out/")                      # every pair, threads here
    log = batch.match_pairs(files, "out/", pairs="one-to-many:template", client=client)
    table = batch.summary("out/")                                   # a row per pair
    batch.write_matrix("out/", "confidence", "out/confidence.csv", "out/confidence.png")
    labels = batch.consistent_labels("out/")                        # one-to-many runs

The jobs are the library's (``sc_batch_prepare``: read a shape, its proxy, its eigenbasis
from the cache in ``cache`` or computed and stored; ``sc_batch_match``: a pair's regions and
map): the same records as ``shapecorr batch`` writes, each pair the answer of
``shapecorr match`` (or ``p2p`` with ``maps=True``). With a ``dask.distributed.Client`` the
per-shape jobs and then the pair jobs that depend on them run as Dask tasks; every worker
must see the same files and cache folder (one machine, or a shared file system). Results
stream back to this process, which alone writes the log: ``out/pairs.jsonl``, a JSON line
per pair, appended as each finishes. Running again resumes (recorded pairs are skipped);
a lost worker's tasks are rerun by Dask and written once.
"""

from __future__ import annotations

import ctypes
import json
import os
import sys
import threading
import warnings
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterable, Mapping, Optional, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import PointwiseOptions, _choice_values, _Params, _check, _lib
from ._lib import lib

if sys.version_info >= (3, 11):
    from typing import Unpack
elif TYPE_CHECKING:  # annotations only (PEP 563)
    from typing_extensions import Unpack

__all__ = ["match_pairs", "summary", "matrix", "write_matrix", "consistent_labels", "read_map", "read_pairs"]

SHAPE_SUFFIXES = (".ply", ".off", ".obj")

#: A folder or file path.
FilePath = Union[str, "os.PathLike[str]"]
#: Files and folders of shapes, or a mapping of name -> file.
Shapes = Union[FilePath, Iterable[FilePath], Mapping[str, FilePath]]
#: ``"all"``, ``"one-to-many:NAME"``, a pair file, or ``(name_a, name_b)`` pairs.
Pairs = Union[FilePath, Iterable[Tuple[str, str]]]
#: A pair's record (a line of ``pairs.jsonl``) or a row of :func:`summary`.
Record = dict[str, Any]
#: ``truth(a, b)``: corresponding vertex arrays ``(vertices_a, vertices_b)``, or None.
Truth = Callable[[str, str], Optional[Tuple[ArrayLike, ArrayLike]]]


class _Batch:
    """One ``sc_batch`` per process and settings (kept for the process's life)."""

    _kept: dict[str, _Batch] = {}
    _lock = threading.Lock()

    @classmethod
    def of(cls, settings):
        key = json.dumps(settings, sort_keys=True)
        with cls._lock:
            if key not in cls._kept:
                cls._kept[key] = cls(settings)
            return cls._kept[key]

    def __init__(self, settings):
        params = _Params(settings["options"])
        flags = (
            (_lib.BATCH_MAPS if settings["maps"] else 0)
            | (_lib.BATCH_POINTS if settings["points"] else 0)
            | (0 if settings["repair"] else _lib.BATCH_NO_REPAIR)
        )
        pointer = ctypes.c_void_p()
        _check(lib.sc_batch_new(params, os.fsencode(settings["cache"]), flags, ctypes.byref(pointer)))
        self._pointer = pointer

    def _handle_pointer(self):
        return self._pointer

    def _record(self, function, *args):
        return _record(function, self, *args)

    def open_folder(self, out):
        """Locks the output folder and checks (or records) the settings in ``batch.json``,
        as the command line does (``sc_batch_open_folder``); :class:`_Folder` releases it."""
        pointer = ctypes.c_void_p()
        _check(lib.sc_batch_open_folder(self, os.fsencode(out), ctypes.byref(pointer)))
        return _Folder(pointer)

    def prepare(self, name, path):
        return self._record(lib.sc_batch_prepare, name.encode(), os.fsencode(path))

    def match(self, a, b, out):
        (name_a, path_a), (name_b, path_b) = a, b
        return self._record(
            lib.sc_batch_match,
            name_a.encode(),
            os.fsencode(path_a),
            name_b.encode(),
            os.fsencode(path_b),
            os.fsencode(out),
        )


def _record(function, *args):
    """Calls a C function that gives an ``sc_batch_record``; returns its JSON, decoded."""
    record = ctypes.c_void_p()
    _check(function(*args, ctypes.byref(record)))
    try:
        return json.loads(lib.sc_batch_record_json(record).decode("utf-8"))
    finally:
        lib.sc_batch_record_free(record)


class _Folder:
    """A locked output folder; ``close()`` releases the lock (so does the process's end)."""

    def __init__(self, pointer):
        self._pointer = pointer

    def close(self):
        if self._pointer:
            lib.sc_batch_folder_free(self._pointer)
            self._pointer = None


def read_pairs(path: FilePath) -> list[tuple[str, str]]:
    """The ``(A, B)`` name pairs of a pair file, read by the library as ``shapecorr batch
    --pairs FILE`` reads it: ``A<TAB>B[<TAB>CATEGORY]`` per line (names may hold spaces), a
    line without a tab split at spaces, ``#`` comments (docs/collections.md)."""
    return [(p["a"], p["b"]) for p in _record(lib.sc_batch_read_pairs, os.fsencode(path))]


#: glibc's mallopt parameters (malloc.h).
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3


def _set_up_dask_worker():
    """Once per Dask worker process, before the library's first job there:
    - the library's own pool gets one thread (unless RAYON_NUM_THREADS says otherwise), as
      Dask gives numpy's BLAS one (OMP_NUM_THREADS=1): the workers are the parallelism;
    - glibc's malloc keeps blocks below 32 MiB in its heap and trims it above 64 MiB. Dask
      starts workers with MALLOC_TRIM_THRESHOLD_=65536, which also fixes malloc's mmap
      threshold at 128 KiB: every large temporary of the pipeline became an mmap and a
      munmap with its pages zeroed again. Measured on 6 FAUST shapes (15 pairs): 11.2-12.2 s
      without that variable, 19.1-20.8 s with it (12 s of it in the kernel).
    Results do not depend on either."""
    if getattr(_set_up_dask_worker, "done", False):
        return
    _set_up_dask_worker.done = True
    try:
        from distributed import get_worker

        get_worker()
    except (ImportError, ValueError):
        return
    os.environ.setdefault("RAYON_NUM_THREADS", "1")
    if "MALLOC_TRIM_THRESHOLD_" in os.environ and sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL("libc.so.6")
            libc.mallopt(_M_MMAP_THRESHOLD, 32 << 20)
            libc.mallopt(_M_TRIM_THRESHOLD, 64 << 20)
        except (OSError, AttributeError):
            pass


def prepare_task(settings: dict[str, Any], name: str, path: str) -> Record:
    """The per-shape job (a Dask task): the shape's record of ``shapes.jsonl``."""
    _set_up_dask_worker()
    return _Batch.of(settings).prepare(name, path)


def match_task(
    settings: dict[str, Any], a: tuple[str, str], b: tuple[str, str], out: str, *shape_records: Record
) -> Record:
    """The per-pair job (a Dask task, after its shapes' ``prepare_task``): the pair's record
    of ``pairs.jsonl``."""
    _set_up_dask_worker()
    return _Batch.of(settings).match(a, b, out)


def _inputs(shapes):
    """``(name, path)`` per shape: files as given, folders expanded (sorted), named by file
    stem, or by the path relative to the common folder when stems repeat (as the command
    line does); a dict gives the names itself."""
    if isinstance(shapes, dict):
        return [(str(name), Path(path)) for name, path in shapes.items()]
    if isinstance(shapes, (str, os.PathLike)):
        shapes = [shapes]
    paths = []
    for item in shapes:
        item = Path(item)
        if item.is_dir():
            found = sorted(p for p in item.iterdir() if p.is_file() and p.suffix.lower() in SHAPE_SUFFIXES)
            if not found:
                raise ValueError(f"{item}: no .ply, .off or .obj file in this folder")
            paths.extend(found)
        else:
            paths.append(item)
    paths = list(dict.fromkeys(paths))
    stems = [p.stem for p in paths]
    if len(set(stems)) == len(stems):
        return list(zip(stems, paths))
    common = Path(os.path.commonpath([str(p.parent) for p in paths]))
    return [(str(p.relative_to(common).with_suffix("")), p) for p in paths]


def _find(inputs, name):
    names = [n for n, _ in inputs]
    if name in names:
        return names.index(name)
    by_stem = [i for i, (_, p) in enumerate(inputs) if p.stem == name]
    if len(by_stem) == 1:
        return by_stem[0]
    if not by_stem:
        raise ValueError(f"no shape named {name!r} among the inputs")
    raise ValueError(f"{name!r} names {len(by_stem)} shapes; use the names of shapes.jsonl")


def _pairs(spec, inputs):
    """Pairs as index tuples: ``"all"``, ``"one-to-many:NAME"``, a pair file, or a list of
    ``(name_a, name_b)``."""
    n = len(inputs)
    if isinstance(spec, str) and spec == "all":
        if n < 2:
            raise ValueError(f"`all` needs two or more shapes, got {n}")
        return [(i, j) for i in range(n) for j in range(i + 1, n)]
    if isinstance(spec, str) and spec.startswith("one-to-many:"):
        t = _find(inputs, spec[len("one-to-many:"):])
        return [(t, j) for j in range(n) if j != t]
    if isinstance(spec, (str, os.PathLike)):
        spec = read_pairs(spec)
    return [(_find(inputs, a), _find(inputs, b)) for a, b in spec]


class _Log:
    """A JSON-lines log read back on start (a last line cut short by a kill is dropped) and
    appended to, one flushed line per record."""

    def __init__(self, path):
        self.path = Path(path)
        self.records = []
        whole = 0
        if self.path.exists():
            data = self.path.read_bytes()
            for line in data.split(b"\n")[:-1]:
                try:
                    self.records.append(json.loads(line))
                except ValueError:
                    break
                whole += len(line) + 1
            if whole != len(data):
                with open(self.path, "r+b") as file:
                    file.truncate(whole)
        self._file = open(self.path, "a", encoding="utf-8")

    def append(self, record):
        self._file.write(json.dumps(record, separators=(",", ":")) + "\n")
        self._file.flush()

    def close(self):
        self._file.close()


def match_pairs(
    shapes: Shapes,
    out: FilePath,
    pairs: Pairs = "all",
    client: Any = None,
    *,
    maps: bool = False,
    points: bool = False,
    repair: bool = True,
    cache: FilePath | None = None,
    workers: int | None = None,
    retry_failed: bool = False,
    progress: Callable[[int, int, Record], object] | None = None,
    **options: Unpack[PointwiseOptions],
) -> Path:
    """Matches the ``pairs`` of ``shapes`` and writes a record per pair to
    ``out/pairs.jsonl`` (and ``out/shapes.jsonl``, ``out/maps/`` with ``maps=True``);
    returns the log's path.

    ``shapes``: files and folders, or a dict of name -> file. ``pairs``: ``"all"``,
    ``"one-to-many:NAME"``, a pair file (``A<TAB>B[<TAB>CATEGORY]`` per line, read as
    :func:`read_pairs` does) or a list of name pairs. ``client``: a ``dask.distributed.Client`` (None: threads here, ``workers`` of
    them, one per core by default). ``cache``: the eigenbasis cache folder (default
    ``out/cache``; every worker must see it). ``options``: the library's named options.
    ``progress(done, total, record)`` is called as each pair finishes. A failed pair is a
    record with ``ok`` false and the library's message; it never stops the batch (and is
    not retried on resume unless ``retry_failed``). The folder is locked while the batch
    runs (a second batch on it raises) and holds the settings in ``batch.json``: a folder
    of a batch with other settings, by this package or by ``shapecorr batch``, is refused.
    A shape whose eigenbasis could not be cached, or whose cache entry was damaged, gets a
    ``warning`` in ``shapes.jsonl`` (and a ``RuntimeWarning``) and is computed without the
    cache. Pairs that failed, now or in an earlier run, are counted in a ``RuntimeWarning``."""
    inputs = _inputs(shapes)
    todo_all = _pairs(pairs, inputs)
    out = Path(out)
    settings = {
        "maps": bool(maps),
        "points": bool(points),
        "repair": bool(repair),
        "cache": str(Path(cache) if cache is not None else out / "cache"),
        "options": _choice_values(options),  # choices by value, whichever way given
    }
    # Bad options fail here, before any task is sent; then the folder is locked and its
    # settings checked by the library, as the command line does.
    folder = _Batch.of(settings).open_folder(out)
    try:
        return _run(inputs, todo_all, out, settings, client, workers, retry_failed, progress)
    finally:
        folder.close()


def _run(inputs, todo_all, out, settings, client, workers, retry_failed, progress):
    log = _Log(out / "pairs.jsonl")
    done = {(r["a"], r["b"]) for r in log.records if r.get("ok") or not retry_failed}
    todo = [(i, j) for i, j in todo_all if (inputs[i][0], inputs[j][0]) not in done]
    needed = sorted({i for pair in todo for i in pair})
    shape_log = _Log(out / "shapes.jsonl")
    total, finished = len(todo) + len(done), len(done)
    wanted = {(inputs[i][0], inputs[j][0]) for i, j in todo_all}
    latest = {(r["a"], r["b"]): bool(r.get("ok")) for r in log.records if (r["a"], r["b"]) in wanted}
    failed_before = sum(not ok and pair in done for pair, ok in latest.items())
    failed_now = 0
    job = lambda i: (inputs[i][0], str(inputs[i][1]))  # noqa: E731
    try:
        if client is None:
            with ThreadPoolExecutor(workers or os.cpu_count() or 1) as pool:
                for record in pool.map(lambda i: prepare_task(settings, *job(i)), needed):
                    _shape_done(shape_log, record)
                futures = {pool.submit(match_task, settings, job(i), job(j), str(out)): (i, j) for i, j in todo}
                for future in as_completed(futures):
                    finished += 1
                    record = _result(future, *(inputs[k][0] for k in futures[future]))
                    failed_now += not record.get("ok")
                    _finish(log, record, progress, finished, total)
        else:
            from distributed import as_completed as dask_completed

            shape_futures = {
                i: client.submit(prepare_task, settings, *job(i), pure=False, key=f"shapecorr-shape-{i}-{os.urandom(4).hex()}")
                for i in needed
            }
            pair_futures = {
                client.submit(
                    match_task, settings, job(i), job(j), str(out), shape_futures[i], shape_futures[j],
                    pure=False, key=f"shapecorr-pair-{i}-{j}-{os.urandom(4).hex()}",
                ): (i, j)
                for i, j in todo
            }
            for future in dask_completed(list(pair_futures)):
                finished += 1
                i, j = pair_futures[future]
                record = _result(future, inputs[i][0], inputs[j][0])
                failed_now += not record.get("ok")
                _finish(log, record, progress, finished, total)
                future.release()
            for i, future in shape_futures.items():
                try:
                    _shape_done(shape_log, future.result())
                except Exception as error:  # the shape's task itself failed (its pairs say why)
                    shape_log.append({"name": inputs[i][0], "path": str(inputs[i][1]), "ok": False,
                                      "error": f"{type(error).__name__}: {error}"})
    finally:
        log.close()
        shape_log.close()
    if failed_now + failed_before:
        warnings.warn(
            f"{failed_now + failed_before} of {total} pairs failed ({failed_now} now, {failed_before} in an "
            f"earlier run); their records in {out / 'pairs.jsonl'} say why, and retry_failed=True computes "
            "them again",
            RuntimeWarning,
            stacklevel=3,
        )
    return out / "pairs.jsonl"


def _shape_done(shape_log, record):
    """Logs a shape's record; its cache warning (a damaged entry computed again, an entry
    that could not be stored) becomes a Python warning too."""
    shape_log.append(record)
    if record.get("warning"):
        warnings.warn(f"shape {record['name']}: {record['warning']}", RuntimeWarning, stacklevel=4)


def _result(future, a, b):
    """The pair's record, or a failed record when its task itself failed: a worker that
    died running it more often than Dask allows (KilledWorker), an error in the binding."""
    try:
        return future.result()
    except Exception as error:
        return {"a": a, "b": b, "ok": False, "error": f"{type(error).__name__}: {error}"}


def _finish(log, record, progress, finished, total):
    log.append(record)
    if progress is not None:
        progress(finished, total, record)


def _records(out):
    """The last record of every pair in ``out/pairs.jsonl``, in the log's order."""
    records = {}
    with open(Path(out) / "pairs.jsonl", encoding="utf-8") as file:
        for line in file:
            if line.endswith("\n"):
                record = json.loads(line)
                records.pop((record["a"], record["b"]), None)
                records[(record["a"], record["b"])] = record
    return list(records.values())


def summary(out: FilePath, truth: Truth | None = None) -> list[Record]:
    """A row per pair of the batch in ``out``: ``a``, ``b``, ``ok``, ``error``, ``k``,
    ``regions_a``, ``regions_b`` (counts), ``matches`` (one-to-one), ``confidence``,
    ``doubtful``, ``seconds`` and, with ``truth``, ``accuracy``: ``truth(a, b)`` returns
    corresponding vertex arrays ``(vertices_a, vertices_b)`` (or None where there is no
    ground truth) and the accuracy is the fraction of those pairs whose vertex of B lies in
    a region matched one-to-one to the region of A's vertex (unweighted)."""
    rows = []
    for r in _records(out):
        row = {
            "a": r["a"],
            "b": r["b"],
            "ok": r["ok"],
            "error": r.get("error"),
            "k": r.get("k"),
            "regions_a": r.get("n_regions_a"),
            "regions_b": r.get("n_regions_b"),
            "matches": len(r.get("matches_one_to_one", [])),
            "confidence": r.get("confidence"),
            "doubtful": r.get("doubtful"),
            "seconds": r.get("seconds"),
        }
        if truth is not None and r["ok"]:
            found = truth(r["a"], r["b"])
            if found is not None:
                va, vb = (np.asarray(v, dtype=np.int64) for v in found)
                la, lb = np.asarray(r["regions_a"])[va], np.asarray(r["regions_b"])[vb]
                matched = {(i, j) for i, j in r["matches_one_to_one"]}
                row["accuracy"] = float(np.mean([(i, j) in matched for i, j in zip(la, lb)]))
        rows.append(row)
    return rows


def matrix(
    out: FilePath, score: str = "confidence", truth: Truth | None = None
) -> tuple[list[str], NDArray[np.float64]]:
    """``(names, m)``: the n x n matrix of ``score`` (a numeric column of :func:`summary`),
    ``m[i, j]`` for the pair (A = names[i], B = names[j]); NaN where there is no pair or no
    value. Names in first-seen order."""
    rows = summary(out, truth=truth)
    names = list(dict.fromkeys([r["a"] for r in rows] + [r["b"] for r in rows]))
    at = {name: i for i, name in enumerate(names)}
    m = np.full((len(names), len(names)), np.nan)
    for r in rows:
        value = r.get(score)
        if value is not None and not isinstance(value, str):
            m[at[r["a"]], at[r["b"]]] = float(value)
    return names, m


def write_matrix(
    out: FilePath,
    score: str = "confidence",
    csv_path: FilePath | None = None,
    png_path: FilePath | None = None,
    truth: Truth | None = None,
) -> tuple[list[str], NDArray[np.float64]]:
    """Writes :func:`matrix` as CSV (a header row of names; empty cells where there is no
    value) and, when ``png_path`` is given, as a heat map (needs matplotlib:
    ``pip install shapecorr[plot]``). Returns ``(names, m)``."""
    names, m = matrix(out, score, truth=truth)
    if csv_path is not None:
        with open(csv_path, "w", encoding="utf-8") as file:
            file.write("," + ",".join(names) + "\n")
            for name, row in zip(names, m):
                cells = ["" if np.isnan(v) else f"{v:.6g}" for v in row]
                file.write(name + "," + ",".join(cells) + "\n")
    if png_path is not None:
        try:
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError as error:
            raise ImportError("the PNG heat map needs matplotlib: pip install shapecorr[plot]") from error
        size = max(4.0, min(20.0, 0.25 * len(names) + 2))
        figure, axes = plt.subplots(figsize=(size + 1, size))
        image = axes.imshow(np.ma.masked_invalid(m), cmap="viridis", interpolation="nearest")
        if len(names) <= 60:
            axes.set_xticks(range(len(names)), names, rotation=90, fontsize=6)
            axes.set_yticks(range(len(names)), names, fontsize=6)
        axes.set_xlabel("B")
        axes.set_ylabel("A")
        axes.set_title(score)
        figure.colorbar(image, ax=axes)
        figure.tight_layout()
        figure.savefig(png_path, dpi=100)
        plt.close(figure)
    return names, m


def consistent_labels(out: FilePath, template: str | None = None) -> dict[str, NDArray[np.int64]]:
    """For a one-to-many run: every shape's regions labelled by the template's regions.
    Returns ``{name: labels}`` with one int per vertex: the template region its region is
    matched to one-to-one, -1 where it is unmatched; the template's own labels as they are.
    ``template`` defaults to the A of the run's pairs (which must be one shape).

    The segmentation is joint per pair, so the template's regions may differ from pair to
    pair; the template's labels are those of its pair with the first B by name, and a region
    of another pair's template takes the label most of its vertices carry there."""
    records = [r for r in _records(out) if r["ok"]]
    templates = {r["a"] for r in records}
    if template is None:
        if len(templates) != 1:
            raise ValueError(f"the run has {len(templates)} shapes as A; name the template")
        template = templates.pop()
    labels: dict[str, NDArray[np.int64]] = {}
    canonical: NDArray[np.int64] | None = None
    for r in sorted((r for r in records if r["a"] == template), key=lambda r: r["b"]):
        regions_a = np.asarray(r["regions_a"], dtype=np.int64)
        if canonical is None:
            canonical = regions_a
            labels[template] = canonical
        # This pair's regions of the template, each to the label most of its vertices carry.
        to_canonical = np.full(max(int(regions_a.max(initial=0)) + 1, 1), -1, dtype=np.int64)
        for region in np.unique(regions_a):
            to_canonical[region] = np.bincount(canonical[regions_a == region]).argmax()
        lookup = np.full(max(r["n_regions_b"], 1), -1, dtype=np.int64)
        for region_a, region_b in r["matches_one_to_one"]:
            lookup[region_b] = to_canonical[region_a]
        labels[r["b"]] = lookup[np.asarray(r["regions_b"], dtype=np.int64)]
    if not labels:
        raise ValueError(f"no finished pair has {template!r} as A")
    return labels


def read_map(out: FilePath, a: str, b: str) -> NDArray[np.uint32]:
    """The map of pair (``a``, ``b``) of a ``maps=True`` run: a vertex of A for every
    vertex of B (numpy uint32)."""
    for r in _records(out):
        if r["a"] == a and r["b"] == b:
            if not r.get("map"):
                raise ValueError(f"pair {a} - {b} has no map ({r.get('error') or 'run without maps'})")
            return np.fromfile(Path(out) / r["map"], dtype="<u4")
    raise KeyError(f"no pair {a} - {b} in {out}")


def _main(argv=None):
    import argparse

    parser = argparse.ArgumentParser(
        prog="python -m shapecorr.batch",
        description="Summary of a batch folder: a table per pair, the n x n matrix of a score "
        "as CSV (and PNG with --png).",
    )
    parser.add_argument("out", help="the batch's output folder")
    parser.add_argument("--score", default="confidence", help="a numeric column (default: confidence)")
    parser.add_argument("--png", action="store_true", help="also write OUT/SCORE.png (matplotlib)")
    args = parser.parse_args(argv)
    rows = summary(args.out)
    print(f"{'a':<24} {'b':<24} {'k':>3} {'regions':>9} {'conf':>6} {'s':>6}  error")
    for r in rows:
        regions = f"{r['regions_a']}/{r['regions_b']}" if r["ok"] else ""
        conf = "" if r["confidence"] is None else f"{r['confidence']:.2f}"
        print(f"{r['a']:<24} {r['b']:<24} {r['k'] or '':>3} {regions:>9} {conf:>6} {r['seconds']:6.2f}  {r['error'] or ''}")
    out = Path(args.out)
    write_matrix(out, args.score, out / f"{args.score}.csv", out / f"{args.score}.png" if args.png else None)
    failed = sum(not r["ok"] for r in rows)
    print(f"{len(rows)} pairs, {failed} failed -> {out / (args.score + '.csv')}")


if __name__ == "__main__":
    _main()
