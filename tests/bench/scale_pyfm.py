#!/usr/bin/env python3
"""pyFM (WKS functional map + ZoomOut) on one pair, for `shapecorr bench scale`.

    scale_pyfm.py A.ply B.ply OUT

The recipe, the PLY reader and the settings are those of tests/bench/p2p_vs_pyfm.py (pyFM's
README "Quickstart" of pyfmaps 1.3.1, verbatim). Writes OUT/map_b_to_a.txt (for every vertex
of B its vertex of A, as `shapecorr p2p`) and OUT/result.json with `timings_s` and this
process's peak memory (`peak_memory_mib`, from getrusage). Make the Python with
tests/bench/scale_pyfm.sh (the pinned venv of p2p_vs_pyfm.sh).
"""

import json
import resource
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from p2p_vs_pyfm import run_pyfm, write_map  # noqa: E402


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    a, b, out = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    _, p2p_zoomout, timings = run_pyfm(a, b)
    write_map(out / "map_b_to_a.txt", p2p_zoomout)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    (out / "result.json").write_text(
        json.dumps({"timings_s": timings, "peak_memory_mib": peak}, indent=1)
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
