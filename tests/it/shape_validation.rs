//! Bad input gets its typed error; repairable input is repaired and reported, never a panic.

use crate::common;

use common::icosphere;
use shapecorr::NoProgress;
use shapecorr::ReadAs;
use shapecorr::{EigenParams, Eigenbasis, Error, Shape, Warning};

fn sphere() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    icosphere(2) // 162 vertices
}

fn small_basis(shape: &Shape) -> Eigenbasis {
    Eigenbasis::compute(
        shape,
        &EigenParams {
            n_eigenpairs: 12,
            ..Default::default()
        },
        &mut NoProgress,
    )
    .unwrap()
}

#[test]
fn non_finite_coordinates_are_rejected_with_the_vertex() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let (mut v, f) = sphere();
        v[17][1] = bad;
        match Shape::mesh(v.clone(), &f) {
            Err(Error::NonFiniteCoordinate { vertex: 17, .. }) => {}
            other => panic!("expected NonFiniteCoordinate at 17, got {other:?}"),
        }
        assert!(matches!(
            Shape::point_cloud(v),
            Err(Error::NonFiniteCoordinate { vertex: 17, .. })
        ));
    }
}

#[test]
fn face_index_out_of_range_is_rejected() {
    let (v, mut f) = sphere();
    let n = v.len() as u32;
    f[5] = [0, 1, n];
    let err = Shape::mesh(v, &f).unwrap_err();
    assert!(matches!(
        err,
        Error::FaceIndexOutOfRange { face: 5, index, n_vertices } if index == n as u64 && n_vertices == n as usize
    ));
    assert!(err.to_string().contains("face 5"));
}

#[test]
fn faces_with_fewer_than_three_corners_are_rejected() {
    let (v, f) = sphere();
    let mut polygons: Vec<Vec<u32>> = f.iter().map(|t| t.to_vec()).collect();
    polygons[3] = vec![0, 1];
    assert!(matches!(
        Shape::mesh_from_polygons(v, &polygons),
        Err(Error::FaceTooSmall {
            face: 3,
            corners: 2
        })
    ));
}

#[test]
fn empty_and_tiny_shapes_are_rejected() {
    assert!(matches!(
        Shape::mesh(vec![], &[]),
        Err(Error::TooFewVertices { received: 0, .. })
    ));
    assert!(matches!(
        Shape::point_cloud(vec![[0.0, 0.0, 0.0]]),
        Err(Error::TooFewVertices { received: 1, .. })
    ));
    // An octahedron: a valid mesh, but far too small for the pipeline.
    let v = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let f = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    assert!(matches!(
        Shape::mesh(v, &f),
        Err(Error::TooFewVertices { received: 6, .. })
    ));
    // Many vertices, but only a few used by faces.
    let (mut v, _) = sphere();
    v.truncate(100);
    assert!(matches!(
        Shape::mesh(v, &[[0, 1, 2], [1, 2, 3]]),
        Err(Error::TooFewVertices { received: 4, .. })
    ));
}

#[test]
fn zero_area_shapes_are_rejected() {
    // Faces that all repeat a corner.
    let (v, f) = sphere();
    let degenerate: Vec<[u32; 3]> = f.iter().map(|t| [t[0], t[0], t[1]]).collect();
    assert!(matches!(
        Shape::mesh(v.clone(), &degenerate),
        Err(Error::ZeroArea { .. })
    ));
    // A mesh with no faces at all.
    assert!(matches!(Shape::mesh(v, &[]), Err(Error::ZeroArea { .. })));
    // Distinct corners, but every vertex on one line.
    let line: Vec<[f64; 3]> = (0..64).map(|i| [i as f64, 2.0 * i as f64, 0.0]).collect();
    let faces: Vec<[u32; 3]> = (0..62).map(|i| [i, i + 1, i + 2]).collect();
    assert!(matches!(
        Shape::mesh(line, &faces),
        Err(Error::ZeroArea { .. })
    ));
    // A point cloud whose points all coincide.
    assert!(matches!(
        Shape::point_cloud(vec![[1.0, 2.0, 3.0]; 50]),
        Err(Error::ZeroArea { .. })
    ));
}

#[test]
fn degenerate_duplicate_and_flipped_faces_are_repaired_and_reported() {
    let (v, f) = sphere();
    let reference = small_basis(&Shape::mesh(v.clone(), &f).unwrap());
    let mut faces = f.clone();
    faces.push([3, 3, 7]); // repeated corner
    faces.push([f[10][1], f[10][2], f[10][0]]); // duplicate of face 10 (rotated)
    faces[20] = [f[20][0], f[20][2], f[20][1]]; // flipped orientation
    let shape = Shape::mesh(v, &faces).unwrap();
    let w = shape.warnings();
    assert!(
        w.contains(&Warning::DegenerateFacesDropped { count: 1 }),
        "{w:?}"
    );
    assert!(
        w.contains(&Warning::DuplicateFacesDropped { count: 1 }),
        "{w:?}"
    );
    assert!(
        w.contains(&Warning::InconsistentOrientation { edges: 3 }),
        "{w:?}"
    );
    assert_eq!(shape.triangles().len(), f.len());
    // None of it changes the Laplacian's spectrum.
    let repaired = small_basis(&shape);
    for j in 1..12 {
        assert!((repaired.values[j] - reference.values[j]).abs() < 1e-9 * reference.values[j]);
    }
}

#[test]
fn non_manifold_edges_and_quads_are_handled() {
    let (mut v, f) = sphere();
    let mut polygons: Vec<Vec<u32>> = f.iter().map(|t| t.to_vec()).collect();
    // A fin: a triangle hanging off an existing edge makes it non-manifold.
    let [a, b, _] = f[0];
    v.push([3.0, 3.0, 3.0]);
    polygons.push(vec![a, b, (v.len() - 1) as u32]);
    // A separate quad far away.
    let base = v.len() as u32;
    v.extend([
        [10.0, 0.0, 0.0],
        [11.0, 0.0, 0.0],
        [11.0, 1.0, 0.0],
        [10.0, 1.0, 0.0],
    ]);
    polygons.push(vec![base, base + 1, base + 2, base + 3]);
    // As given: the default repairs would leave the far quad out (a far, small piece).
    let shape = Shape::mesh_with(v, &polygons, &shapecorr::Repairs::none()).unwrap();
    let w = shape.warnings();
    assert!(w.contains(&Warning::NonManifoldEdges { count: 1 }), "{w:?}");
    assert!(
        w.contains(&Warning::PolygonsTriangulated { count: 1 }),
        "{w:?}"
    );
    assert!(
        w.contains(&Warning::DisconnectedPieces { count: 2 }),
        "{w:?}"
    );
    assert_eq!(shape.triangles().len(), f.len() + 3);
    let basis = small_basis(&shape);
    assert!(basis.values.iter().all(|x| x.is_finite()));
    // Two pieces: two zero eigenvalues.
    assert!(basis.values[1].abs() < 1e-8 && basis.values[2] > 1e-3);
}

#[test]
fn needle_and_zero_area_triangles_are_mollified() {
    // Split one triangle of the sphere at a point on its edge: one zero-area triangle (a
    // vertex on the edge) and two needles remain valid geometry.
    let (mut v, mut f) = sphere();
    let reference = small_basis(&Shape::mesh(v.clone(), &f).unwrap());
    let [a, b, c] = f[0];
    let (pa, pb) = (v[a as usize], v[b as usize]);
    let t = 1e-9;
    v.push([
        pa[0] + t * (pb[0] - pa[0]),
        pa[1] + t * (pb[1] - pa[1]),
        pa[2] + t * (pb[2] - pa[2]),
    ]);
    let m = (v.len() - 1) as u32;
    f[0] = [a, m, c];
    f.push([m, b, c]);
    // The neighbour across edge a-b still uses the edge a-b: add the zero-area triangle
    // a-m-b (collinear) to keep the surface closed.
    f.push([a, b, m]);
    // As given: the default weld would merge the vertex 1e-9 along the edge into its end.
    let polygons: Vec<Vec<u32>> = f.iter().map(|t| t.to_vec()).collect();
    let shape = Shape::mesh_with(v, &polygons, &shapecorr::Repairs::none()).unwrap();
    assert!(shape
        .warnings()
        .iter()
        .any(|w| matches!(w, Warning::NeedleOrZeroAreaFaces { .. })));
    let basis = small_basis(&shape);
    for j in 1..12 {
        assert!(basis.values[j].is_finite());
        assert!(
            (basis.values[j] - reference.values[j]).abs() < 1e-3 * reference.values[j],
            "eigenvalue {j}: {} vs {}",
            basis.values[j],
            reference.values[j]
        );
    }
}

#[test]
fn duplicate_points_in_a_cloud_are_harmless() {
    let (mut v, _) = icosphere(3);
    let copies: Vec<[f64; 3]> = v[..40].to_vec();
    v.extend(copies);
    let shape = Shape::point_cloud(v).unwrap();
    let basis = small_basis(&shape);
    assert!(basis.values.iter().all(|x| x.is_finite()));
    assert!(basis.values[1] > 1.0);
}

#[test]
fn malformed_files_give_file_errors_naming_the_file() {
    let dir = std::env::temp_dir().join(format!("shapecorr-validation-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases: [(&str, &[u8]); 4] = [
        ("truncated.off", b"OFF\n4 2 0\n0 0 0\n1 0 0\n"),
        ("garbage.ply", b"\x00\x01garbage\xff"),
        ("bad.obj", b"v 1 2\nf 1 2 3\n"),
        ("unknown.stl", b"solid x\n"),
    ];
    for (name, bytes) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let err = Shape::read(&path, ReadAs::Auto).unwrap_err();
        assert!(matches!(err, Error::File { .. }), "{name}: {err:?}");
        assert!(err.to_string().contains(name), "{name}: {err}");
    }
    // A well-formed file whose face refers to a missing vertex: the shape layer's error.
    let path = dir.join("out_of_range.off");
    let mut text = String::from("OFF\n40 1 0\n");
    for i in 0..40 {
        text.push_str(&format!("{} {} 0\n", i % 7, i / 7));
    }
    text.push_str("3 0 1 40\n");
    std::fs::write(&path, text).unwrap();
    assert!(matches!(
        Shape::read(&path, ReadAs::Auto),
        Err(Error::FaceIndexOutOfRange { index: 40, .. })
    ));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn oriented_triangles_turn_flipped_and_inward_faces_outward() {
    let (v, f) = sphere(); // outward-facing
    let same_cycle =
        |t: [u32; 3], u: [u32; 3]| (0..3).any(|r| [t[r], t[(r + 1) % 3], t[(r + 2) % 3]] == u);
    let outward = |faces: &[[u32; 3]]| {
        faces.len() == f.len() && faces.iter().zip(&f).all(|(&t, &u)| same_cycle(t, u))
    };
    // Already consistent and outward: unchanged.
    let shape = Shape::mesh(v.clone(), &f).unwrap();
    assert_eq!(shape.oriented_triangles().unwrap(), f);
    // Every face turned inward, then a few of them back: each of the three is repaired to
    // the outward orientation.
    let inward: Vec<[u32; 3]> = f.iter().map(|t| [t[0], t[2], t[1]]).collect();
    let mut mixed = inward.clone();
    for t in mixed.iter_mut().step_by(7) {
        *t = [t[0], t[2], t[1]];
    }
    let mut few = f.clone();
    for t in few.iter_mut().step_by(11) {
        *t = [t[1], t[0], t[2]];
    }
    for faces in [&inward, &mixed, &few] {
        let shape = Shape::mesh(v.clone(), faces).unwrap();
        assert!(outward(&shape.oriented_triangles().unwrap()));
    }
    // Two spheres, one inward, one outward: each piece on its own.
    let mut two_v = v.clone();
    two_v.extend(v.iter().map(|p| [p[0] + 5.0, p[1], p[2]]));
    let n = v.len() as u32;
    let mut two_f = inward.clone();
    two_f.extend(f.iter().map(|t| t.map(|i| i + n)));
    // The repairs would leave the second sphere out as a separate object.
    let keep_pieces = shapecorr::shape::Repairs {
        debris_fraction: 0.0,
        ..Default::default()
    };
    let polygons: Vec<Vec<u32>> = two_f.iter().map(|t| t.to_vec()).collect();
    let two = Shape::mesh_with(two_v, &polygons, &keep_pieces).unwrap();
    let oriented = two.oriented_triangles().unwrap();
    assert!(outward(&oriented[..f.len()]));
    assert!(oriented[f.len()..]
        .iter()
        .zip(&f)
        .all(|(&t, u)| same_cycle(t, u.map(|i| i + n))));
    // A point cloud's local triangles are turned outward by its normals: on the sphere,
    // every one faces away from the centre (a positive triple product a . (b x c)).
    let cloud = Shape::point_cloud(v.clone()).unwrap();
    let local = cloud
        .oriented_triangles()
        .expect("a sphere's cloud is oriented");
    let faces_out = |[a, b, c]: [[f64; 3]; 3]| {
        a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0])
            > 0.0
    };
    let facing_out = local
        .iter()
        .filter(|t| faces_out(t.map(|i| v[i as usize])))
        .count();
    assert_eq!(
        facing_out,
        local.len(),
        "{facing_out} of {} outward",
        local.len()
    );
}

#[test]
fn a_moebius_strip_has_no_orientation() {
    // A strip of 40 quads around a circle, its ends joined with a half twist.
    let segments = 40u32;
    let mut vertices = Vec::new();
    for i in 0..segments {
        let angle = std::f64::consts::TAU * i as f64 / segments as f64;
        let twist = angle / 2.0;
        for side in [-1.0, 1.0] {
            let r = 2.0 + 0.5 * side * twist.cos();
            vertices.push([r * angle.cos(), r * angle.sin(), 0.5 * side * twist.sin()]);
        }
    }
    let mut faces = Vec::new();
    for i in 0..segments {
        let (a, b) = (2 * i, 2 * i + 1);
        // The last quad joins the first edge upside down (the half twist).
        let (c, d) = if i + 1 < segments {
            (2 * i + 2, 2 * i + 3)
        } else {
            (1, 0)
        };
        faces.push([a, b, d]);
        faces.push([a, d, c]);
    }
    let strip = Shape::mesh(vertices.clone(), &faces).unwrap();
    assert!(strip.oriented_triangles().is_none());
    // The same strip cut open is orientable (its faces were consistent: kept, or all
    // reversed by the sign of the enclosed volume).
    let open: Vec<[u32; 3]> = faces[..faces.len() - 2].to_vec();
    let reversed: Vec<[u32; 3]> = open.iter().map(|t| [t[0], t[2], t[1]]).collect();
    let cut = Shape::mesh(vertices, &open)
        .unwrap()
        .oriented_triangles()
        .unwrap();
    assert!(cut == open || cut == reversed);
}
