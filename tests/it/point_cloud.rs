//! The point-cloud Laplacian follows the mesh's spectrum.

use crate::common;

use shapecorr::synth::{self, FigureKind, FigureSpec};
use shapecorr::{EigenParams, Eigenbasis, Shape};

fn first_eigenvalues(shape: &Shape, k: usize) -> Vec<f64> {
    let params = EigenParams {
        n_eigenpairs: k,
        ..Default::default()
    };
    Eigenbasis::compute(shape, &params).unwrap().values
}

fn assert_spectra_close(mesh: &Shape, cloud: &Shape, k: usize, tolerance: f64) {
    let a = first_eigenvalues(mesh, k);
    let b = first_eigenvalues(cloud, k);
    let worst = (1..k)
        .map(|j| (a[j] - b[j]).abs() / a[j])
        .fold(0.0, f64::max);
    println!("largest relative eigenvalue difference over the first {k}: {worst:.4}");
    for j in 1..k {
        let r = (a[j] - b[j]).abs() / a[j];
        assert!(
            r < tolerance,
            "eigenvalue {j}: mesh {:.4}, point cloud {:.4} (relative difference {r:.4})",
            a[j],
            b[j]
        );
    }
}

#[test]
fn sampled_humanoid_cloud_has_the_meshs_first_20_eigenvalues_within_5_percent() {
    let mesh = synth::figure(&FigureSpec {
        kind: FigureKind::Humanoid,
        target_vertices: 8000,
        ..Default::default()
    })
    .unwrap();
    let cloud = synth::sample_points(&mesh, 8000, 0.0, 3).unwrap();
    let mesh = Shape::mesh(mesh.vertices, &mesh.triangles).unwrap();
    let cloud = Shape::point_cloud(cloud.points).unwrap();
    assert_spectra_close(&mesh, &cloud, 20, 0.05);
}

#[test]
fn mesh_vertices_as_a_cloud_have_the_meshs_first_20_eigenvalues_within_5_percent() {
    let (v, f) = common::icosphere(5);
    // Stretch the sphere so the spectrum has no multiplicities.
    let v: Vec<[f64; 3]> = v.iter().map(|p| [1.4 * p[0], p[1], 0.7 * p[2]]).collect();
    let mesh = Shape::mesh(v.clone(), &f).unwrap();
    let cloud = Shape::point_cloud(v).unwrap();
    assert_spectra_close(&mesh, &cloud, 20, 0.05);
}
