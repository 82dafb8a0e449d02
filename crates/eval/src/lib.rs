//! # shapecorr-eval
//!
//! The research harness of [`shapecorr`]: it measures the pipeline, it is not part of it
//! (nothing here reaches `libshapecorr.so`).
//!
//! [`datasets`] reads the benchmark collections (FAUST, TOSCA, SHREC'07, their remeshed
//! versions, non-isometric pairs); [`bench`](mod@bench) scores region correspondences
//! (the paper's Tables 1 and 3), [`bench_pointwise`] point-to-point maps (Table 2) and
//! [`bench_clouds`] the point-cloud protocol; [`reeb`] is the Reeb-graph baseline;
//! [`bench_store`] caches eigenbases and keeps resumable logs; [`bench_all`] runs every table
//! and writes `docs/results.md`; [`plot`] draws the PNG figures; [`bench_tails`] runs every pair of every dataset for
//! `docs/tails.md`; [`bench_scale`] measures time and memory against size (`docs/scale.md`);
//! [`seeded`] gives per-pair seeds and random turns; [`tails`] summarises every
//! score by its mean, median, worst pair and count of failed pairs.

#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bench;
pub mod bench_all;
pub mod bench_clouds;
pub mod bench_pointwise;
pub mod bench_scale;
pub mod bench_store;
pub mod bench_tails;
pub mod datasets;
pub mod plot;
pub mod reeb;
pub mod seeded;
pub mod tails;
