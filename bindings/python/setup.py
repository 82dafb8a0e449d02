"""Builds the package with the compiled library inside it.

`pip wheel ./bindings/python` (or `python -m build --wheel bindings/python`, or `pip install
./bindings/python`) runs `cargo build --profile dist --locked -p shapecorr --lib` in the
repository (two levels up): the release build without debug information, the library as
shipped (about 6 MB instead of 33 MB), and copies it (target/dist/libshapecorr.so, .dylib or
shapecorr.dll) into the package.
Set SHAPECORR_LIB to a library file to package that one instead (no cargo needed).

The wheel is tagged `py3-none-<platform>`: the library is loaded with ctypes, so one wheel
serves every Python 3 of that platform (on Linux, `auditwheel repair` then gives it its
manylinux tag). The repository's license files are copied next to this file, where
`license-files` in pyproject.toml can name them.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Distribution, setup
from setuptools.command.bdist_wheel import bdist_wheel
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent
REPOSITORY = HERE.parents[1]
NAMES = {"linux": "libshapecorr.so", "darwin": "libshapecorr.dylib", "win32": "shapecorr.dll"}
LIBRARY_NAME = NAMES.get(sys.platform, "libshapecorr.so")
LICENSE_FILES = ("LICENSE-MIT", "LICENSE-APACHE")


def compiled_library():
    override = os.environ.get("SHAPECORR_LIB")
    if override:
        path = Path(override)
        if not path.is_file():
            # pip runs this file in its own folder: a relative path is not the caller's.
            raise SystemExit(
                f"SHAPECORR_LIB={override} is not a file (seen from {HERE}: give an absolute path)"
            )
        return path
    if not (REPOSITORY / "Cargo.toml").is_file():
        raise SystemExit(
            f"no Cargo.toml in {REPOSITORY}: build from a shapecorr checkout, or set "
            "SHAPECORR_LIB to a compiled library"
        )
    subprocess.run(
        ["cargo", "build", "--profile", "dist", "--locked", "-p", "shapecorr", "--lib"],
        cwd=REPOSITORY,
        check=True,
    )
    return REPOSITORY / "target" / "dist" / LIBRARY_NAME


def copy_license_files():
    """setuptools takes license files from inside the project folder only: the repository's
    are copied here (fresh each build; git ignores the copies). An unpacked sdist has no
    repository around it but carries the copies already."""
    for name in LICENSE_FILES:
        source = REPOSITORY / name
        if source.is_file():
            shutil.copyfile(source, HERE / name)
        elif not (HERE / name).is_file():
            raise SystemExit(f"{name} is neither in {REPOSITORY} nor in {HERE}")


class BuildWithLibrary(build_py):
    def run(self):
        super().run()
        target = Path(self.build_lib) / "shapecorr" / LIBRARY_NAME
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(compiled_library(), target)


class BinaryDistribution(Distribution):
    """The wheel holds a compiled library, so it is platform-specific."""

    def has_ext_modules(self):
        return True


class PlatformWheel(bdist_wheel):
    """Tagged for the platform only (`py3-none-linux_x86_64`, `py3-none-macosx_11_0_arm64`,
    `py3-none-win_amd64`): nothing in the wheel depends on the Python version or its C ABI.
    The platform is setuptools' own (on macOS that of the building Python, `universal2` for
    python.org builds: `--plat-name` or delocate-wheel narrow it to the library's)."""

    def get_tag(self):
        _, _, platform = super().get_tag()
        return "py3", "none", platform


copy_license_files()
setup(
    cmdclass={"build_py": BuildWithLibrary, "bdist_wheel": PlatformWheel},
    distclass=BinaryDistribution,
)
