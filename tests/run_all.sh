#!/usr/bin/env bash
# Runs every test of the project: the layout limits (tests/layout/check.py: modules at most
# 1,200 lines, functions at most 150); the Rust unit, integration and documentation tests of
# the workspace (the pipeline crate, crates/eval, crates/cli: library, file readers,
# generated figures, spectral identities, region correspondence, command line, the C
# header's drift check); a short run of every fuzz target (tests/fuzz/run.sh: 10 s each); the
# C API's tests (plain and under AddressSanitizer + UndefinedBehaviorSanitizer, the ownership
# tests under valgrind; C++ wrapper; example programs); the C/C++ install (tests/install/run.sh: `cargo cinstall` into a temporary prefix, then the README's C
# and C++ examples built with pkg-config and with CMake); the Python binding's tests (its
# wheel built, repaired and installed into a fresh target/py-venv); and the Blender extension
# and MeshLab script headless (bpy and pymeshlab from PyPI, in target/blender-venv).
# Needs the Rust toolchain (and its nightly for the fuzz targets), gcc/g++ and python3.
# Installs what is missing: cargo-c with cargo; valgrind, cmake and pkg-config with apt-get;
# numpy, pytest, dask, matplotlib, mypy and trimesh into the test venv, auditwheel into the
# wheel's build venv, bpy and pymeshlab into the Blender venv.
# Tests that need the benchmark data (../shared/data or $SHAPECORR_DATA) skip cleanly
# without it.
#
# Where the time goes on a 2-core machine, and what keeps it short:
# - One build of the workspace for every Rust test and for the C tests: `cargo build
#   --release --workspace --all-targets` builds the library (libshapecorr.so), the tool and
#   the test executables with the features the tests need, so `cargo test` links nothing
#   more. (A plain `cargo build --release` would build every dependency a second time:
#   proptest and cbindgen turn on features of shared crates. The library as built without
#   the test dependencies is what `cargo cinstall` builds and installs below.) Each crate's
#   integration tests are one executable (tests/it/), linked once.
# - valgrind runs the C API's ownership tests, in two processes at once (tests/c/run.sh).
# - The fuzz targets are built with `cargo +nightly build` and cargo-fuzz's flags, with no
#   cargo-fuzz to install (tests/fuzz/run.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
python3 tests/layout/check.py
cargo build --release --locked --workspace --all-targets
cargo test --release --locked --workspace --all-targets
cargo test --release --locked --workspace --doc
bash tests/fuzz/run.sh
bash tests/c/run.sh
bash tests/install/run.sh
# The wheel and the Blender zip package the library `cargo cinstall` just built (the same
# `dist` profile): the shipped library is built once, not twice (4-5 minutes less), and
# every package carries the same bits. Run alone, those scripts build it with cargo.
export SHAPECORR_DIST_LIB=$PWD/target/install-tests/prefix/lib/libshapecorr.so
bash tests/python/run.sh
bash tests/blender/run.sh
