#!/usr/bin/env python3
"""Benchmark: shapecorr's eigensolver against scipy's eigsh on the identical problem.

For every shape and k, `shapecorr eigen --export` writes the stiffness L and mass M it built
(unit-area shape) and its eigenpairs; this script then runs scipy.sparse.linalg.eigsh on the
same L and M with the same shift (sigma = -1, i.e. L + M is factored) and compares:
time, peak memory, eigenvalue agreement, relative residuals
||L phi - lambda M phi|| / (lambda ||M phi||), and M-orthonormality.

Usage: python tests/bench/eigen_vs_scipy.py [--data DIR] [--repeat N]
(tests/bench/eigen.sh creates a virtual environment with numpy and scipy and runs this.)
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy
import scipy.io
import scipy.sparse.linalg

ROOT = Path(__file__).resolve().parents[2]
BINARY = ROOT / "target" / "release" / "shapecorr"
SHIFT = 1.0  # shapecorr's EigenParams::default().shift: A = L + SHIFT * M


def run_shapecorr(path, k, outdir):
    out = subprocess.run(
        [str(BINARY), "eigen", str(path), "--k", str(k), "--json", "--export", str(outdir)],
        check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def scipy_child(outdir, k):
    """Runs in a fresh process so that its peak memory is its own."""
    L = scipy.io.mmread(str(Path(outdir) / "L.mtx")).tocsc()
    M = scipy.io.mmread(str(Path(outdir) / "M.mtx")).tocsc()
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t0 = time.perf_counter()
    values, vectors = scipy.sparse.linalg.eigsh(L, k=k, M=M, sigma=-SHIFT, which="LM")
    elapsed = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    order = np.argsort(values)
    np.save(Path(outdir) / "scipy_values.npy", values[order])
    np.save(Path(outdir) / "scipy_vectors.npy", vectors[:, order])
    print(json.dumps({"time": elapsed, "peak_mib": peak / 1024.0, "peak_before_mib": before / 1024.0}))


def quality(L, M, values, vectors):
    m_diag = M.diagonal()
    lv = L @ vectors
    mv = vectors * m_diag[:, None]
    res = np.linalg.norm(lv - mv * values[None, :], axis=0)
    scale = np.maximum(np.abs(values), 1.0) * np.linalg.norm(mv, axis=0)
    rel_res = res / scale
    gram = vectors.T @ mv
    orth = np.abs(gram - np.eye(len(values))).max()
    return rel_res[1:].max(), orth


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", default=os.environ.get("SHAPECORR_DATA", str(ROOT.parent / "shared" / "data")))
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        scipy_child(args.child[0], int(args.child[1]))
        return 0

    data = Path(args.data)
    shapes = [data / "faust" / "tr_reg_000.ply", data / "tosca" / "david0.ply"]
    shapes = [s for s in shapes if s.exists()]
    if not shapes:
        print(f"benchmark data not found under {data}; nothing to measure (set --data or SHAPECORR_DATA)")
        return 0
    if not BINARY.exists():
        print(f"{BINARY} missing: run `cargo build --release` first", file=sys.stderr)
        return 1
    print(f"machine: {os.cpu_count()} cores; numpy {np.__version__}, scipy {scipy.__version__}; "
          f"median of {args.repeat} runs each")
    header = ("shape", "n", "k", "ours_s", "scipy_s", "ratio", "max_rel_dlambda",
              "res_ours", "res_scipy", "orth_ours", "orth_scipy", "mem_ours_MiB", "mem_scipy_MiB")
    print(" | ".join(header))
    rows = []
    for path in shapes:
        for k in (100, 50):
            with tempfile.TemporaryDirectory() as tmp:
                ours = [run_shapecorr(path, k, tmp) for _ in range(args.repeat)]
                t_ours = statistics.median(r["timings_s"]["eigensolve"] for r in ours)
                mem_ours = max(r["peak_memory_mib"] for r in ours)
                theirs = []
                for _ in range(args.repeat):
                    out = subprocess.run([sys.executable, __file__, "--child", tmp, str(k)],
                                         check=True, capture_output=True, text=True)
                    theirs.append(json.loads(out.stdout))
                t_scipy = statistics.median(r["time"] for r in theirs)
                mem_scipy = max(r["peak_mib"] for r in theirs)
                L = scipy.io.mmread(str(Path(tmp) / "L.mtx")).tocsc()
                M = scipy.io.mmread(str(Path(tmp) / "M.mtx")).tocsc()
                n = L.shape[0]
                our_values = np.loadtxt(Path(tmp) / "eigenvalues.txt")
                our_vectors = np.fromfile(Path(tmp) / "eigenvectors.f64", dtype="<f8").reshape((k, n)).T
                sc_values = np.load(Path(tmp) / "scipy_values.npy")
                sc_vectors = np.load(Path(tmp) / "scipy_vectors.npy")
                # Scipy's vectors are Euclidean-orthonormal in the M inner product already
                # (eigsh with M returns M-orthonormal vectors); check both the same way.
                d_lambda = np.abs(our_values[1:] - sc_values[1:]) / np.abs(sc_values[1:])
                res_ours, orth_ours = quality(L, M, our_values, our_vectors)
                res_sc, orth_sc = quality(L, M, sc_values, sc_vectors)
                row = (path.stem, n, k, f"{t_ours:.3f}", f"{t_scipy:.3f}", f"{t_ours / t_scipy:.2f}",
                       f"{d_lambda.max():.1e}", f"{res_ours:.1e}", f"{res_sc:.1e}",
                       f"{orth_ours:.1e}", f"{orth_sc:.1e}", f"{mem_ours:.0f}", f"{mem_scipy:.0f}")
                rows.append(row)
                print(" | ".join(str(x) for x in row), flush=True)
    print("ours_s: shapecorr eigensolve (factorisation + block Lanczos), scipy_s: eigsh(L, k, M, "
          "sigma=-1) (factorisation included); res: max over j>=1 of ||L phi - lambda M phi|| / "
          "(lambda ||M phi||); orth: max |Phi^T M Phi - I|; mem: peak RSS of each process.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
