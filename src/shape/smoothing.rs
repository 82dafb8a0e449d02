//! Scanner noise on a mesh, measured and taken out of the working copy.
//!
//! Vertex noise of a few tenths of a percent of the diagonal tilts every face: the cotangent
//! Laplacian and the descriptors then see a rough surface, and a FAUST_r pair at 1% noise
//! fails outright (docs/scans.md). Noise is told from shape by [`roughness`], the median
//! angle between the normals of faces that share an edge: a smooth surface, coarse or fine,
//! bends at few of its edges, noise at all of them. A noisy working copy is smoothed by
//! Taubin's low-pass filter (Taubin, "A signal processing approach to fair surface design",
//! SIGGRAPH 1995), which does not shrink the shape as plain Laplacian smoothing does. The
//! answers stay on the input vertices: only the positions the stages see move.

use std::collections::HashMap;

use crate::shape::{Shape, ShapeKind};

/// A mesh whose [`roughness`] is above this many radians (20 degrees) is smoothed before
/// matching. Chosen on generated figures and checked on every shape of the development data
/// (docs/scans.md, "Noisy meshes"): clean shapes have medians of 0.03-0.17, and 0.25% noise
/// on a FAUST_r shape already gives 0.4 and more.
pub const NOISY_ROUGHNESS: f64 = 0.35;

/// Taubin steps (one shrinking and one inflating pass each) on a noisy copy. Not tuned:
/// Taubin's own examples use a few to a few tens; five took 1% noise on FAUST_r pairs from
/// 14x the clean error to 1.3x (docs/scans.md).
pub const TAUBIN_STEPS: usize = 5;

/// Taubin's shrinking factor.
const TAUBIN_LAMBDA: f64 = 0.5;
/// Taubin's inflating factor: pass band about 0.1 (1/lambda + 1/mu).
const TAUBIN_MU: f64 = -0.53;

/// The median angle, in radians, between the normals of two faces sharing an edge (edges
/// of exactly two faces); `None` for a point cloud or a mesh without such an edge.
pub fn roughness(shape: &Shape) -> Option<f64> {
    if shape.kind() != ShapeKind::Mesh {
        return None;
    }
    let vertices = shape.vertices();
    let normals: Vec<[f64; 3]> = shape
        .triangles()
        .iter()
        .map(|t| unit_normal(t.map(|v| vertices[v as usize])))
        .collect();
    let mut faces_of_edge: HashMap<(u32, u32), (usize, usize)> =
        HashMap::with_capacity(shape.triangles().len() * 3 / 2);
    for (f, t) in shape.triangles().iter().enumerate() {
        for k in 0..3 {
            let (p, q) = (t[k], t[(k + 1) % 3]);
            let entry = faces_of_edge
                .entry((p.min(q), p.max(q)))
                .or_insert((f, usize::MAX));
            if entry.0 != f {
                // A third face makes the edge non-manifold: left out below.
                entry.1 = if entry.1 == usize::MAX {
                    f
                } else {
                    usize::MAX - 1
                };
            }
        }
    }
    let mut angles: Vec<f64> = faces_of_edge
        .values()
        .filter(|&&(_, g)| g < usize::MAX - 1)
        .map(|&(f, g)| {
            let (m, n) = (normals[f], normals[g]);
            (m[0] * n[0] + m[1] * n[1] + m[2] * n[2])
                .clamp(-1.0, 1.0)
                .acos()
        })
        .filter(|a| a.is_finite())
        .collect();
    if angles.is_empty() {
        return None;
    }
    let middle = angles.len() / 2;
    let (_, median, _) = angles.select_nth_unstable_by(middle, f64::total_cmp);
    Some(*median)
}

/// Whether `shape` is a mesh noisy enough to be smoothed ([`NOISY_ROUGHNESS`]).
pub fn is_noisy(shape: &Shape) -> bool {
    roughness(shape).is_some_and(|r| r > NOISY_ROUGHNESS)
}

/// `shape`'s vertices after `steps` Taubin steps with uniform weights over the edges of its
/// faces; vertices on no face keep their place.
pub fn taubin_smoothed(shape: &Shape, steps: usize) -> Vec<[f64; 3]> {
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); shape.n_vertices()];
    for t in shape.triangles() {
        for k in 0..3 {
            let (p, q) = (t[k], t[(k + 1) % 3]);
            neighbours[p as usize].push(q);
            neighbours[q as usize].push(p);
        }
    }
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
    }
    let mut positions = shape.vertices().to_vec();
    for pass in 0..2 * steps {
        let factor = if pass % 2 == 0 {
            TAUBIN_LAMBDA
        } else {
            TAUBIN_MU
        };
        let before = positions.clone();
        for (v, around) in neighbours.iter().enumerate() {
            if around.is_empty() {
                continue;
            }
            let scale = 1.0 / around.len() as f64;
            for c in 0..3 {
                let mean = around.iter().map(|&w| before[w as usize][c]).sum::<f64>() * scale;
                positions[v][c] = before[v][c] + factor * (mean - before[v][c]);
            }
        }
    }
    positions
}

/// The unit normal of a triangle (zero for a degenerate one, whose angles are left out).
fn unit_normal([a, b, c]: [[f64; 3]; 3]) -> [f64; 3] {
    let (u, w) = (
        [0, 1, 2].map(|i| b[i] - a[i]),
        [0, 1, 2].map(|i| c[i] - a[i]),
    );
    let n = [
        u[1] * w[2] - u[2] * w[1],
        u[2] * w[0] - u[0] * w[2],
        u[0] * w[1] - u[1] * w[0],
    ];
    let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if length > 0.0 {
        n.map(|x| x / length)
    } else {
        [f64::NAN; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth;

    fn figure(target_vertices: usize) -> Shape {
        let mesh = synth::figure(&synth::FigureSpec {
            target_vertices,
            ..Default::default()
        })
        .unwrap();
        Shape::mesh(mesh.vertices, &mesh.triangles).unwrap()
    }

    fn noisy(shape: &Shape, level: f64) -> Shape {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let moved = shape
            .vertices()
            .iter()
            .map(|p| p.map(|x| x + level * uniform()))
            .collect();
        shape.with_vertices(moved).unwrap()
    }

    #[test]
    fn a_smooth_figure_is_not_noisy_and_noise_is_told_and_smoothed_out() {
        let figure = figure(4000);
        let clean = roughness(&figure).unwrap();
        assert!(clean < NOISY_ROUGHNESS / 2.0, "clean roughness {clean}");
        let edge = figure.mean_edge_length();
        let rough = noisy(&figure, 1.5 * edge);
        assert!(is_noisy(&rough), "roughness {:?}", roughness(&rough));
        let smoothed = rough
            .with_vertices(taubin_smoothed(&rough, TAUBIN_STEPS))
            .unwrap();
        assert!(
            !is_noisy(&smoothed),
            "after smoothing {:?}",
            roughness(&smoothed)
        );
        // Taubin's filter keeps the size: the bounding box within 3% of the clean one.
        let extent = |s: &Shape| {
            let ys: Vec<f64> = s.vertices().iter().map(|p| p[1]).collect();
            ys.iter().cloned().fold(f64::MIN, f64::max)
                - ys.iter().cloned().fold(f64::MAX, f64::min)
        };
        let ratio = extent(&smoothed) / extent(&figure);
        assert!((ratio - 1.0).abs() < 0.03, "height ratio {ratio}");
    }

    #[test]
    fn a_point_cloud_has_no_roughness() {
        let cloud = Shape::point_cloud(figure(1000).vertices().to_vec()).unwrap();
        assert_eq!(roughness(&cloud), None);
        assert!(!is_noisy(&cloud));
    }
}
