#!/usr/bin/env bash
# The Blender extension and the MeshLab script, headless: installs the `bpy` module (Blender
# as a Python module, about 400 MB, kept in pip's cache and in target/blender-venv between
# runs) and pymeshlab from PyPI, builds the extension zip (blender_addon/build.py) and runs
# both pytest suites against it, with the library as shipped (the `dist` profile; cargo
# builds it here if tests/python/run.sh has not).
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=target/blender-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
# bpy 4.5 is the Blender LTS built for CPython 3.11 (the extension itself needs 4.2+).
"$venv/bin/python" -m pip install -q --disable-pip-version-check "bpy==4.5.*" pymeshlab pytest
cargo build --profile dist --locked -p shapecorr --lib
zip=$("$venv/bin/python" blender_addon/build.py --lib target/dist/libshapecorr.so)
echo "extension: $zip"
SHAPECORR_BLENDER_ZIP="$zip" "$venv/bin/python" -m pytest -q -p no:cacheprovider -rs blender_addon/tests
"$venv/bin/python" -m pytest -q -p no:cacheprovider -rs meshlab_plugin/tests
