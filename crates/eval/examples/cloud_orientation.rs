//! How far a point cloud's orientation can be trusted (docs/scans.md, "Point clouds"): for
//! every mesh file given, its vertices jittered by 0.2% of the height as a cloud, the share
//! of local triangles that agree with their corners' normals
//! ([`cloud_orientation::OrientedCloud::agreement`]) and the share of normals that agree
//! with the mesh's own outward vertex normals (the truth). With `--synth`, the same for
//! clouds sampled by `synth::sample_points` (the CLI's `synth --points`) on generated
//! figures of 3,000 vertices with noise of 0, 0.2% and 0.5% of the diagonal, each point
//! against the outward normal of the vertex it stands for.
//!
//!     cargo run --release -p shapecorr-eval --example cloud_orientation -- FILE ..
//!     cargo run --release -p shapecorr-eval --example cloud_orientation -- --synth

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shapecorr::shape::cloud_orientation::{orient, TRUSTED_AGREEMENT};
use shapecorr::synth::{self, FigureKind, FigureSpec};
use shapecorr::{ReadAs, Shape};

fn main() -> shapecorr::Result<()> {
    for file in std::env::args().skip(1) {
        if file == "--synth" {
            generated_clouds()?;
            continue;
        }
        let mesh = Shape::read(std::path::Path::new(&file), ReadAs::Auto)?;
        if mesh.kind() == shapecorr::ShapeKind::PointCloud {
            let cloud = orient(mesh.vertices());
            println!("{file} (a cloud): agreement {:.3}", cloud.agreement);
            continue;
        }
        let Some(truth) = outward_normals(&mesh) else {
            continue;
        };
        let v = mesh.vertices();
        let height = (0..3)
            .map(|k| {
                let (lo, hi) = v
                    .iter()
                    .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p[k]), h.max(p[k])));
                hi - lo
            })
            .fold(0.0, f64::max);
        for jitter in [0.0, 0.002] {
            let mut rng = ChaCha8Rng::seed_from_u64(7);
            let points: Vec<[f64; 3]> = v
                .iter()
                .map(|p| {
                    p.map(|x| {
                        let (a, b): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
                        x + jitter
                            * height
                            * (-2.0 * a.ln()).sqrt()
                            * (std::f64::consts::TAU * b).cos()
                    })
                })
                .collect();
            let cloud = orient(&points);
            let right = (0..v.len())
                .filter(|&i| {
                    let n = cloud.normals[i];
                    n[0] * truth[i][0] + n[1] * truth[i][1] + n[2] * truth[i][2] > 0.0
                })
                .count();
            let cosine = |i: usize| {
                let (n, t) = (cloud.normals[i], truth[i]);
                let d = n[0] * t[0] + n[1] * t[1] + n[2] * t[2];
                d / ((t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt() + 1e-300)
            };
            let wrong = (0..v.len()).filter(|&i| cosine(i) < -0.5).count();
            println!(
                "{file} jitter {jitter}: wrong by far {:.3}, agreement {:.3} ({}), outward {:.3}",
                wrong as f64 / v.len() as f64,
                cloud.agreement,
                if cloud.agreement >= TRUSTED_AGREEMENT {
                    "trusted"
                } else {
                    "not trusted"
                },
                right as f64 / v.len() as f64
            );
        }
    }
    Ok(())
}

/// Area-weighted vertex normals of a mesh's consistently oriented faces (None when it has
/// none).
fn outward_normals(mesh: &Shape) -> Option<Vec<[f64; 3]>> {
    let v = mesh.vertices();
    let mut normals = vec![[0.0; 3]; v.len()];
    for t in &mesh.oriented_triangles()? {
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
    Some(normals)
}

/// `--synth`: the generated clouds' normals against the outward normals of their source
/// vertices.
fn generated_clouds() -> shapecorr::Result<()> {
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
        let truth = outward_normals(&shape).unwrap_or_default();
        for noise in [0.0, 0.002, 0.005] {
            let cloud = synth::sample_points(&mesh, 3000, noise, 3)?;
            let oriented = orient(&cloud.points);
            let wrong = (oriented.normals.iter().zip(&cloud.source_vertex))
                .filter(|(n, &v)| {
                    let t = truth.get(v as usize).copied().unwrap_or_default();
                    n[0] * t[0] + n[1] * t[1] + n[2] * t[2] <= 0.0
                })
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
