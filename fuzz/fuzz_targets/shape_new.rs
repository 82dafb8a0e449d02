//! `Shape` construction (validation and repairs) from decoded vertices and polygons
//! (`shapecorr_fuzz::decode_shape`), with the default, no, or any repairs; then the invariants
//! of the shape made.
//!
//! Input: `how: u8`, the repairs, the shape. `how & 3`: 0 `Shape::mesh` (triangles,
//! default repairs), 1 `Shape::mesh_with` (polygons of any size), 2 `Shape::point_cloud_with`,
//! 3 `Shape::from_raw_with` (`how & 4`: as a point cloud). Repairs by `(how >> 4) & 3`:
//! 0 default, 1 none, 2 default values switched by the bits of the next byte, 3 any values
//! (two `f64` and a byte).
#![no_main]

use libfuzzer_sys::fuzz_target;
use shapecorr::shape::Repairs;
use shapecorr::{ReadAs, Shape, ShapeKind};
use shapecorr_fuzz::{decode_shape, Bytes};

fn repairs(b: &mut Bytes, how: u8) -> Repairs {
    let default = Repairs::default();
    match (how >> 4) & 3 {
        0 => default,
        1 => Repairs::none(),
        2 => {
            let on = b.u8();
            Repairs {
                weld_tolerance: if on & 1 != 0 {
                    default.weld_tolerance
                } else {
                    0.0
                },
                debris_fraction: if on & 2 != 0 {
                    default.debris_fraction
                } else {
                    0.0
                },
                outliers: on & 4 != 0,
                ..Default::default()
            }
        }
        _ => Repairs {
            weld_tolerance: b.f64(),
            debris_fraction: b.f64(),
            outliers: b.u8() & 1 != 0,
            ..Default::default()
        },
    }
}

fn check(shape: &Shape, n: usize) {
    assert_eq!(shape.n_vertices(), n);
    let active = shape.active_vertices();
    assert!(active.len() >= shapecorr::shape::MIN_VERTICES);
    assert!(active.windows(2).all(|w| w[0] < w[1]));
    assert!(active.last().is_some_and(|&v| (v as usize) < n));
    let is_active = |v: u32| active.binary_search(&v).is_ok();
    assert_eq!(shape.representative().len(), n);
    assert!(shape.representative().iter().all(|&r| is_active(r)));
    assert!(shape.triangles().iter().flatten().all(|&v| is_active(v)));
    assert!(shape.n_pieces() >= 1);
    if shape.kind() == ShapeKind::Mesh {
        assert!(shape.mesh_area() > 0.0);
        let _ = shape.oriented_triangles();
    }
    let _ = (shape.edges(), shape.width());
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let how = b.u8();
    let repairs = repairs(&mut b, how);
    let raw = decode_shape(&mut b, how & 3 != 0);
    let n = raw.vertices.len();
    let shape = match how & 3 {
        0 => {
            let triangles: Vec<[u32; 3]> =
                raw.polygons.iter().map(|p| [p[0], p[1], p[2]]).collect();
            Shape::mesh(raw.vertices, &triangles)
        }
        1 => Shape::mesh_with(raw.vertices, &raw.polygons, &repairs),
        2 => Shape::point_cloud_with(raw.vertices, &repairs),
        _ => Shape::from_raw_with(raw, ReadAs::point_cloud_when(how & 4 != 0), &repairs),
    };
    if let Ok(shape) = shape {
        check(&shape, n);
    }
});
