//! The integration tests of the pipeline crate, one module per subject, linked into one test
//! executable (`cargo test --release --test it`; `cargo test --release --test it spectral::`
//! runs one module). One executable links the library and its dependencies once instead of
//! once per file. Tests that need a process of their own start one (limits.rs runs itself
//! again with one global thread). Shapes made by the tests themselves are in common.rs.

mod collection;
mod common;
mod correspondence;
mod dense_limits;
mod determinism;
mod fuzz_regressions;
mod header;
mod heat_geodesics;
mod hypotheses;
mod io_files;
mod limits;
mod low_poly;
mod matching;
mod multiresolution;
mod partial;
mod pieces;
mod point_cloud;
mod pointwise;
mod repairs;
mod segmentation;
mod shape_validation;
mod spectral;
mod symmetry_breaking;
mod synth_figures;
mod transfer;
