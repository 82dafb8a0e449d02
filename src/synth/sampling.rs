//! Point clouds sampled on a figure's surface, with the ground-truth vertex of every point.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::geom::{add, dist, scale, triangle_area, V3};
use super::FigureMesh;
use crate::{Error, Result};

/// Points sampled on a mesh; `source_vertex[i]` is the mesh vertex that point `i` stands for
/// (the corner of its triangle nearest to the noise-free sample).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SampledCloud {
    /// The sampled points, noise included.
    pub points: Vec<[f64; 3]>,
    /// For every point, the 0-based index of the mesh vertex it stands for.
    pub source_vertex: Vec<u32>,
}

/// Samples `n_points` points uniformly on the surface of `mesh` (triangles chosen with
/// probability proportional to area, uniform barycentric position inside), then moves each
/// by a random vector of uniformly random direction and length uniform in
/// `[0, noise * width]`, where `width` is the diagonal of the mesh's bounding box.
/// Deterministic for a given `seed`.
///
/// Errors with [`Error::InvalidParameter`] when `n_points` is 0, `noise` is negative or not
/// finite, or the mesh has a face index out of range or no area.
pub fn sample_points(
    mesh: &FigureMesh,
    n_points: usize,
    noise: f64,
    seed: u64,
) -> Result<SampledCloud> {
    if n_points == 0 {
        return Err(Error::InvalidParameter {
            name: "n_points",
            reason: "must be at least 1".into(),
        });
    }
    if !noise.is_finite() || noise < 0.0 {
        return Err(Error::InvalidParameter {
            name: "noise",
            reason: format!("must be a finite fraction >= 0 of the shape width, got {noise}"),
        });
    }
    let n = mesh.vertices.len();
    if let Some(t) = mesh
        .triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(Error::InvalidParameter {
            name: "mesh",
            reason: format!("triangle {t:?} refers to a vertex beyond the {n} vertices"),
        });
    }
    // Cumulative areas, for choosing triangles by area.
    let mut cumulative = Vec::with_capacity(mesh.triangles.len());
    let mut total = 0.0;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        total += triangle_area(a, b, c);
        cumulative.push(total);
    }
    if !(total > 0.0 && total.is_finite()) {
        return Err(Error::InvalidParameter {
            name: "mesh",
            reason: format!("the mesh has no usable surface area (total area {total})"),
        });
    }
    let width = bounding_box_diagonal(&mesh.vertices);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut cloud = SampledCloud {
        points: Vec::with_capacity(n_points),
        source_vertex: Vec::with_capacity(n_points),
    };
    for _ in 0..n_points {
        let r = rng.random::<f64>() * total;
        let f = cumulative
            .partition_point(|&c| c <= r)
            .min(mesh.triangles.len() - 1);
        let t = mesh.triangles[f];
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        // Uniform in the triangle: sqrt-warped barycentric coordinates.
        let s = rng.random::<f64>().sqrt();
        let u = rng.random::<f64>();
        let p = barycentric(a, b, c, 1.0 - s, s * (1.0 - u), s * u);
        let nearest = (0..3)
            .min_by(|&i, &j| dist(p, [a, b, c][i]).total_cmp(&dist(p, [a, b, c][j])))
            .unwrap_or(0);
        let offset = if noise > 0.0 {
            let len = noise * width * rng.random::<f64>();
            random_direction(&mut rng, len)
        } else {
            [0.0; 3]
        };
        cloud.points.push(add(p, offset));
        cloud.source_vertex.push(t[nearest]);
    }
    Ok(cloud)
}

fn barycentric(a: V3, b: V3, c: V3, wa: f64, wb: f64, wc: f64) -> V3 {
    add(add(scale(a, wa), scale(b, wb)), scale(c, wc))
}

/// A vector of length `len` in a uniformly random direction.
fn random_direction(rng: &mut ChaCha8Rng, len: f64) -> V3 {
    let z = 2.0 * rng.random::<f64>() - 1.0;
    let phi = std::f64::consts::TAU * rng.random::<f64>();
    let r = (1.0 - z * z).max(0.0).sqrt();
    [len * r * phi.cos(), len * r * phi.sin(), len * z]
}

/// Length of the diagonal of the bounding box of `points`.
pub(crate) fn bounding_box_diagonal(points: &[V3]) -> f64 {
    let (lo, hi) = crate::shape::bounding_box(points);
    dist(lo, hi).max(0.0)
}

/// Every point moved by an isotropic Gaussian whose root mean square is `level` times the
/// diagonal of the points' bounding box (scanner noise, docs/scans.md). Deterministic for a
/// given `seed`.
pub fn with_noise(points: &[[f64; 3]], level: f64, seed: u64) -> Vec<[f64; 3]> {
    let sigma = level * crate::shape::bounding_box_diagonal(points) / 3f64.sqrt();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    points
        .iter()
        .map(|p| {
            p.map(|x| {
                let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
                x + sigma * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
            })
        })
        .collect()
}
