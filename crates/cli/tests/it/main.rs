//! The command line's end-to-end tests, one module per subject, linked into one test
//! executable (`cargo test --release -p shapecorr-cli --test it`; add `hostile::` to run one
//! module). Each runs the `shapecorr` binary of this build; what they share is in common.rs.

mod batch;
mod bench_all;
mod cli;
mod common;
mod files;
mod guidance;
mod hostile;
mod memory_cap;
