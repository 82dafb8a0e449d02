"""Builds the installable Blender extension zip: the add-on's files, the Python binding
(bindings/python/shapecorr) and the compiled library, for the platform this runs on.

    python blender_addon/build.py            # -> target/blender/shapecorr-<version>-linux_x64.zip

Without --lib it builds the library with the shipping profile (`cargo build --profile dist`:
no debug information). Options: --lib PATH packages an already built library as it is;
--out DIR changes the output folder. To build for another platform, run this on that
platform (the library must be compiled there): it names the zip and the manifest's
`platforms` after it (windows-x64, macos-arm64, macos-x64, linux-arm64).
"""

import argparse
import platform
import re
import subprocess
import sys
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPOSITORY = HERE.parent
SOURCE = HERE / "shapecorr_blender"
BINDING = REPOSITORY / "bindings" / "python" / "shapecorr"
LIBRARY_NAMES = {"linux": "libshapecorr.so", "darwin": "libshapecorr.dylib", "win32": "shapecorr.dll"}
# The manifest's licence (GPL-3.0-or-later, as Blender asks of add-ons) and the project's own.
LICENCES = [HERE / "LICENSE-GPL-3.0", REPOSITORY / "LICENSE-MIT", REPOSITORY / "LICENSE-APACHE"]


def blender_platform():
    system = {"linux": "linux", "darwin": "macos", "win32": "windows"}[sys.platform]
    machine = platform.machine().lower()
    arch = "arm64" if machine in ("arm64", "aarch64") else "x64"
    return f"{system}-{arch}"


def build(library=None, out=None):
    """Builds the zip and returns its path."""
    name = LIBRARY_NAMES[sys.platform]
    if library is None:
        # The shipping profile: the release build without debug information.
        command = ["cargo", "build", "--profile", "dist", "--locked", "-p", "shapecorr", "--lib"]
        subprocess.run(command, cwd=REPOSITORY, check=True)
        library = REPOSITORY / "target" / "dist" / name
    library = Path(library)
    if not library.is_file():
        raise SystemExit(f"no library at {library}")
    manifest = (SOURCE / "blender_manifest.toml").read_text()
    version = re.search(r'^version = "(.*)"$', manifest, re.M).group(1)
    target = blender_platform()
    manifest = re.sub(r"^platforms = .*$", f'platforms = ["{target}"]', manifest, flags=re.M)
    out = Path(out) if out else REPOSITORY / "target" / "blender"
    out.mkdir(parents=True, exist_ok=True)
    zip_path = out / f"shapecorr-{version}-{target.replace('-', '_')}.zip"
    with zipfile.ZipFile(zip_path, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("blender_manifest.toml", manifest)
        for path in sorted(SOURCE.glob("*.py")):
            archive.write(path, path.name)
        for path in sorted(BINDING.glob("*.py")):
            archive.write(path, f"shapecorr/{path.name}")
        archive.write(library, f"shapecorr/{name}")
        for path in LICENCES:
            archive.write(path, path.name)
    return zip_path


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lib", help="an already built libshapecorr to package")
    parser.add_argument("--out", help="output folder (default: target/blender)")
    args = parser.parse_args()
    print(build(args.lib, args.out))


if __name__ == "__main__":
    main()
