#!/usr/bin/env bash
# Runs every test of the project: the layout limits (tests/layout/check.py: modules at most
# 1,200 lines, functions at most 150); the Rust unit, integration and documentation tests of
# the workspace (the pipeline crate, crates/eval, crates/cli: library, file readers,
# generated figures, spectral identities, region correspondence, command line, the C
# header's drift check; each crate's integration tests are one executable, tests/it/); a
# short run of every fuzz target (tests/fuzz/run.sh: 10 s each); the C API's tests
# (tests/c/run.sh: test_api whole plain and under AddressSanitizer +
# UndefinedBehaviorSanitizer, its ownership tests under valgrind; C++ wrapper; example
# programs); the C/C++ install (tests/install/run.sh: `cargo cinstall` into a temporary
# prefix, then the README's C and C++ examples built with pkg-config and with CMake); the
# Python binding's tests (its wheel built, repaired and installed into a fresh
# target/py-venv); and the Blender extension and MeshLab script headless (bpy and pymeshlab
# from PyPI, in target/blender-venv).
# Needs the Rust toolchain (and its nightly for the fuzz targets), gcc/g++ and python3.
# Installs what is missing: cargo-c with cargo; valgrind, cmake and pkg-config with apt-get;
# numpy, pytest, dask, matplotlib, mypy and trimesh into the test venv, auditwheel into the
# wheel's build venv, bpy and pymeshlab into the Blender venv.
# Tests that need the benchmark data (../shared/data or $SHAPECORR_DATA) skip cleanly
# without it.
#
# What keeps it short on a 2-core machine:
# - One build of the workspace for the Rust and the C tests: `cargo build --release
#   --workspace --all-targets` builds the library (target/release/libshapecorr.so), the tool
#   and every test executable with the features the tests need, and `cargo test` reuses it.
#   A plain `cargo build --release` first would build every dependency twice (proptest and
#   cbindgen turn on features of shared crates, which changes them all). The library built
#   without the test dependencies is still built and tested: it is what `cargo cinstall`
#   installs below, and what the wheel and the Blender extension package.
# - valgrind runs test_api's ownership tests, in two processes at once (tests/c/run.sh says
#   which tests and why).
# - The fuzz targets are built with `cargo +nightly build` and cargo-fuzz's flags: no
#   cargo-fuzz to install (tests/fuzz/run.sh).
# - cargo-c, when missing, is built unoptimised (tests/install/run.sh).
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
