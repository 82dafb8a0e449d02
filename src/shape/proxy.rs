//! Coarse proxies of dense shapes (issue 20; docs/design.md, step 16): the pipeline runs on a
//! proxy of a few thousand vertices and its answers come back to every input vertex.
//!
//! A mesh is simplified by meshoptimizer's edge collapse (`meshopt::simplify`, quadric
//! error, regularised triangles: the Laplacian wants well-shaped triangles more than an exact
//! silhouette); a point cloud by its point simplification (`meshopt::simplify_points`, a
//! spatial grid). Both keep a subset of the input vertices, so every proxy vertex is an input
//! vertex ([`Proxy::input_vertex`]). Every input vertex is located on the proxy
//! ([`Proxy::location`]): on a mesh the closest point of the proxy surface (a triangle and
//! barycentric weights), on a point cloud its three nearest proxy points (inverse-distance
//! weights). A k-d tree finds the candidates, so building a proxy is O(n log n).

use rayon::prelude::*;

use crate::shape::neighbors::PointTree;
use crate::shape::{Repairs, Shape, ShapeKind};
use crate::Result;

/// Where an input vertex lies on its proxy: three proxy vertices and their weights (summing
/// to 1), heaviest first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// Proxy vertices, heaviest first.
    pub vertices: [u32; 3],
    /// Their weights (barycentric on a mesh), descending, summing to 1.
    pub weights: [f64; 3],
}

impl SurfacePoint {
    /// The proxy vertex nearest on the surface (the heaviest).
    pub fn nearest(&self) -> u32 {
        self.vertices[0]
    }
}

/// A simplified shape and where every input vertex lies on it.
#[derive(Debug, Clone)]
pub struct Proxy {
    /// The simplified shape the pipeline runs on.
    pub shape: Shape,
    /// For every proxy vertex, the input vertex it is (ascending).
    pub input_vertex: Vec<u32>,
    /// For every input vertex, where it lies on the proxy.
    pub location: Vec<SurfacePoint>,
}

/// Proxy candidates checked per input vertex: the triangles around its nearest proxy
/// vertices (not tuned; `tests/multiresolution.rs` checks that every located point lies
/// within half a proxy edge of its vertex on a 12K figure with a 2K proxy).
const NEAREST_PROXY_VERTICES: usize = 4;

impl Proxy {
    /// A proxy of `shape` with about `target_vertices` vertices (at least 3 fewer than the
    /// shape's active vertices, else [`crate::Error::InvalidParameter`]).
    pub fn build(shape: &Shape, target_vertices: usize) -> Result<Proxy> {
        let active = shape.active_vertices();
        if target_vertices < 64 || target_vertices >= active.len() {
            return Err(crate::Error::InvalidParameter {
                name: "proxy_vertices",
                reason: format!(
                    "a proxy needs 64 or more vertices and fewer than the shape's {}, got {target_vertices}",
                    active.len()
                ),
            });
        }
        let positions: Vec<[f32; 3]> = shape
            .vertices()
            .iter()
            .map(|p| p.map(|x| x as f32))
            .collect();
        let (kept, triangles) = match shape.kind() {
            ShapeKind::Mesh => {
                let triangles = simplified_triangles(shape, &positions, target_vertices);
                let mut kept: Vec<u32> = triangles.iter().flatten().copied().collect();
                kept.sort_unstable();
                kept.dedup();
                (kept, triangles)
            }
            ShapeKind::PointCloud => {
                let points: Vec<[f32; 3]> = active.iter().map(|&v| positions[v as usize]).collect();
                let mut kept: Vec<u32> =
                    meshopt::simplify_points_decoder(&points, None, 0.0, target_vertices)
                        .into_iter()
                        .map(|i| active[i as usize])
                        .collect();
                kept.sort_unstable();
                kept.dedup();
                (kept, Vec::new())
            }
        };
        let mut proxy_index = vec![u32::MAX; shape.n_vertices()];
        for (i, &v) in kept.iter().enumerate() {
            proxy_index[v as usize] = i as u32;
        }
        let vertices: Vec<[f64; 3]> = kept.iter().map(|&v| shape.vertices()[v as usize]).collect();
        let proxy_shape = match shape.kind() {
            ShapeKind::Mesh => {
                let triangles: Vec<Vec<u32>> = triangles
                    .iter()
                    .map(|t| t.iter().map(|&v| proxy_index[v as usize]).collect())
                    .collect();
                Shape::mesh_with(vertices, &triangles, &Repairs::default())?
            }
            ShapeKind::PointCloud => Shape::point_cloud_with(vertices, &Repairs::default())?,
        };
        let location = locate(shape, &proxy_shape);
        Ok(Proxy {
            shape: proxy_shape,
            input_vertex: kept,
            location,
        })
    }

    /// A per-vertex value of the proxy taken by every input vertex from its nearest proxy
    /// vertex on the surface (region labels: the boundaries follow the proxy's, with no
    /// isolated vertex of another label).
    pub fn lift_nearest<T: Copy>(&self, proxy_values: &[T]) -> Vec<T> {
        self.location
            .iter()
            .map(|p| proxy_values[p.nearest() as usize])
            .collect()
    }
}

/// The triangles meshoptimizer keeps for about `target_vertices` vertices, in input indices.
fn simplified_triangles(
    shape: &Shape,
    positions: &[[f32; 3]],
    target_vertices: usize,
) -> Vec<[u32; 3]> {
    let indices: Vec<u32> = shape.triangles().iter().flatten().copied().collect();
    // A closed surface has about two triangles per vertex. The error bound is left open
    // (1.0 of the mesh's extent): the count decides.
    let target_indices = 3 * 2 * target_vertices;
    let kept = meshopt::simplify_decoder(
        &indices,
        positions,
        target_indices,
        1.0,
        meshopt::SimplifyOptions::Regularize,
        None,
    );
    kept.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
}

/// Where every input vertex of `shape` lies on `proxy` (an inactive vertex where its
/// representative lies).
fn locate(shape: &Shape, proxy: &Shape) -> Vec<SurfacePoint> {
    let proxy_active = proxy.active_vertices();
    let active_points: Vec<[f64; 3]> = proxy_active
        .iter()
        .map(|&v| proxy.vertices()[v as usize])
        .collect();
    let tree = PointTree::new(&active_points);
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); proxy.n_vertices()];
    for (f, t) in proxy.triangles().iter().enumerate() {
        for &v in t {
            incident[v as usize].push(f as u32);
        }
    }
    let at = |query: &[f64; 3]| -> SurfacePoint {
        let near = tree.nearest_k(query, NEAREST_PROXY_VERTICES.max(3));
        if proxy.kind() == ShapeKind::PointCloud {
            return inverse_distance(
                &near
                    .iter()
                    .map(|&(i, d2)| (proxy_active[i], d2.sqrt()))
                    .collect::<Vec<_>>(),
            );
        }
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        for &(i, _) in near.iter().take(NEAREST_PROXY_VERTICES) {
            for &f in &incident[proxy_active[i] as usize] {
                let t = proxy.triangles()[f as usize];
                let corners = t.map(|v| proxy.vertices()[v as usize]);
                let (d2, bary) = closest_on_triangle(query, &corners);
                if best.is_none_or(|(b, bf, _)| d2 < b || (d2 == b && f < bf)) {
                    best = Some((d2, f, bary));
                }
            }
        }
        let (_, f, bary) = best.expect("every active proxy vertex lies on a triangle");
        heaviest_first(proxy.triangles()[f as usize], bary)
    };
    let representative = shape.representative();
    let own: Vec<SurfacePoint> = shape
        .vertices()
        .par_iter()
        .enumerate()
        .map(|(v, p)| {
            if representative[v] as usize == v {
                at(p)
            } else {
                SurfacePoint {
                    vertices: [0; 3],
                    weights: [1.0, 0.0, 0.0],
                }
            }
        })
        .collect();
    (0..shape.n_vertices())
        .map(|v| own[representative[v] as usize])
        .collect()
}

/// Weights inversely proportional to the distance (a point at distance 0 takes all).
fn inverse_distance(near: &[(u32, f64)]) -> SurfacePoint {
    let mut vertices = [near[0].0; 3];
    let mut weights = [1.0, 0.0, 0.0];
    if near[0].1 > 0.0 {
        let inv: Vec<f64> = near.iter().take(3).map(|&(_, d)| 1.0 / d).collect();
        let total: f64 = inv.iter().sum();
        for (i, &(v, _)) in near.iter().take(3).enumerate() {
            vertices[i] = v;
            weights[i] = inv[i] / total;
        }
    }
    SurfacePoint { vertices, weights }
}

fn heaviest_first(t: [u32; 3], bary: [f64; 3]) -> SurfacePoint {
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| bary[j].total_cmp(&bary[i]).then(i.cmp(&j)));
    SurfacePoint {
        vertices: order.map(|i| t[i]),
        weights: order.map(|i| bary[i]),
    }
}

/// Squared distance from `p` to the triangle and the barycentric weights of the closest
/// point (Ericson, Real-Time Collision Detection, 5.1.5).
pub(crate) fn closest_on_triangle(p: &[f64; 3], [a, b, c]: &[[f64; 3]; 3]) -> (f64, [f64; 3]) {
    let sub = |x: &[f64; 3], y: &[f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let dot = |x: &[f64; 3], y: &[f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(&ab, &ap), dot(&ac, &ap));
    let bary = if d1 <= 0.0 && d2 <= 0.0 {
        [1.0, 0.0, 0.0]
    } else {
        let bp = sub(p, b);
        let (d3, d4) = (dot(&ab, &bp), dot(&ac, &bp));
        let cp = sub(p, c);
        let (d5, d6) = (dot(&ab, &cp), dot(&ac, &cp));
        let vc = d1 * d4 - d3 * d2;
        let vb = d5 * d2 - d1 * d6;
        let va = d3 * d6 - d5 * d4;
        if d3 >= 0.0 && d4 <= d3 {
            [0.0, 1.0, 0.0]
        } else if d6 >= 0.0 && d5 <= d6 {
            [0.0, 0.0, 1.0]
        } else if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            let v = d1 / (d1 - d3);
            [1.0 - v, v, 0.0]
        } else if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            let w = d2 / (d2 - d6);
            [1.0 - w, 0.0, w]
        } else if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            [0.0, 1.0 - w, w]
        } else {
            let denom = va + vb + vc;
            if denom <= 0.0 || !denom.is_finite() {
                // A degenerate triangle: its first corner.
                [1.0, 0.0, 0.0]
            } else {
                let (v, w) = (vb / denom, vc / denom);
                [1.0 - v - w, v, w]
            }
        }
    };
    let q = [0, 1, 2].map(|i| bary[0] * a[i] + bary[1] * b[i] + bary[2] * c[i]);
    let d = sub(p, &q);
    (dot(&d, &d), bary)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_closest_point_of_a_triangle_is_found_in_every_zone() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let inside = closest_on_triangle(&[0.25, 0.25, 2.0], &t);
        assert!((inside.0 - 4.0).abs() < 1e-12);
        assert!((inside.1[1] - 0.25).abs() < 1e-12 && (inside.1[2] - 0.25).abs() < 1e-12);
        assert_eq!(
            closest_on_triangle(&[-1.0, -1.0, 0.0], &t).1,
            [1.0, 0.0, 0.0]
        );
        assert_eq!(
            closest_on_triangle(&[3.0, -1.0, 0.0], &t).1,
            [0.0, 1.0, 0.0]
        );
        let edge = closest_on_triangle(&[1.0, 1.0, 0.0], &t);
        assert!((edge.1[1] - 0.5).abs() < 1e-12 && (edge.1[2] - 0.5).abs() < 1e-12);
        assert!((edge.0 - 0.5).abs() < 1e-12);
    }
}
