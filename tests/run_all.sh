#!/usr/bin/env bash
# Runs every test of the project: the Rust unit, integration and documentation tests
# (library, file readers, generated figures, spectral identities, region correspondence,
# command line). The C and Python suites
# join here when the C API lands (issue 4). Installs nothing beyond the Rust toolchain yet.
# Tests that need the benchmark data (../shared/data or $SHAPECORR_DATA) skip cleanly
# without it.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --locked
cargo test --release --locked --all-targets
cargo test --release --locked --doc
