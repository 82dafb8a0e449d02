//! One module per command: its arguments (a `clap::Args` struct) and its `run`.

pub mod batch;
pub mod bench;
pub mod demo;
pub mod eigen;
pub mod info;
pub mod p2p;
pub mod regions;
pub mod synth;
pub mod transfer;

use std::path::Path;

use shapecorr::Error;

/// An error about shape A or B of a pair ([`Error::InShape`]) as one naming its file too.
pub fn naming_files(e: Error, a: &Path, b: &Path) -> Error {
    match e {
        Error::InShape { side, .. } => Error::file(if side == 'A' { a } else { b }, e.to_string()),
        e => e,
    }
}
