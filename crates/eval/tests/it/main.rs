//! The evaluation harness's integration tests, one module per subject, linked into one test
//! executable (`cargo test --release -p shapecorr-eval --test it`; add `reeb::` to run one
//! module).

mod bench_clouds;
mod datasets;
mod matching_variants;
mod reeb;
