"""The package as pip installs it from the wheel (tests/python/run.sh): the library inside
it, the licence files and expression, the platform-only wheel tag and the type information
that mypy reads. Skipped unless SHAPECORR_EXPECT_PACKAGED=1: a source checkout has none of
these."""

import importlib.metadata
import os
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

import shapecorr
from shapecorr import _lib

pytestmark = pytest.mark.skipif(
    os.environ.get("SHAPECORR_EXPECT_PACKAGED") != "1",
    reason="only when testing an installed wheel (tests/python/run.sh sets SHAPECORR_EXPECT_PACKAGED=1)",
)

REPOSITORY = Path(__file__).resolve().parents[3]
PACKAGE = Path(shapecorr.__file__).resolve().parent
DISTRIBUTION = importlib.metadata.distribution("shapecorr")


def test_installed_package_uses_its_packaged_library():
    assert PACKAGE.parent == Path(sysconfig.get_paths()["platlib"]).resolve()
    assert _lib.LIBRARY_PATH.parent == PACKAGE
    # Shipped without debug information (the `dist` profile; the target is at most 8 MB).
    size = _lib.LIBRARY_PATH.stat().st_size
    assert size <= 8 * 1024 * 1024, f"packaged library is {size / 2**20:.1f} MiB"


def test_the_licence_files_and_expression_are_installed():
    assert DISTRIBUTION.metadata["License-Expression"] == "MIT OR Apache-2.0"
    licenses = {path.name: path for path in DISTRIBUTION.files if path.parent.name == "licenses"}
    assert sorted(licenses) == ["LICENSE-APACHE", "LICENSE-MIT"]
    for name, path in licenses.items():
        assert path.read_text() == (REPOSITORY / name).read_text(), name


def test_the_wheel_is_tagged_for_the_platform_only():
    """One wheel for every Python 3 (ctypes loads the library; no C extension), repaired to
    a manylinux tag on Linux."""
    wheel = dict(
        line.split(": ", 1) for line in DISTRIBUTION.read_text("WHEEL").splitlines() if ": " in line
    )
    assert wheel["Root-Is-Purelib"] == "false"
    python, abi, platform = wheel["Tag"].split("-")
    assert (python, abi) == ("py3", "none")
    assert platform != "any"
    if sys.platform.startswith("linux"):
        assert platform.startswith("manylinux_"), platform


def test_the_package_is_typed_and_mypy_reads_its_types(tmp_path):
    assert (PACKAGE / "py.typed").is_file()
    wrong = tmp_path / "wrong.py"
    wrong.write_text(
        "import shapecorr\n"
        "name: str = shapecorr.Shape.figure().vertices\n"
        'shapecorr.match(shapecorr.Shape.figure(), "b.ply")\n'
        "shape = shapecorr.Shape.figure()\n"
        "shapecorr.match(shape, shape, k_mx=8)\n"
        'shapecorr.pointwise_map(shape, shape, p2p_refinement="icpp")\n'
        'shapecorr.pointwise_map(shape, shape, p2p_refinement="icp", p2p_regions=2, k_max=8)\n'
    )
    checked = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--no-incremental", str(wrong)],
        capture_output=True, text=True, cwd=tmp_path, timeout=300,
    )
    assert checked.returncode == 1, checked.stdout + checked.stderr
    assert 'expression has type "ndarray[' in checked.stdout and "float64" in checked.stdout
    assert 'Argument 2 to "match" has incompatible type "str"; expected "Shape"' in checked.stdout
    # A misspelt option and a choice's name that does not exist (the options are typed).
    assert 'Unexpected keyword argument "k_mx" for "match"' in checked.stdout
    assert 'Argument "p2p_refinement" to "pointwise_map" has incompatible type' in checked.stdout
    assert "Found 4 errors" in checked.stdout, checked.stdout
