//! Inputs the fuzz targets (`fuzz/`, docs/fuzzing.md) found crashing, minimised: each must
//! now give a shape or an error, never a panic. Overflows panic only with overflow checks (a
//! debug build, `cargo test` without `--release`, and the fuzz builds).

use std::path::Path;

use shapecorr::ffi::{sc_shape_free, sc_shape_new_point_cloud, ScShape, ScStatus};
use shapecorr::shape::io::parse_ply;
use shapecorr::{Error, ReadAs, Shape};

/// Found by `read_ply`, `shape_new` and `ffi_shape_new`: a cloud of 30 points a unit apart,
/// one point 1e20 away and one 1e30 away. The far-vertex repair drops only the 1e30 one, so
/// the robust size falls back to the cluster's and the 1e20 point's welding cell
/// (`repair::weld`, 1e-6 of the size per cell) saturated at `i64::MAX`, whose neighbour cell
/// `x + 1` overflowed.
#[test]
fn welding_a_point_far_beyond_the_cell_range() {
    const PLY: &[u8] = b"ply\nformat ascii 1.0\nelement vertex 32\nproperty float x\n\
        property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n2 0 0\n3 0 0\n0 1 0\n\
        1 1 0\n2 1 0\n3 1 0\n0 2 0\n1 2 0\n2 2 0\n3 2 0\n0 3 0\n1 3 0\n2 3 0\n3 3 0\n0 0 1\n\
        1 0 1\n2 0 1\n3 0 1\n0 1 1\n1 1 1\n2 1 1\n3 1 1\n0 2 1\n1 2 1\n2 2 1\n3 2 1\n0 3 1\n\
        1 3 1\n1e+20 0 0\n1e+30 0 0\n";
    let raw = parse_ply(PLY, Path::new("weld.ply")).unwrap();
    let xyz: Vec<f64> = raw.vertices.iter().flatten().copied().collect();
    // Too few points are left once the two far ones are left out: an error, not a panic.
    let error = Shape::from_raw(raw, ReadAs::Auto).unwrap_err();
    assert!(matches!(error, Error::TooFewVertices { .. }), "{error}");
    let mut handle: *mut ScShape = std::ptr::null_mut();
    // SAFETY: `xyz` holds 3 * 32 doubles; `handle` is writable and freed below.
    unsafe {
        let status = sc_shape_new_point_cloud(xyz.as_ptr(), 32, &mut handle);
        assert_eq!(status, ScStatus::TooFewVertices);
        sc_shape_free(handle);
    }
}
