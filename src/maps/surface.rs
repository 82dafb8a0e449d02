//! The map onto A's surface (docs/transfer.md, "The surface map"): for every vertex of B, a
//! point of A's surface (three vertices of A and weights, [`SurfacePoint`]), so that data
//! carried from A to B is as smooth as A's and not quantised to A's vertices.
//!
//! Method: the vertex map is smoothed over B's one-ring and projected back onto A. Every
//! vertex of B takes the mean of the images of itself and its neighbours (one-ring on a mesh,
//! [`CLOUD_NEIGHBORS`] nearest points on a point cloud), leaving out images further than
//! [`TEAR_EDGES`] mean edges of A from its own image (the map tears there: at a seam of the
//! map, the vertex keeps its own side). The mean is then projected onto the triangles of A
//! around the images it came from (Ericson's closest point); on a point cloud A it takes its
//! three nearest images, weighted inversely to the distance. A vertex map that is already
//! smooth moves by less than an edge; where B is finer than A, the vertices that shared an
//! image of A now spread over A's triangles. Measured against the exact ground truth of
//! generated figures (`docs/transfer.md`). O(n) after the vertex map; nothing compares the
//! two vertex sets.

use rayon::prelude::*;

use crate::progress::{polled, Cancel, Progress, Stage};
use crate::shape::neighbors::PointTree;
use crate::shape::surface_point::{
    closest_on_triangle, heaviest_first, inverse_distance, SurfacePoint,
};
use crate::shape::{Shape, ShapeKind};
use crate::{Error, Result};

/// Images further than this many mean edges of A from a vertex's own image are left out of
/// its mean (the map tears between them). Not tuned: as the proxies' lifting (docs/design.md,
/// step 16).
const TEAR_EDGES: f64 = 3.0;

/// Neighbours of a point of a point cloud B whose images are averaged (a mesh vertex has
/// about six). Not tuned.
const CLOUD_NEIGHBORS: usize = 6;

/// Vertices of B per block between cancel checks.
const BLOCK: usize = 16_384;

/// For every vertex of B, a point of A's surface.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceMap {
    /// `points[v]`: where vertex `v` of B lands on A (vertices of A, weights summing to 1).
    pub points: Vec<SurfacePoint>,
    /// A's vertex count (every index of `points` is below it).
    pub n_vertices_a: usize,
    /// A's [`Shape::fingerprint`]: per-corner transfers check that they are given A.
    pub fingerprint_a: u64,
}

impl SurfaceMap {
    /// The surface map of the vertex map `p2p_ba` (for every vertex of B, a vertex of A), as
    /// described in the module docs. Errors when `p2p_ba` does not fit the shapes.
    /// Reports progress as [`Stage::Transfer`] and honours cancellation.
    pub fn from_vertex_map(
        a: &Shape,
        b: &Shape,
        p2p_ba: &[u32],
        progress: &mut dyn Progress,
    ) -> Result<SurfaceMap> {
        if p2p_ba.len() != b.n_vertices() {
            return Err(Error::InvalidParameter {
                name: "p2p_ba",
                reason: format!(
                    "has {} entries, B has {} vertices",
                    p2p_ba.len(),
                    b.n_vertices()
                ),
            });
        }
        if let Some(bad) = p2p_ba.iter().find(|&&v| v as usize >= a.n_vertices()) {
            return Err(Error::InvalidParameter {
                name: "p2p_ba",
                reason: format!(
                    "vertex {bad} of A does not exist (A has {})",
                    a.n_vertices()
                ),
            });
        }
        let points = polled(progress, Stage::Transfer, (0.0, 1.0), |cancel| {
            surface_points(a, b, p2p_ba, cancel)
        })?;
        Ok(SurfaceMap {
            points,
            n_vertices_a: a.n_vertices(),
            fingerprint_a: a.fingerprint(),
        })
    }

    /// The map's images as points of space, on A's vertex positions `positions_a` (A's own,
    /// or A in another pose with the same vertices).
    pub fn positions(&self, positions_a: &[[f64; 3]]) -> Vec<[f64; 3]> {
        self.points
            .iter()
            .map(|p| {
                [0, 1, 2].map(|c| {
                    (0..3)
                        .map(|i| p.weights[i] * positions_a[p.vertices[i] as usize][c])
                        .sum()
                })
            })
            .collect()
    }
}

/// Every vertex of B, by blocks between cancel checks.
fn surface_points(
    a: &Shape,
    b: &Shape,
    p2p_ba: &[u32],
    cancel: &Cancel,
) -> Result<Vec<SurfacePoint>> {
    let neighbors = neighbors_of(b);
    let incident = (a.kind() == ShapeKind::Mesh).then(|| a.triangles_around_vertices());
    let tear2 = (TEAR_EDGES * a.mean_edge_length()).powi(2);
    let pa = a.vertices();
    let representative = b.representative();
    let n_b = b.n_vertices();
    let mut own = Vec::with_capacity(n_b);
    for start in (0..n_b).step_by(BLOCK) {
        cancel.check()?;
        cancel.set_fraction(start as f32 / n_b as f32);
        let block: Vec<SurfacePoint> = (start..(start + BLOCK).min(n_b))
            .into_par_iter()
            .map(|v| {
                let image = p2p_ba[v];
                let at = pa[image as usize];
                let mut images = vec![image];
                images.extend(
                    neighbors[v]
                        .iter()
                        .map(|&u| p2p_ba[u as usize])
                        .filter(|&w| squared_distance(&pa[w as usize], &at) <= tear2),
                );
                let target = [0, 1, 2].map(|c| {
                    images.iter().map(|&w| pa[w as usize][c]).sum::<f64>() / images.len() as f64
                });
                images.sort_unstable();
                images.dedup();
                match &incident {
                    Some(incident) => on_triangles(a, incident, &images, &target),
                    None => {
                        let mut near: Vec<(u32, f64)> = images
                            .iter()
                            .map(|&w| (w, squared_distance(&pa[w as usize], &target).sqrt()))
                            .collect();
                        near.sort_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
                        inverse_distance(&near)
                    }
                }
            })
            .collect();
        own.extend(block);
    }
    // A welded duplicate of B lands where its representative does.
    Ok((0..n_b).map(|v| own[representative[v] as usize]).collect())
}

/// The closest point to `target` on the triangles of A around `images`.
fn on_triangles(
    a: &Shape,
    incident: &[Vec<u32>],
    images: &[u32],
    target: &[f64; 3],
) -> SurfacePoint {
    let mut best: Option<(f64, u32, [f64; 3])> = None;
    for &w in images {
        for &f in &incident[w as usize] {
            let corners = a.triangles()[f as usize].map(|v| a.vertices()[v as usize]);
            let (d2, bary) = closest_on_triangle(target, &corners);
            if best.is_none_or(|(d, g, _)| d2 < d || (d2 == d && f < g)) {
                best = Some((d2, f, bary));
            }
        }
    }
    match best {
        Some((_, f, bary)) => heaviest_first(a.triangles()[f as usize], bary),
        // An image on no triangle (an isolated vertex left in the mesh): the image itself.
        None => SurfacePoint {
            vertices: [images[0]; 3],
            weights: [1.0, 0.0, 0.0],
        },
    }
}

/// For every vertex of B, the neighbours whose images are averaged: the one-ring on a mesh,
/// the [`CLOUD_NEIGHBORS`] nearest points on a point cloud (active vertices only).
fn neighbors_of(b: &Shape) -> Vec<Vec<u32>> {
    let mut neighbors = vec![Vec::new(); b.n_vertices()];
    match b.kind() {
        ShapeKind::Mesh => {
            for (i, j) in b.edges() {
                neighbors[i as usize].push(j);
                neighbors[j as usize].push(i);
            }
        }
        ShapeKind::PointCloud => {
            let active = b.active_vertices();
            let points: Vec<[f64; 3]> = active.iter().map(|&v| b.vertices()[v as usize]).collect();
            let tree = PointTree::new(&points);
            let near: Vec<Vec<u32>> = points
                .par_iter()
                .map(|p| {
                    tree.nearest_k(p, CLOUD_NEIGHBORS + 1)
                        .into_iter()
                        .skip(1)
                        .map(|(i, _)| active[i])
                        .collect()
                })
                .collect();
            for (&v, near) in active.iter().zip(near) {
                neighbors[v as usize] = near;
            }
        }
    }
    neighbors
}

/// The triangles around every vertex of A (None for a point cloud).
fn squared_distance(p: &[f64; 3], q: &[f64; 3]) -> f64 {
    (0..3).map(|c| (p[c] - q[c]).powi(2)).sum()
}
