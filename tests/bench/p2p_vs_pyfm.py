#!/usr/bin/env python3
"""Point-to-point maps: shapecorr vs pyFM (WKS functional map + ZoomOut), same pairs, same clock.

Run it through tests/bench/p2p_vs_pyfm.sh, which makes the pinned venv (target/pyfm-venv),
builds the release binary and pins every BLAS/OpenMP pool to one thread.

pyFM settings (pyfmaps==1.3.1, the version pinned in p2p_vs_pyfm.sh)
---------------------------------------------------------------------
The pyFM side is pyFM's README "Quickstart" of that exact release, verbatim (it is the
long_description of the PyPI package, i.e. `pyfmaps-1.3.1.dist-info/METADATA` in the venv; the
same recipe is in the repository's gallery example examples/gallery/plot_05_maps_without_
correspondence.py, RobinMagnet/pyFM):

    mesh1 = TriMesh.load(A, area_normalize=True, center=True)
    mesh2 = TriMesh.load(B, area_normalize=True, center=True)
    model = FunctionalMapping(mesh1, mesh2)
    model.preprocess(descr_type="WKS", subsample_step=2)
    model.fit(K=30, w_descr=1e0, w_lap=1e-1, w_dcomm=1e0, w_orient=1e0)
    p2p_21 = model.get_p2p()                          # -> OUT/pyfm_wks/
    FM_zo = model.zoomout_refine(nit=16, step=5)
    p2p_21_zo = model.get_p2p(FM_zo)                  # -> OUT/pyfm/

Everything not written there is the library default of pyfmaps 1.3.1 (pyFM/functional.py):
preprocess(n_descr=100, k_process=200 eigenpairs per shape, k_descr=128, no landmarks,
l2-normalised descriptors); TriMesh.process(k=200, intrinsic=False) = cotangent Laplacian;
fit(use_resolvent_laplacian=True, resolvent_gamma=0.5, optinit="zeros", L-BFGS-B factr=1e7,
pgtol=1e-5); zoomout_refine(subsample=None) = ZoomOut on all vertices, K 30 -> 110;
get_p2p(use_adj=False, n_jobs=None) = one-job sklearn nearest-neighbour search.
Note w_orient=1 is the README's value (the fit() default is 0; the README keeps it above 0
because descriptors alone cannot tell left from right).

The only deviation: pyFM's TriMesh.load reads .off/.obj only, and the benchmark shapes are
.ply, so the PLY is parsed here with numpy (read_ply below) and handed to
TriMesh(vertices, faces, area_normalize=True, center=True), which is what TriMesh.load does
after reading the file. The parse is inside pyFM's timed span.

Direction: mesh1 = A = source, mesh2 = B = target. pyFM's p2p_21[i] is the vertex of mesh1
matched to vertex i of mesh2, i.e. for every vertex of B its vertex on A: the same convention
as shapecorr's map_b_to_a.txt. One 0-based index per line, n_B lines.

Timing: pyFM from reading the two files to the final ZoomOut map (both eigenbases, WKS,
fit, conversion, ZoomOut), time.perf_counter(); the WKS-only map is timed up to its own
get_p2p(). Ours: wall clock of the `shapecorr p2p` subprocess, once with RAYON_NUM_THREADS=1
and once with default threads; its own result.json timings_s.total is recorded too.

Errors are measured by one tool for all methods: `shapecorr bench maps` (geodesic error on A
per vertex of B, flip-tolerant variant via the mirror maps); see evaluate().
The data is research-only: nothing here copies shapes, outputs go under --out.
"""

import argparse
import json
import os
import platform
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
LAYOUTS = {"faust": "faust", "tosca": "tosca"}  # pair-file stem -> sub-folder of --data
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")

PYFM_SETTINGS = {
    "source": "pyfmaps 1.3.1 README Quickstart (PyPI long_description; "
    "RobinMagnet/pyFM examples/gallery/plot_05_maps_without_correspondence.py)",
    "trimesh": {"area_normalize": True, "center": True},
    "preprocess": {"descr_type": "WKS", "subsample_step": 2},
    "fit": {"K": 30, "w_descr": 1e0, "w_lap": 1e-1, "w_dcomm": 1e0, "w_orient": 1e0},
    "zoomout_refine": {"nit": 16, "step": 5},
    "library_defaults": "preprocess n_descr=100 k_process=200 k_descr=128; "
    "zoomout subsample=None; get_p2p n_jobs=None",
}


# --------------------------------------------------------------------------- input


def read_pairs(path, limit=None):
    pairs = []
    for line in Path(path).read_text().splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        cols = line.split("\t")
        if len(cols) < 2:
            sys.exit(f"{path}: bad pair line {line!r} (want: source<TAB>target<TAB>category)")
        cat = cols[2].strip() if len(cols) > 2 else ""
        pairs.append((cols[0].strip(), cols[1].strip(), cat))
    if limit is not None:
        pairs = pairs[:limit]
    return pairs


def shape_path(data, layout, name):
    return Path(data) / layout / f"{name}.ply"


_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}


def read_ply(path):
    """(vertices (n,3) float64, faces (m,3) int64) of a triangle-mesh PLY, file order kept.

    Handles ascii and binary little/big endian, any vertex properties (x, y, z are picked
    out), and a face element whose only property is the vertex-index list (all triangles)."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            raise ValueError(f"{path}: not a PLY file")
        fmt, elements = None, []
        while True:
            line = f.readline()
            if not line:
                raise ValueError(f"{path}: PLY header has no end_header")
            tok = line.decode("ascii", "replace").split()
            if not tok or tok[0] in ("comment", "obj_info"):
                continue
            if tok[0] == "end_header":
                break
            if tok[0] == "format":
                fmt = tok[1]
            elif tok[0] == "element":
                elements.append([tok[1], int(tok[2]), []])
            elif tok[0] == "property":
                elements[-1][2].append(tok[1:])
        body = f.read()

    if fmt == "ascii":
        return _read_ply_ascii(path, elements, body)
    if fmt not in ("binary_little_endian", "binary_big_endian"):
        raise ValueError(f"{path}: unsupported PLY format {fmt!r}")
    end = "<" if fmt == "binary_little_endian" else ">"
    offset, verts, faces = 0, None, None
    for name, count, props in elements:
        if any(p[0] == "list" for p in props):
            if name != "face" or len(props) != 1:
                raise ValueError(f"{path}: unsupported list element {name!r}")
            _, ctype, itype, _ = props[0]
            cdt, idt = np.dtype(end + _PLY_TYPES[ctype]), np.dtype(end + _PLY_TYPES[itype])
            # Fast path: every face a triangle -> fixed-size records.
            rec = np.dtype([("n", cdt), ("v", idt, (3,))])
            arr = np.frombuffer(body, dtype=rec, count=count, offset=offset)
            if not np.all(arr["n"] == 3):
                raise ValueError(f"{path}: only triangle faces are supported")
            faces = arr["v"].astype(np.int64)
            offset += rec.itemsize * count
        else:
            rec = np.dtype([(p[1], end + _PLY_TYPES[p[0]]) for p in props])
            arr = np.frombuffer(body, dtype=rec, count=count, offset=offset)
            offset += rec.itemsize * count
            if name == "vertex":
                verts = np.stack([arr["x"], arr["y"], arr["z"]], axis=1).astype(np.float64)
    if verts is None or faces is None:
        raise ValueError(f"{path}: needs vertex and face elements")
    return verts, faces


def _read_ply_ascii(path, elements, body):
    lines = iter(body.decode("ascii").splitlines())
    verts, faces = None, None
    for name, count, props in elements:
        rows = [next(lines).split() for _ in range(count)]
        if name == "vertex":
            names = [p[-1] for p in props]
            idx = [names.index(c) for c in ("x", "y", "z")]
            verts = np.array([[float(r[i]) for i in idx] for r in rows], dtype=np.float64)
        elif name == "face":
            if any(int(r[0]) != 3 for r in rows):
                raise ValueError(f"{path}: only triangle faces are supported")
            faces = np.array([[int(x) for x in r[1:4]] for r in rows], dtype=np.int64)
    if verts is None or faces is None:
        raise ValueError(f"{path}: needs vertex and face elements")
    return verts, faces


def write_map(path, p2p):
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(path, np.asarray(p2p, dtype=np.int64), fmt="%d")


# --------------------------------------------------------------------------- pyFM


def run_pyfm(path_a, path_b):
    """pyFM README recipe on (A, B). Returns (p2p_21 WKS-only, p2p_21 ZoomOut, timings)."""
    from pyFM.functional import FunctionalMapping
    from pyFM.mesh import TriMesh

    s = PYFM_SETTINGS
    t = {}
    t0 = time.perf_counter()
    va, fa = read_ply(path_a)
    vb, fb = read_ply(path_b)
    mesh1 = TriMesh(va, fa, **s["trimesh"])
    mesh2 = TriMesh(vb, fb, **s["trimesh"])
    t["load"] = time.perf_counter() - t0

    t1 = time.perf_counter()
    model = FunctionalMapping(mesh1, mesh2)
    model.preprocess(**s["preprocess"])
    t["preprocess"] = time.perf_counter() - t1  # both eigenbases + WKS

    t1 = time.perf_counter()
    model.fit(**s["fit"])
    t["fit"] = time.perf_counter() - t1

    t1 = time.perf_counter()
    p2p_wks = model.get_p2p()
    t["p2p"] = time.perf_counter() - t1
    t["total_wks"] = time.perf_counter() - t0

    t1 = time.perf_counter()
    fm_zo = model.zoomout_refine(**s["zoomout_refine"])
    p2p_zo = model.get_p2p(fm_zo)
    t["zoomout"] = time.perf_counter() - t1
    t["total"] = time.perf_counter() - t0

    n_b = mesh2.n_vertices
    assert p2p_zo.shape == (n_b,) and p2p_wks.shape == (n_b,), "p2p_21 must have n_B entries"
    assert p2p_zo.max() < mesh1.n_vertices
    return p2p_wks, p2p_zo, t


def pyfm_self_error(path_a, path_b, maps, n_samples=300, seed=0):
    """Cross-check (not timed, identity ground truth only): pyFM's own way of scoring a map,
    as in its gallery examples: mean heat-method geodesic distance on A (unit area) between
    the matched and the true vertex, over n_samples farthest-point samples of B."""
    from pyFM.mesh import TriMesh

    va, fa = read_ply(path_a)
    vb, fb = read_ply(path_b)
    if len(va) != len(vb):
        return {k: None for k in maps}
    mesh1 = TriMesh(va, fa, area_normalize=True, center=True)
    mesh2 = TriMesh(vb, fb, area_normalize=True, center=True)
    np.random.seed(seed)
    sub = mesh2.farthest_point_sampling(n_samples)
    dist = mesh1.geodesic_from(sub)  # (n1, n_samples): distances to the true vertices
    cols = np.arange(len(sub))
    return {
        k: (None if p is None else float(dist[np.asarray(p)[sub], cols].mean() / mesh1.sqrt_area))
        for k, p in maps.items()
    }


# --------------------------------------------------------------------------- ours


def run_ours(binary, path_a, path_b, out_dir, one_thread):
    env = dict(os.environ)
    if one_thread:
        env["RAYON_NUM_THREADS"] = "1"
    else:
        env.pop("RAYON_NUM_THREADS", None)
    if out_dir.exists():
        shutil.rmtree(out_dir)
    cmd = [str(binary), "p2p", str(path_a), str(path_b), "--out", str(out_dir)]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    rec = {"wall_s": wall, "ok": proc.returncode == 0, "cmd": " ".join(cmd)}
    if proc.returncode != 0:
        rec["error"] = first_error_line(proc)
        return rec
    try:
        res = json.loads((out_dir / "result.json").read_text())
        rec["total_s"] = res.get("timings_s", {}).get("total")
    except (OSError, ValueError) as e:
        rec["total_s"] = None
        rec["warning"] = f"result.json unreadable: {e}"
    if not (out_dir / "map_b_to_a.txt").exists():
        rec["ok"] = False
        rec["error"] = "no map_b_to_a.txt written"
    return rec


# --------------------------------------------------------------------------- evaluation


def evaluate(binary, data, pairs_file, limit, maps_dir, json_path):
    """`shapecorr bench maps` on one maps folder -> {(source, target): pair record} or None.

    Expected JSON: {"pairs": [{"source", "target", "category", "mean_error",
    "mean_error_flip" (or null), "within_005", "within_010"}], ...}."""
    cmd = [str(binary), "bench", "maps", "--data", str(data), "--pairs", str(pairs_file),
           "--maps", str(maps_dir), "--json", str(json_path)]
    if limit is not None:
        cmd += ["--limit", str(limit)]
    ok, why = has_subcommand(binary, "bench", "maps")
    if not ok:
        print(f"  {maps_dir.name}: not evaluated, this build has no `shapecorr bench maps` "
              f"({why}). The maps are kept in {maps_dir}; evaluate them later with:\n"
              f"    {' '.join(cmd)}")
        return None
    if json_path.exists():
        json_path.unlink()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0 or not json_path.exists():
        print(f"  {maps_dir.name}: `shapecorr bench maps` failed (exit {proc.returncode}: "
              f"{first_error_line(proc)}); command:\n    {' '.join(cmd)}")
        return None
    try:
        doc = json.loads(json_path.read_text())
        return {(p["source"], p["target"]): p for p in doc["pairs"]}
    except (ValueError, KeyError, TypeError) as e:
        print(f"  evaluation of {maps_dir.name}: {json_path} is not the expected JSON ({e})")
        return None


def flip_tolerant(p):
    e, f = p.get("mean_error"), p.get("mean_error_flip")
    if e is None:
        return None
    return e if f is None else min(e, f)


def first_error_line(proc):
    """The most telling line of a failed command's output (clap puts it first)."""
    lines = [s.strip() for s in (proc.stderr + "\n" + proc.stdout).splitlines() if s.strip()]
    for line in lines:
        if line.lower().startswith("error"):
            return line
    return lines[0] if lines else f"exit {proc.returncode}"


def has_subcommand(binary, *sub):
    if not Path(binary).exists():
        return False, f"{binary} not built"
    proc = subprocess.run([str(binary), *sub, "--help"], capture_output=True, text=True)
    return proc.returncode == 0, (None if proc.returncode == 0 else first_error_line(proc))


def mean(xs):
    xs = [x for x in xs if x is not None]
    return float(np.mean(xs)) if xs else None


# --------------------------------------------------------------------------- main


def blas_report():
    try:
        from threadpoolctl import threadpool_info

        return [{k: i.get(k) for k in ("user_api", "internal_api", "num_threads", "version")}
                for i in threadpool_info()]
    except Exception as e:  # noqa: BLE001 - informational only
        return [{"error": str(e)}]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", required=True, help="benchmark data root (has faust/, tosca/)")
    ap.add_argument("--pairs", required=True, help="pair list: faust.txt or tosca.txt")
    ap.add_argument("--limit", type=int, default=None, help="first N pairs only")
    ap.add_argument("--out", default=str(REPO / "target" / "p2p_vs_pyfm"))
    ap.add_argument("--shapecorr", default=str(REPO / "target" / "release" / "shapecorr"))
    ap.add_argument("--skip-pyfm", action="store_true", help="keep existing OUT/pyfm maps")
    ap.add_argument("--skip-ours", action="store_true", help="keep existing OUT/ours maps")
    ap.add_argument("--pyfm-self-error", action="store_true",
                    help="also score maps pyFM's own way (heat geodesics, 300 samples, "
                         "identity ground truth); not timed, slower")
    args = ap.parse_args()

    data, out, binary = Path(args.data), Path(args.out), Path(args.shapecorr)
    stem = Path(args.pairs).stem
    if stem not in LAYOUTS:
        sys.exit(f"--pairs: layout follows the file name; know {sorted(LAYOUTS)}, got {stem!r}")
    layout = LAYOUTS[stem]
    pairs = read_pairs(args.pairs, args.limit)
    if not pairs:
        sys.exit(f"{args.pairs}: no pairs")
    out.mkdir(parents=True, exist_ok=True)

    import scipy
    import sklearn
    from importlib.metadata import version as dist_version

    pyfm_version = dist_version("pyfmaps")

    threads = {v: os.environ.get(v) for v in THREAD_VARS}
    blas = blas_report()
    print(f"p2p_vs_pyfm: {len(pairs)} pairs of {args.pairs} ({layout}), out {out}")
    print(f"pyFM {pyfm_version}, numpy {np.__version__}, scipy {scipy.__version__}, "
          f"scikit-learn {sklearn.__version__}, python {platform.python_version()}, "
          f"{os.cpu_count()} CPUs")
    print("threads: " + ", ".join(f"{k}={v}" for k, v in threads.items())
          + "; BLAS pools: " + ", ".join(f"{b.get('internal_api')}={b.get('num_threads')}"
                                         for b in blas if "error" not in b))
    if any(v != "1" for v in threads.values()):
        print("WARNING: BLAS/OpenMP not pinned to one thread; run through p2p_vs_pyfm.sh")
    print("pyFM settings: " + json.dumps({k: v for k, v in PYFM_SETTINGS.items()
                                          if k not in ("source", "library_defaults")}))
    have_ours = False
    if not args.skip_ours:
        have_ours, why = has_subcommand(binary, "p2p")
        if not have_ours:
            print(f"WARNING: our side is skipped: no `shapecorr p2p` in this build ({why})")

    previous = {}  # with --skip-*, keep the timings of the run that made the kept maps
    if (args.skip_pyfm or args.skip_ours) and (out / "runs.json").exists():
        try:
            previous = {(r["source"], r["target"]): r
                        for r in json.loads((out / "runs.json").read_text())}
        except (ValueError, KeyError, TypeError):
            previous = {}

    records = []
    for i, (src, tgt, cat) in enumerate(pairs):
        pa, pb = shape_path(data, layout, src), shape_path(data, layout, tgt)
        key = f"{src}__{tgt}"
        rec = {"source": src, "target": tgt, "category": cat}
        for p in (pa, pb):
            if not p.exists():
                sys.exit(f"missing shape {p}")
        line = f"[{i + 1}/{len(pairs)}] {src} -> {tgt}:"

        old = previous.get((src, tgt), {})
        for k in (["pyfm"] if args.skip_pyfm else []) + (
                ["ours_1t", "ours_default", "ours_same_map_both_thread_counts"]
                if args.skip_ours else []):
            if k in old:
                rec[k] = old[k]

        maps = {}
        if not args.skip_pyfm:
            try:
                p2p_wks, p2p_zo, t = run_pyfm(pa, pb)
                write_map(out / "pyfm" / f"{key}.txt", p2p_zo)
                write_map(out / "pyfm_wks" / f"{key}.txt", p2p_wks)
                rec["pyfm"] = {"ok": True, "timings_s": t}
                maps.update(pyfm=p2p_zo, pyfm_wks=p2p_wks)
                line += f" pyFM {t['total']:.2f}s (WKS {t['total_wks']:.2f}s)"
            except Exception as e:  # noqa: BLE001 - one failed pair must not stop the run
                rec["pyfm"] = {"ok": False, "error": f"{type(e).__name__}: {e}"}
                line += f" pyFM FAILED ({type(e).__name__}: {e})"

        if have_ours and not args.skip_ours:
            r1 = run_ours(binary, pa, pb, out / "ours_run" / key, one_thread=True)
            rd = run_ours(binary, pa, pb, out / "ours_run_default" / key, one_thread=False)
            rec["ours_1t"], rec["ours_default"] = r1, rd
            if r1["ok"]:
                dst = out / "ours" / f"{key}.txt"
                dst.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(out / "ours_run" / key / "map_b_to_a.txt", dst)
                maps["ours"] = np.loadtxt(dst, dtype=np.int64, ndmin=1)
                if rd["ok"]:
                    rec["ours_same_map_both_thread_counts"] = bool(np.array_equal(
                        maps["ours"],
                        np.loadtxt(out / "ours_run_default" / key / "map_b_to_a.txt",
                                   dtype=np.int64, ndmin=1)))
                line += f" ours {r1['wall_s']:.2f}s 1t"
            else:
                line += f" ours FAILED ({r1.get('error')})"
            line += f", {rd['wall_s']:.2f}s default" if rd["ok"] else ""

        if args.pyfm_self_error and maps:
            rec["self_error"] = pyfm_self_error(pa, pb, maps)
            line += " | pyFM-style error " + ", ".join(
                f"{k} {v:.4f}" for k, v in rec["self_error"].items() if v is not None)
        print(line, flush=True)
        records.append(rec)
        (out / "runs.json").write_text(json.dumps(records, indent=1))

    # ---- evaluation by our CLI, the same for every method
    print("\nevaluation: shapecorr bench maps")
    methods = [("pyfm_wks", "pyFM WKS fit (no refinement)"),
               ("pyfm", "pyFM WKS + ZoomOut"),
               ("ours", "shapecorr p2p")]
    evals = {}
    for m, _ in methods:
        if (out / m).is_dir():
            evals[m] = evaluate(binary, data, args.pairs, args.limit, out / m,
                                out / f"{m}_eval.json")

    # ---- aggregate
    def times(method):
        if method == "pyfm":
            return [r["pyfm"]["timings_s"]["total"] for r in records if r.get("pyfm", {}).get("ok")]
        if method == "pyfm_wks":
            return [r["pyfm"]["timings_s"]["total_wks"] for r in records
                    if r.get("pyfm", {}).get("ok")]
        return [r["ours_1t"]["wall_s"] for r in records if r.get("ours_1t", {}).get("ok")]

    summary = {"pairs_file": str(args.pairs), "data": str(data), "n_pairs": len(pairs),
               "limit": args.limit, "threads": threads, "blas": blas,
               "cpus": os.cpu_count(), "pyfm_version": pyfm_version,
               "numpy": np.__version__, "scipy": scipy.__version__,
               "scikit_learn": sklearn.__version__, "pyfm_settings": PYFM_SETTINGS,
               "methods": {}, "pairs": records}
    for m, label in methods:
        ev = evals.get(m) or {}
        pe = list(ev.values())
        agg = {"label": label, "n_timed": len(times(m)), "mean_s_per_pair": mean(times(m)),
               "n_evaluated": len(pe), "mean_error": mean([p.get("mean_error") for p in pe]),
               "mean_error_flip_tolerant": mean([flip_tolerant(p) for p in pe]),
               "within_005": mean([p.get("within_005") for p in pe]),
               "within_010": mean([p.get("within_010") for p in pe])}
        if m == "ours":
            agg["mean_s_per_pair_default_threads"] = mean(
                [r["ours_default"]["wall_s"] for r in records
                 if r.get("ours_default", {}).get("ok")])
            agg["mean_own_total_s_1t"] = mean(
                [r["ours_1t"].get("total_s") for r in records if r.get("ours_1t", {}).get("ok")])
            same = [r["ours_same_map_both_thread_counts"] for r in records
                    if "ours_same_map_both_thread_counts" in r]
            agg["same_map_1t_vs_default"] = f"{sum(same)}/{len(same)}"
        if args.pyfm_self_error:
            agg["pyfm_style_error"] = mean([r.get("self_error", {}).get(m) for r in records])
        summary["methods"][m] = agg

    # speed ratio on the pairs both sides finished
    both = [r for r in records if r.get("pyfm", {}).get("ok") and r.get("ours_1t", {}).get("ok")]
    ratio = {}
    if both:
        py = sum(r["pyfm"]["timings_s"]["total"] for r in both)
        ratio["pyfm_over_ours_1thread"] = py / sum(r["ours_1t"]["wall_s"] for r in both)
        both_d = [r for r in both if r.get("ours_default", {}).get("ok")]
        if both_d:
            ratio["pyfm_over_ours_default_threads"] = (
                sum(r["pyfm"]["timings_s"]["total"] for r in both_d)
                / sum(r["ours_default"]["wall_s"] for r in both_d))
        ratio["n_pairs"] = len(both)
    summary["speed_ratio"] = ratio

    def f(x, w=9, p=4):
        return f"{x:{w}.{p}f}" if x is not None else f"{'n/a':>{w}}"

    print(f"\n{len(pairs)} pairs of {Path(args.pairs).name}; pyFM and BLAS on one thread "
          f"(OMP/OPENBLAS/MKL_NUM_THREADS=1); ours timed with RAYON_NUM_THREADS=1 and default "
          f"({os.cpu_count()} CPUs). Errors: geodesic on A, unit-area units, by "
          f"`shapecorr bench maps`.")
    print(f"{'method':32s} {'err':>9s} {'flip-tol':>9s} {'<0.05':>7s} {'<0.10':>7s} "
          f"{'s/pair':>8s} {'s/pair*':>8s}")
    for m, label in methods:
        a = summary["methods"][m]
        print(f"{label:32s} {f(a['mean_error'])} {f(a['mean_error_flip_tolerant'])} "
              f"{f(a['within_005'], 7, 3)} {f(a['within_010'], 7, 3)} "
              f"{f(a['mean_s_per_pair'], 8, 2)} "
              f"{f(a.get('mean_s_per_pair_default_threads'), 8, 2) if m == 'ours' else ''}")
    print("s/pair: one thread (ours: RAYON_NUM_THREADS=1); s/pair*: ours with default threads")
    if args.pyfm_self_error:
        print("pyFM-style error (heat geodesics, 300 FPS samples): " + ", ".join(
            f"{m} {f(summary['methods'][m].get('pyfm_style_error'), 0)}" for m, _ in methods))
    if ratio:
        print(f"speed ratio pyFM(WKS+ZoomOut) / ours over {ratio['n_pairs']} pairs: "
              f"{ratio['pyfm_over_ours_1thread']:.2f}x (1 thread)"
              + (f", {ratio['pyfm_over_ours_default_threads']:.2f}x (default threads)"
                 if "pyfm_over_ours_default_threads" in ratio else ""))
    else:
        print("speed ratio: n/a (no pair finished on both sides)")
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    print(f"wrote {out / 'summary.json'}")


if __name__ == "__main__":
    main()
