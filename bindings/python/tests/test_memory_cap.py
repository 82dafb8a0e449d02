"""Under an address-space limit (``ulimit -v``, ``resource.RLIMIT_AS``), ``match`` and
``pointwise_map`` on 5K-vertex figures run to the end under 1 GB and raise
:class:`shapecorr.ResourceLimitError` under 300 MB: the interpreter never dies (before the
fix it aborted, docs/decisions.md, "Address space"). Each case runs in a child interpreter,
which sets the limit on itself after its imports."""

import os
import subprocess
import sys

import pytest

CHILD = r"""
import resource, sys
import shapecorr
a = shapecorr.Shape.figure("humanoid", 0, 5000)
b = shapecorr.Shape.figure("humanoid", 3, 5000)
limit = int(sys.argv[1]) * 1024
resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
for name, job in (("match", shapecorr.match), ("pointwise_map", shapecorr.pointwise_map)):
    try:
        job(a, b)
        print(name, "ok")
    except shapecorr.ResourceLimitError as e:
        print(name, "ResourceLimitError", e)
"""


def run_capped(kib):
    env = dict(os.environ, RAYON_NUM_THREADS="2", OPENBLAS_NUM_THREADS="1")
    return subprocess.run(
        [sys.executable, "-c", CHILD, str(kib)], env=env, capture_output=True, text=True, timeout=300
    )


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS as Linux counts it")
@pytest.mark.parametrize("kib, outcome", [(1_048_576, "ok"), (307_200, "ResourceLimitError")])
def test_jobs_under_an_address_space_limit_end_or_raise_never_abort(kib, outcome):
    child = run_capped(kib)
    assert child.returncode == 0, f"exit {child.returncode}: {child.stdout}{child.stderr}"
    lines = child.stdout.splitlines()
    assert [line.split()[:2] for line in lines] == [["match", outcome], ["pointwise_map", outcome]], (
        child.stdout + child.stderr
    )
    if outcome != "ok":
        assert all("ulimit -v" in line for line in lines), child.stdout
