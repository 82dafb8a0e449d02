//! How far a point cloud's orientation can be trusted (docs/scans.md, "Point clouds"): for
//! every mesh file given, its vertices jittered by 0.2% of the height as a cloud, the share
//! of local triangles that agree with their corners' normals
//! ([`cloud_orientation::OrientedCloud::agreement`]) and the share of normals that agree
//! with the mesh's own outward vertex normals (the truth).
//!
//!     cargo run --release -p shapecorr-eval --example cloud_orientation -- FILE ..

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shapecorr::shape::cloud_orientation::{orient, TRUSTED_AGREEMENT};
use shapecorr::{ReadAs, Shape};

fn main() -> shapecorr::Result<()> {
    for file in std::env::args().skip(1) {
        let mesh = Shape::read(std::path::Path::new(&file), ReadAs::Auto)?;
        if mesh.kind() == shapecorr::ShapeKind::PointCloud {
            let cloud = orient(mesh.vertices());
            println!("{file} (a cloud): agreement {:.3}", cloud.agreement);
            continue;
        }
        let Some(faces) = mesh.oriented_triangles() else {
            continue;
        };
        let v = mesh.vertices();
        let mut truth = vec![[0.0; 3]; v.len()];
        for t in &faces {
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
                    truth[i as usize][k] += n[k];
                }
            }
        }
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
