//! Reading the input shapes: the repairs (on unless `--no-repair`), errors naming the side
//! and the file, and the repairs made printed on stderr, one line each, naming the input.

use std::path::Path;

use shapecorr::{Error, ReadAs, Repairs, Shape};

use crate::commands::naming_files;

/// Reads `path` as a shape (a point cloud when `points`), with the default repairs unless
/// `no_repair`.
pub fn read_shape(path: &Path, points: bool, no_repair: bool) -> Result<Shape, Error> {
    let repairs = if no_repair {
        Repairs::none()
    } else {
        Repairs::default()
    };
    Shape::read_with(path, ReadAs::point_cloud_when(points), &repairs)
}

/// Reads shape `side` (`'A'` or `'B'`) of a pair as [`read_shape`]; an error names the side
/// and the file, and every repair made is printed on stderr as `shapecorr: repaired SIDE
/// (PATH): ...`.
pub fn read_input(side: char, path: &Path, points: bool, no_repair: bool) -> Result<Shape, Error> {
    let shape = read_shape(path, points, no_repair).map_err(|e| match e {
        Error::File { path, reason } => Error::File {
            path,
            reason: format!("shape {side}: {reason}"),
        },
        e => naming_files(e.in_shape(side), path, path),
    })?;
    for warning in shape.warnings().iter().filter(|w| w.is_repair()) {
        eprintln!("shapecorr: repaired {side} ({}): {warning}", path.display());
    }
    Ok(shape)
}
