#!/usr/bin/env bash
# The Python binding's tests: installs the package the way a user does
# (`pip install ./bindings/python`, which ships the compiled library inside it) into a
# virtual environment under target/, then runs its pytest suite against that installed copy.
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=target/py-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --disable-pip-version-check numpy pytest "dask[distributed]" matplotlib
"$venv/bin/python" -m pip install -q --disable-pip-version-check --force-reinstall --no-deps ./bindings/python
# Run from the tests folder so `import shapecorr` finds the installed package, not the source.
cd bindings/python/tests
SHAPECORR_EXPECT_PACKAGED=1 "../../../$venv/bin/python" -m pytest -q -p no:cacheprovider .
