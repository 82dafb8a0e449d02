#!/usr/bin/env bash
# The Blender extension and the MeshLab script, headless: installs the `bpy` module (Blender
# as a Python module, about 400 MB a version, kept in pip's cache and in target/blender-venv*
# between runs) and pymeshlab from PyPI, builds the extension zip (blender_addon/build.py) and
# runs the extension's pytest suite on every Blender version it supports, then the MeshLab
# suite, with the library as shipped (the `dist` profile: $SHAPECORR_DIST_LIB, or cargo
# builds it here).
#
# Blender versions: 4.2 LTS (the manifest's minimum), 4.5 LTS and the newest 5.x, all built
# for CPython 3.11. SHAPECORR_BLENDER_VERSIONS="4.5" runs one of them.
set -euo pipefail
cd "$(dirname "$0")/../.."
versions=${SHAPECORR_BLENDER_VERSIONS:-"4.2 4.5 5.0"}
# SHAPECORR_DIST_LIB: a `dist` library already built (tests/run_all.sh passes the one
# `cargo cinstall` built); without it cargo builds one here.
library=${SHAPECORR_DIST_LIB:-target/dist/libshapecorr.so}
[ -n "${SHAPECORR_DIST_LIB:-}" ] || cargo build --profile dist --locked -p shapecorr --lib
for version in $versions; do
    # 4.5 keeps the folder it always had (it also holds pymeshlab for the MeshLab suite).
    venv=target/blender-venv
    [ "$version" = 4.5 ] || venv=target/blender-venv-$version
    if [ ! -x "$venv/bin/python" ]; then
        python3 -m venv "$venv"
    fi
    "$venv/bin/python" -m pip install -q --disable-pip-version-check "bpy==$version.*" pytest
    zip=$("$venv/bin/python" blender_addon/build.py --lib "$library")
    echo "extension: $zip, Blender $("$venv/bin/python" -c 'import bpy; print(bpy.app.version_string)')"
    SHAPECORR_BLENDER_ZIP="$zip" "$venv/bin/python" -m pytest -q -p no:cacheprovider -rs blender_addon/tests
done
venv=target/blender-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --disable-pip-version-check pymeshlab pytest
"$venv/bin/python" -m pytest -q -p no:cacheprovider -rs meshlab_plugin/tests
