//! Whether the point-cloud Laplacian is where clouds lose accuracy (docs/scans.md, "Point
//! clouds"): for every mesh file given, the relative difference between the eigenvalues of
//! the point-cloud Laplacian of its vertices and those of its own cotangent Laplacian (both
//! at unit area). `crates/eval/scripts/cloud_spectrum_reference.py` prints the same for
//! Sharp and Crane's `robust_laplacian` package, the reference.
//!
//!     cargo run --release -p shapecorr-eval --example cloud_spectrum -- MESH ...

use shapecorr::{EigenParams, Eigenbasis, NoProgress, ReadAs, Shape};

/// The eigenvalues compared (0-based; 0 is the constant function's).
const SHOWN: [usize; 7] = [1, 2, 5, 10, 20, 40, 59];

fn main() -> shapecorr::Result<()> {
    let params = EigenParams {
        n_eigenpairs: 60,
        ..Default::default()
    };
    for path in std::env::args().skip(1) {
        let mesh = Shape::read(std::path::Path::new(&path), ReadAs::Auto)?;
        let cloud = Shape::point_cloud(mesh.vertices().to_vec())?;
        let on_mesh = Eigenbasis::compute(&mesh, &params, &mut NoProgress)?;
        let on_cloud = Eigenbasis::compute(&cloud, &params, &mut NoProgress)?;
        let row: Vec<String> = SHOWN
            .iter()
            .map(|&k| {
                let relative = (on_cloud.values[k] - on_mesh.values[k]) / on_mesh.values[k];
                format!("{k}: {relative:+.3}")
            })
            .collect();
        println!("{path}: {}", row.join("  "));
    }
    Ok(())
}
