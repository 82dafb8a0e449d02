//! Reading the input shapes: the repairs (on unless `--no-repair`), and the repairs made
//! printed on stderr, one line each, naming the input.

use std::path::Path;

use shapecorr::{Error, ReadAs, Repairs, Shape};

/// Reads `path` as a shape (a point cloud when `points`), with the default repairs unless
/// `no_repair`. The repairs made are printed on stderr as `shapecorr: repaired SIDE (PATH):
/// ...` when `side` names the input (`"A"`, `"B"`).
pub fn read_shape(
    path: &Path,
    points: bool,
    no_repair: bool,
    side: Option<&str>,
) -> Result<Shape, Error> {
    let repairs = if no_repair {
        Repairs::none()
    } else {
        Repairs::default()
    };
    let shape = Shape::read_with(path, ReadAs::point_cloud_when(points), &repairs)?;
    if let Some(side) = side {
        for warning in shape.warnings().iter().filter(|w| w.is_repair()) {
            eprintln!("shapecorr: repaired {side} ({}): {warning}", path.display());
        }
    }
    Ok(shape)
}
