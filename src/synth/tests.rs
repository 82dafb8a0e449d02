//! Unit tests of the figure pipeline's internals (the public behaviour is tested in
//! `tests/it/synth_figures.rs`).

use super::*;

/// Writes `mesh` as an ASCII OBJ file (for looking at the figures).
fn write_obj(path: &str, mesh: &FigureMesh) {
    use std::io::Write;
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    for v in &mesh.vertices {
        writeln!(f, "v {} {} {}", v[0], v[1], v[2]).unwrap();
    }
    for t in &mesh.triangles {
        writeln!(f, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
}

/// Dumps figures to /tmp/synth_figures for a visual check: `cargo test --lib synth::tests::dump -- --ignored`.
#[test]
#[ignore]
fn dump() {
    std::fs::create_dir_all("/tmp/synth_figures").unwrap();
    let target: usize = std::env::var("SYNTH_TARGET")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5000);
    for kind in [
        FigureKind::Humanoid,
        FigureKind::Quadruped,
        FigureKind::Star { limbs: 5 },
        FigureKind::Star { limbs: 8 },
    ] {
        let poses: Vec<usize> = (0..n_poses(kind)).collect();
        let t = std::time::Instant::now();
        let var = |name: &str| {
            std::env::var(name)
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(1.0)
        };
        let prop = Proportions {
            limb_length: var("SYNTH_LENGTH"),
            limb_thickness: var("SYNTH_THICKNESS"),
            ..Default::default()
        };
        let meshes = figure_poses(kind, target, prop, &poses).unwrap();
        eprintln!(
            "{kind}: {} vertices, {:?}",
            meshes[0].vertices.len(),
            t.elapsed()
        );
        for (p, m) in meshes.iter().enumerate() {
            write_obj(&format!("/tmp/synth_figures/{kind}_{p}.obj"), m);
        }
    }
}

fn kinds() -> Vec<FigureKind> {
    let mut k = vec![FigureKind::Humanoid, FigureKind::Quadruped];
    k.extend((3..=8).map(|limbs| FigureKind::Star { limbs }));
    k
}

/// Skinning turns faces with their bones: each posed face normal agrees with its rest normal
/// turned by the blended rotation of its first corner, so no face flips over (a few faces in
/// the creases of strongly bent joints turn by up to about 90 degrees).
#[test]
fn posed_faces_do_not_flip() {
    use geom::{area_vector, dot, normalize};
    for kind in kinds() {
        let skel = skeleton::skeleton(kind);
        let rest = rest_mesh(&skel, 2500).unwrap();
        let weights = skinning::weights(&skel, &rest.vertices);
        for p in 1..n_poses(kind) {
            let pose = skeleton::pose(kind, &skel, p);
            let posed = skinning::deform(
                &skel,
                &weights,
                &rest.vertices,
                &Proportions::default(),
                &pose,
            );
            let rot = skinning::vertex_rotations(&skel, &weights, rest.vertices.len(), &pose);
            let mut worst = 1.0f64;
            let mut turned = 0;
            for t in &rest.triangles {
                let [a, b, c] = t.map(|i| i as usize);
                let n0 = normalize(area_vector(
                    rest.vertices[a],
                    rest.vertices[b],
                    rest.vertices[c],
                ));
                let n1 = normalize(area_vector(posed[a], posed[b], posed[c]));
                let r = rot[a] * nalgebra::Vector3::from(n0);
                let d = dot([r.x, r.y, r.z], n1);
                worst = worst.min(d);
                if d < 0.5 {
                    turned += 1;
                }
            }
            assert!(
                worst > -0.2,
                "{kind} pose {p}: a face turned over ({worst})"
            );
            assert!(
                turned * 100 < rest.triangles.len(),
                "{kind} pose {p}: {turned} faces turned by more than 60 degrees"
            );
        }
    }
}

/// The weights of every vertex are a partition of unity, and a vertex in the middle of a
/// limb segment follows that segment alone.
#[test]
fn skinning_weights_partition_unity() {
    let skel = skeleton::skeleton(FigureKind::Humanoid);
    let rest = rest_mesh(&skel, 2000).unwrap();
    let w = skinning::weights(&skel, &rest.vertices);
    for v in 0..rest.vertices.len() {
        let s: f64 = w.of(v).map(|(_, x)| x).sum();
        assert!((s - 1.0).abs() < 1e-12);
        assert!(w.of(v).all(|(_, x)| x > 0.0 && x <= 1.0));
    }
    let shin = skel.index("l_shin");
    let cone = skel.bones[shin].shapes[0];
    let mid = geom::lerp(cone.a, cone.b, 0.5);
    let v = (0..rest.vertices.len())
        .min_by(|&a, &b| {
            geom::dist(rest.vertices[a], mid).total_cmp(&geom::dist(rest.vertices[b], mid))
        })
        .unwrap();
    let ws: Vec<(usize, f64)> = w.of(v).collect();
    assert_eq!(ws, vec![(shin, 1.0)]);
}

/// The bone axes, which the polygoniser forces inside, are inside the figure.
#[test]
fn bone_axes_are_inside() {
    for kind in kinds() {
        let skel = skeleton::skeleton(kind);
        let field = field::Field::new(&skel.shapes(), skel.blend);
        for (a, b) in skel.axes() {
            for i in 0..=20 {
                let p = geom::lerp(a, b, i as f64 / 20.0);
                assert!(
                    field.eval(p) < -0.02,
                    "{kind}: axis point {p:?} is not well inside"
                );
            }
        }
    }
}

/// Every kind's rest skeleton is symmetric: mirrored (humanoid, quadruped) or n-fold (stars).
#[test]
fn skeletons_are_symmetric() {
    for kind in kinds() {
        let skel = skeleton::skeleton(kind);
        let field = field::Field::new(&skel.shapes(), skel.blend);
        let transform = |p: geom::V3| match kind {
            FigureKind::Star { limbs } => {
                let (s, c) = (std::f64::consts::TAU / limbs as f64).sin_cos();
                [c * p[0] - s * p[2], p[1], s * p[0] + c * p[2]]
            }
            _ => [-p[0], p[1], p[2]],
        };
        for i in 0..2000 {
            let t = i as f64;
            let p = [
                (t * 0.37).sin() * 0.8,
                0.9 + (t * 0.11).cos() * 0.9,
                (t * 0.23).sin() * 0.7,
            ];
            assert!(
                (field.eval(p) - field.eval(transform(p))).abs() < 1e-9,
                "{kind} at {p:?}"
            );
        }
    }
}
