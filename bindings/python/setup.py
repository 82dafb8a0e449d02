"""Builds the package with the compiled library inside it.

`pip install ./bindings/python` runs `cargo build --profile dist --locked -p shapecorr --lib`
in the repository (two levels up): the release build without debug information, the
library as shipped (about 6 MB instead of 33 MB), and copies target/dist/libshapecorr.so
into the package.
Set SHAPECORR_LIB to a library file to package that one instead (no cargo needed).
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent
REPOSITORY = HERE.parents[1]
NAMES = {"linux": "libshapecorr.so", "darwin": "libshapecorr.dylib", "win32": "shapecorr.dll"}
LIBRARY_NAME = NAMES.get(sys.platform, "libshapecorr.so")


def compiled_library():
    override = os.environ.get("SHAPECORR_LIB")
    if override:
        path = Path(override)
        if not path.is_file():
            raise SystemExit(f"SHAPECORR_LIB={override} is not a file")
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


setup(cmdclass={"build_py": BuildWithLibrary}, distclass=BinaryDistribution)
