//! One module per command: its arguments (a `clap::Args` struct) and its `run`.

pub mod bench;
pub mod demo;
pub mod eigen;
pub mod info;
pub mod p2p;
pub mod regions;
pub mod synth;
