//! One module per command: its arguments (a `clap::Args` struct) and its `run`.

pub mod bench;
pub mod demo;
pub mod eigen;
pub mod info;
pub mod p2p;
pub mod regions;
pub mod synth;

use std::path::Path;

use shapecorr::{Error, ReadAs, Shape};

/// Reads shape `side` (`'A'` or `'B'`) of a pair; an error names the side and the file.
pub fn read_input(side: char, path: &Path, points: bool) -> Result<Shape, Error> {
    Shape::read(path, ReadAs::point_cloud_when(points)).map_err(|e| match e {
        Error::File { path, reason } => Error::File {
            path,
            reason: format!("shape {side}: {reason}"),
        },
        e => naming_files(e.in_shape(side), path, path),
    })
}

/// An error about shape A or B of a pair ([`Error::InShape`]) as one naming its file too.
pub fn naming_files(e: Error, a: &Path, b: &Path) -> Error {
    match e {
        Error::InShape { side, .. } => Error::file(if side == 'A' { a } else { b }, e.to_string()),
        e => e,
    }
}
