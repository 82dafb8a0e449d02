//! Whether the outward orientation of generated noisy clouds is right (docs/scans.md, "Point
//! clouds"): clouds sampled by `synth::sample_points` (the CLI's `synth --points`) on
//! generated figures of 3,000 vertices, with noise of 0, 0.2% and 0.5% of the diagonal; each
//! point's normal from [`orient`] against the outward normal of the vertex it stands for.
//!
//!     cargo run --release -p shapecorr-eval --example cloud_orientation_synth

use shapecorr::shape::cloud_orientation::orient;
use shapecorr::synth::{self, FigureKind, FigureSpec};
use shapecorr::Shape;

fn main() -> shapecorr::Result<()> {
    let figures = [
        (FigureKind::Humanoid, 0),
        (FigureKind::Humanoid, 3),
        (FigureKind::Quadruped, 2),
    ];
    for (kind, pose) in figures {
        let mesh = synth::figure(&FigureSpec {
            kind,
            pose,
            target_vertices: 3000,
            ..Default::default()
        })?;
        let shape = Shape::mesh(mesh.vertices.clone(), &mesh.triangles)?;
        let truth = vertex_normals(
            &mesh.vertices,
            &shape.oriented_triangles().unwrap_or_default(),
        );
        for noise in [0.0, 0.002, 0.005] {
            let cloud = synth::sample_points(&mesh, 3000, noise, 3)?;
            let oriented = orient(&cloud.points);
            let wrong = (oriented.normals.iter().zip(&cloud.source_vertex))
                .filter(|(n, &v)| dot(n, &truth[v as usize]) <= 0.0)
                .count();
            println!(
                "{kind:?} pose {pose}, noise {noise}: {wrong} of {} normals not outward; \
                 agreement {:.3}",
                cloud.points.len(),
                oriented.agreement
            );
        }
    }
    Ok(())
}

/// Area-weighted vertex normals of oriented faces.
fn vertex_normals(v: &[[f64; 3]], faces: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut normals = vec![[0.0; 3]; v.len()];
    for t in faces {
        let [a, b, c] = t.map(|i| v[i as usize]);
        let (e, f) = (
            [0, 1, 2].map(|k| b[k] - a[k]),
            [0, 1, 2].map(|k| c[k] - a[k]),
        );
        let n = [
            e[1] * f[2] - e[2] * f[1],
            e[2] * f[0] - e[0] * f[2],
            e[0] * f[1] - e[1] * f[0],
        ];
        for &i in t {
            for k in 0..3 {
                normals[i as usize][k] += n[k];
            }
        }
    }
    normals
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (0..3).map(|k| a[k] * b[k]).sum()
}
