//! Distances along the surface, and the region-to-region distances that symmetry breaking
//! compares (docs/design.md, step 12).
//!
//! These are **edge-graph** distances: Dijkstra over the mesh edges (or a point cloud's
//! 6-NN graph) with Euclidean edge lengths. They overestimate the true geodesic distance by
//! a few percent (paths are confined to edges), which is harmless at the region level,
//! where only differences between region pairs of two shapes are compared. [`HeatGeodesics`]
//! gives accurate geodesic distances (the heat method) for evaluating pointwise maps.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use faer::Mat;
use rayon::prelude::*;

use crate::shape::DisjointSets;
use crate::spectral::laplacian::{heron_area, triangulation, Laplacian};
use crate::spectral::sparse::SparseCholesky;
use crate::{Error, Result, Shape};

/// Stands in for the distance between two regions that cannot reach each other (different
/// connected pieces) in [`region_distance_matrix`]: this factor times the largest finite
/// vertex distance met in the solves. Finite, so that the symmetry-breaking energy stays
/// finite; larger than any real distance, so that separating pieces is penalised.
pub const UNREACHABLE_FACTOR: f64 = 2.0;

/// The edge graph of a shape, in compressed-row form over the input vertices, with edge
/// lengths already scaled. Build it once and solve from many sources.
#[derive(Debug, Clone)]
pub struct EdgeGraph {
    /// `offsets[v]..offsets[v + 1]` indexes the neighbours of input vertex `v`.
    offsets: Vec<usize>,
    neighbours: Vec<u32>,
    lengths: Vec<f64>,
    /// For every input vertex, the active vertex whose distance it takes.
    representative: Vec<u32>,
}

impl EdgeGraph {
    /// The graph of `shape.edges()` with Euclidean lengths times `scale` (pass
    /// `1 / sqrt(input_area)` for distances on the unit-area shape).
    pub fn new(shape: &Shape, scale: f64) -> EdgeGraph {
        let n = shape.n_vertices();
        let vertices = shape.vertices();
        let edges = shape.edges();
        let mut degree = vec![0usize; n + 1];
        for &(a, b) in &edges {
            degree[a as usize + 1] += 1;
            degree[b as usize + 1] += 1;
        }
        for v in 0..n {
            degree[v + 1] += degree[v];
        }
        let offsets = degree;
        let mut fill = offsets.clone();
        let mut neighbours = vec![0u32; 2 * edges.len()];
        let mut lengths = vec![0.0; 2 * edges.len()];
        for &(a, b) in &edges {
            let (pa, pb) = (vertices[a as usize], vertices[b as usize]);
            let length = scale
                * ((pa[0] - pb[0]).powi(2) + (pa[1] - pb[1]).powi(2) + (pa[2] - pb[2]).powi(2))
                    .sqrt();
            for (from, to) in [(a, b), (b, a)] {
                let slot = fill[from as usize];
                neighbours[slot] = to;
                lengths[slot] = length;
                fill[from as usize] += 1;
            }
        }
        EdgeGraph {
            offsets,
            neighbours,
            lengths,
            representative: shape.representative().to_vec(),
        }
    }

    /// Number of input vertices.
    pub fn n_vertices(&self) -> usize {
        self.representative.len()
    }

    /// Multi-source Dijkstra: for every input vertex, the distance to the nearest source
    /// (`f64::INFINITY` when unreachable). Sources are input vertices; an unreferenced one
    /// stands for its representative, and unreferenced vertices take their representative's
    /// distance.
    ///
    /// # Panics
    /// When a source is not a vertex index.
    pub fn distances(&self, sources: &[u32]) -> Vec<f64> {
        let n = self.n_vertices();
        let mut distance = vec![f64::INFINITY; n];
        let mut heap = BinaryHeap::new();
        for &s in sources {
            assert!(
                (s as usize) < n,
                "source vertex {s} out of range: the shape has {n} vertices"
            );
            let r = self.representative[s as usize];
            if distance[r as usize] != 0.0 {
                distance[r as usize] = 0.0;
                heap.push(Entry {
                    distance: 0.0,
                    vertex: r,
                });
            }
        }
        while let Some(Entry {
            distance: d,
            vertex,
        }) = heap.pop()
        {
            let v = vertex as usize;
            if d > distance[v] {
                continue; // stale entry
            }
            for slot in self.offsets[v]..self.offsets[v + 1] {
                let w = self.neighbours[slot] as usize;
                let candidate = d + self.lengths[slot];
                if candidate < distance[w] {
                    distance[w] = candidate;
                    heap.push(Entry {
                        distance: candidate,
                        vertex: w as u32,
                    });
                }
            }
        }
        for v in 0..n {
            let r = self.representative[v] as usize;
            if r != v {
                distance[v] = distance[r];
            }
        }
        distance
    }
}

/// A heap entry ordered so that [`BinaryHeap`] pops the smallest distance first (ties: the
/// smaller vertex), which makes the visiting order deterministic.
#[derive(Debug, Clone, Copy)]
struct Entry {
    distance: f64,
    vertex: u32,
}

impl PartialEq for Entry {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Entry {}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .distance
            .total_cmp(&self.distance)
            .then_with(|| other.vertex.cmp(&self.vertex))
    }
}

/// Multi-source edge-graph distances (Dijkstra over `shape.edges()`, Euclidean lengths times
/// `scale`): for every input vertex, the distance to the nearest of `sources`;
/// `f64::INFINITY` when unreachable. Unreferenced vertices take their representative's
/// value. Plain edge-graph distances, not exact geodesics (see the module docs).
///
/// # Panics
/// When a source is not a vertex index.
pub fn edge_graph_distances(shape: &Shape, sources: &[u32], scale: f64) -> Vec<f64> {
    EdgeGraph::new(shape, scale).distances(sources)
}

/// Symmetric region-to-region distances (docs/design.md, step 12):
/// `D[R,Q] = 0.5 * (mean_Q d_R + mean_R d_Q)`, `D[R,R] = 0`, where `d_R` is the edge-graph
/// distance from all vertices of region `R` (one multi-source solve per region, in parallel)
/// and `mean_Q` the `mass`-weighted mean over the vertices of `Q` (unweighted for a region
/// whose mass is zero).
///
/// `mass` and `labels` are per input vertex (e.g. [`crate::Eigenbasis::mass`] and
/// [`crate::regions::graph::ShapeGraph::labels`]); `scale` multiplies the edge lengths (pass
/// `1 / sqrt(input_area)` for the unit-area shape). A vertex that cannot reach `R` (another
/// connected piece) counts at the large finite distance [`UNREACHABLE_FACTOR`] times the
/// largest finite vertex distance of all solves; so does an empty region (no vertices) for
/// every other region. Deterministic: the result does not depend on the thread count.
///
/// # Panics
/// When `mass` or `labels` is not one value per vertex, or a label is `>= n_regions`.
pub fn region_distance_matrix(
    shape: &Shape,
    mass: &[f64],
    labels: &[u32],
    n_regions: usize,
    scale: f64,
) -> Mat<f64> {
    let n = shape.n_vertices();
    assert_eq!(mass.len(), n, "mass needs one value per input vertex");
    assert_eq!(labels.len(), n, "labels need one value per input vertex");
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); n_regions];
    let mut region_mass = vec![0.0; n_regions];
    for (v, &label) in labels.iter().enumerate() {
        assert!(
            (label as usize) < n_regions,
            "vertex {v} has label {label}, but n_regions is {n_regions}"
        );
        members[label as usize].push(v as u32);
        region_mass[label as usize] += mass[v];
    }
    // Averaging weights: the mass, or 1 per vertex in a region without mass.
    let weight: Vec<f64> = (0..n)
        .map(|v| {
            if region_mass[labels[v] as usize] > 0.0 {
                mass[v]
            } else {
                1.0
            }
        })
        .collect();
    let mut total_weight = vec![0.0; n_regions];
    for v in 0..n {
        total_weight[labels[v] as usize] += weight[v];
    }

    let graph = EdgeGraph::new(shape, scale);
    // Per source region R: the weighted sum of finite d_R over each region Q, the weight of
    // the vertices of Q that R cannot reach, and the largest finite distance.
    let solves: Vec<(Vec<f64>, Vec<f64>, f64)> = (0..n_regions)
        .into_par_iter()
        .map(|r| {
            let mut finite_sum = vec![0.0; n_regions];
            let mut unreachable = vec![0.0; n_regions];
            if members[r].is_empty() {
                return (finite_sum, unreachable, 0.0);
            }
            let d = graph.distances(&members[r]);
            let mut max_finite: f64 = 0.0;
            for v in 0..n {
                let q = labels[v] as usize;
                if d[v].is_finite() {
                    finite_sum[q] += weight[v] * d[v];
                    max_finite = max_finite.max(d[v]);
                } else {
                    unreachable[q] += weight[v];
                }
            }
            (finite_sum, unreachable, max_finite)
        })
        .collect();
    let max_finite = solves.iter().map(|s| s.2).fold(0.0, f64::max);
    let far = if max_finite > 0.0 {
        UNREACHABLE_FACTOR * max_finite
    } else {
        1.0
    };
    // mean[r][q]: weighted mean over Q of d_R.
    let mean = |r: usize, q: usize| -> f64 {
        if members[r].is_empty() || members[q].is_empty() {
            return far;
        }
        let (finite_sum, unreachable, _) = &solves[r];
        (finite_sum[q] + unreachable[q] * far) / total_weight[q]
    };
    Mat::from_fn(n_regions, n_regions, |r, q| {
        if r == q {
            0.0
        } else {
            0.5 * (mean(r, q) + mean(q, r))
        }
    })
}

/// Geodesic distances by the **heat method** (Crane, Weischedel and Wardetzky 2013), accurate
/// enough for evaluating pointwise maps (edge-graph distances are not): heat flows from the
/// sources for a short time `t = h^2` (`(M + t L) u = delta`), its normalised gradient
/// `X = -grad u / |grad u|` points along the geodesics, and the distance solves
/// `L phi = -div X`. Both matrices are factored once in [`HeatGeodesics::new`]; each call
/// of [`HeatGeodesics::distances`] is two sparse solves. Gradients and divergences use the
/// same intrinsically mollified edge lengths as the Laplacian, so degenerate triangles are
/// handled the same way. Point clouds use the Laplacian's local triangulations.
pub struct HeatGeodesics {
    heat: SparseCholesky,
    poisson: SparseCholesky,
    triangles: Vec<[u32; 3]>,
    /// Per triangle: the cotangent of each corner and the 2D layout of its corners.
    corners: Vec<TriangleFrame>,
    /// Weight of each triangle (1 for a mesh, 1/3 for a point cloud's local triangles).
    weight: f64,
    /// Connected piece of each active vertex.
    piece: Vec<usize>,
    /// Active index of every input vertex (through its representative).
    active_of_input: Vec<u32>,
}

struct TriangleFrame {
    points: [[f64; 2]; 3],
    cot: [f64; 3],
    area: f64,
}

/// Regularisation of `L` in the distance solve (on the unit-area shape, whose first
/// non-zero eigenvalue is O(10)): it only fixes the free constant.
const POISSON_SHIFT: f64 = 1e-6;

impl HeatGeodesics {
    /// Prepares the solver for a shape (factors `M + t L` and `L + eps M`).
    pub fn new(shape: &Shape) -> Result<HeatGeodesics> {
        let triangulation = triangulation(shape);
        let laplacian = Laplacian::from_triangulation(&triangulation)?;
        let (n, triangles, lengths, weight) = (
            triangulation.positions.len(),
            triangulation.triangles,
            triangulation.lengths,
            triangulation.weight,
        );
        let scale = laplacian.input_area.sqrt();
        let corners: Vec<TriangleFrame> = lengths.iter().map(|l| TriangleFrame::new(*l)).collect();
        let mean_edge = lengths.iter().flatten().sum::<f64>() / (3 * lengths.len()) as f64 / scale;
        let t = mean_edge * mean_edge;
        let par = faer::Par::Seq;
        let heat = SparseCholesky::new(
            &laplacian.stiffness,
            t,
            &laplacian.mass,
            par,
            "heat method: M + t L",
        )?;
        let shift: Vec<f64> = laplacian.mass.iter().map(|m| POISSON_SHIFT * m).collect();
        let poisson = SparseCholesky::new(
            &laplacian.stiffness,
            1.0,
            &shift,
            par,
            "heat method: L + eps M",
        )?;
        let mut sets = DisjointSets::new(n);
        for t in &triangles {
            sets.union(t[0] as usize, t[1] as usize);
            sets.union(t[0] as usize, t[2] as usize);
        }
        let piece = (0..n).map(|v| sets.find(v)).collect();
        let mut active_index = vec![u32::MAX; shape.n_vertices()];
        for (i, &v) in shape.active_vertices().iter().enumerate() {
            active_index[v as usize] = i as u32;
        }
        let active_of_input = shape
            .representative()
            .iter()
            .map(|&r| active_index[r as usize])
            .collect();
        Ok(HeatGeodesics {
            heat,
            poisson,
            triangles,
            corners,
            weight,
            piece,
            active_of_input,
        })
    }

    /// For every input vertex, the geodesic distance (in the input's units) to the nearest
    /// of `sources` (input vertex indices); `f64::INFINITY` on pieces without a source.
    pub fn distances(&self, sources: &[u32]) -> Result<Vec<f64>> {
        let n_input = self.active_of_input.len();
        if sources.is_empty() {
            return Err(Error::InvalidParameter {
                name: "sources",
                reason: "give at least one source vertex".into(),
            });
        }
        if let Some(&bad) = sources.iter().find(|&&s| s as usize >= n_input) {
            return Err(Error::InvalidParameter {
                name: "sources",
                reason: format!("vertex {bad} is out of range: the shape has {n_input} vertices"),
            });
        }
        let n = self.heat.len();
        let active_sources: Vec<usize> = sources
            .iter()
            .map(|&s| self.active_of_input[s as usize] as usize)
            .collect();
        // 1. Heat flow from the sources.
        let mut u = Mat::<f64>::zeros(n, 1);
        for &s in &active_sources {
            u[(s, 0)] = 1.0;
        }
        let mut buffer = self.heat.scratch(1)?;
        self.heat.solve_in_place(u.as_mut(), &mut buffer);
        // 2-3. Normalised gradient per triangle, integrated divergence per vertex.
        let mut divergence = Mat::<f64>::zeros(n, 1);
        for (t, frame) in self.triangles.iter().zip(&self.corners) {
            let values = t.map(|v| u[(v as usize, 0)]);
            let Some(x) = frame.unit_descent(values) else {
                continue;
            };
            for k in 0..3 {
                let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
                let p = frame.points;
                let e1 = [p[k1][0] - p[k][0], p[k1][1] - p[k][1]];
                let e2 = [p[k2][0] - p[k][0], p[k2][1] - p[k][1]];
                let dot = |e: [f64; 2]| e[0] * x[0] + e[1] * x[1];
                divergence[(t[k] as usize, 0)] +=
                    0.5 * self.weight * (frame.cot[k2] * dot(e1) + frame.cot[k1] * dot(e2));
            }
        }
        // 4. L phi = -div X, then the smallest value at the sources is 0.
        for i in 0..n {
            divergence[(i, 0)] = -divergence[(i, 0)];
        }
        let mut buffer = self.poisson.scratch(1)?;
        self.poisson
            .solve_in_place(divergence.as_mut(), &mut buffer);
        let phi = divergence;
        let mut offset: std::collections::BTreeMap<usize, f64> = Default::default();
        for &s in &active_sources {
            let entry = offset.entry(self.piece[s]).or_insert(f64::INFINITY);
            *entry = entry.min(phi[(s, 0)]);
        }
        Ok(self
            .active_of_input
            .iter()
            .map(|&a| {
                let a = a as usize;
                match offset.get(&self.piece[a]) {
                    // The divergence is built from input-unit lengths, so phi is in input units.
                    Some(&o) => (phi[(a, 0)] - o).max(0.0),
                    None => f64::INFINITY,
                }
            })
            .collect())
    }
}

impl TriangleFrame {
    /// Lays out a triangle from its edge lengths (`l[k]` opposite corner `k`):
    /// corner 0 at the origin, corner 1 on the x axis, corner 2 above it.
    fn new(l: [f64; 3]) -> TriangleFrame {
        let area = heron_area(l[0], l[1], l[2]);
        let x = (l[1] * l[1] + l[2] * l[2] - l[0] * l[0]) / (2.0 * l[2]);
        let y = (l[1] * l[1] - x * x).max(0.0).sqrt();
        let cot = [0, 1, 2].map(|k| {
            let (a, b, c) = (l[k], l[(k + 1) % 3], l[(k + 2) % 3]);
            (b * b + c * c - a * a) / (4.0 * area)
        });
        TriangleFrame {
            points: [[0.0, 0.0], [l[2], 0.0], [x, y]],
            cot,
            area,
        }
    }

    /// `-grad u / |grad u|` for the linear function with corner values `u`, or `None` where
    /// the gradient vanishes or the triangle has no area.
    fn unit_descent(&self, u: [f64; 3]) -> Option<[f64; 2]> {
        if !(self.area > 0.0) {
            return None;
        }
        let p = self.points;
        let mut g = [0.0; 2];
        for k in 0..3 {
            // grad phi_k = rot90(p[k+2] - p[k+1]) / (2 area)
            let e = [
                p[(k + 2) % 3][0] - p[(k + 1) % 3][0],
                p[(k + 2) % 3][1] - p[(k + 1) % 3][1],
            ];
            g[0] += u[k] * -e[1];
            g[1] += u[k] * e[0];
        }
        let norm = (g[0] * g[0] + g[1] * g[1]).sqrt();
        (norm > 0.0 && norm.is_finite()).then(|| [-g[0] / norm, -g[1] / norm])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat `nx` by `ny` grid of unit squares in the xy plane, each split into two
    /// triangles along the same diagonal.
    fn grid(nx: usize, ny: usize, spacing: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut vertices = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                vertices.push([i as f64 * spacing, j as f64 * spacing, 0.0]);
            }
        }
        let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
        let mut triangles = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        (vertices, triangles)
    }

    #[test]
    fn distances_along_grid_axes_are_euclidean() {
        let (vertices, triangles) = grid(10, 6, 0.5);
        let shape = Shape::mesh(vertices.clone(), &triangles).unwrap();
        let d = edge_graph_distances(&shape, &[0], 2.0);
        for (v, p) in vertices.iter().enumerate() {
            if p[1] == 0.0 || p[0] == 0.0 || p[0] == p[1] {
                let euclid = 2.0 * (p[0] * p[0] + p[1] * p[1]).sqrt();
                assert!(
                    (d[v] - euclid).abs() < 1e-12,
                    "vertex {v}: {} vs {euclid}",
                    d[v]
                );
            }
            // Edge paths never beat the straight line.
            assert!(d[v] >= 2.0 * (p[0] * p[0] + p[1] * p[1]).sqrt() - 1e-12);
        }
    }

    #[test]
    fn multi_source_is_the_minimum_of_single_sources() {
        let (vertices, triangles) = grid(12, 7, 1.0);
        let shape = Shape::mesh(vertices, &triangles).unwrap();
        let sources = [3u32, 40, 77];
        let all = edge_graph_distances(&shape, &sources, 1.0);
        let singles: Vec<Vec<f64>> = sources
            .iter()
            .map(|&s| edge_graph_distances(&shape, &[s], 1.0))
            .collect();
        for v in 0..all.len() {
            let min = singles.iter().map(|d| d[v]).fold(f64::INFINITY, f64::min);
            assert_eq!(all[v], min, "vertex {v}");
        }
        for &s in &sources {
            assert_eq!(all[s as usize], 0.0);
        }
    }

    #[test]
    fn unreferenced_vertices_take_their_representatives_value() {
        let (mut vertices, triangles) = grid(6, 4, 1.0);
        let n = vertices.len() as u32;
        // Two stray vertices used by no face, near vertices (6, 4) and (0, 2).
        vertices.push([6.2, 4.1, 0.3]);
        vertices.push([-0.4, 2.0, 0.0]);
        let shape = Shape::mesh(vertices, &triangles).unwrap();
        let representative = shape.representative();
        assert_eq!(representative[n as usize], 34);
        assert_eq!(representative[n as usize + 1], 14);
        let d = edge_graph_distances(&shape, &[0], 1.0);
        assert_eq!(d[n as usize], d[34]);
        assert_eq!(d[n as usize + 1], d[14]);
        assert_eq!(d[14], 2.0);
        // An unreferenced source stands for its representative.
        let from_stray = edge_graph_distances(&shape, &[n + 1], 1.0);
        assert_eq!(from_stray, edge_graph_distances(&shape, &[14], 1.0));
    }

    #[test]
    fn other_pieces_are_unreachable() {
        let (mut vertices, mut triangles) = grid(3, 3, 1.0);
        let (second, second_triangles) = grid(3, 3, 1.0);
        let offset = vertices.len() as u32;
        vertices.extend(second.iter().map(|p| [p[0] + 10.0, p[1], p[2]]));
        triangles.extend(second_triangles.iter().map(|t| t.map(|v| v + offset)));
        // The repairs would leave the second grid out as a separate object.
        let keep_pieces = crate::shape::Repairs {
            debris_fraction: 0.0,
            ..Default::default()
        };
        let polygons: Vec<Vec<u32>> = triangles.iter().map(|t| t.to_vec()).collect();
        let shape = Shape::mesh_with(vertices, &polygons, &keep_pieces).unwrap();
        let d = edge_graph_distances(&shape, &[0], 1.0);
        assert!(d[..offset as usize].iter().all(|x| x.is_finite()));
        assert!(d[offset as usize..].iter().all(|x| *x == f64::INFINITY));

        // Region level: two regions per piece; across pieces the large finite value.
        let labels: Vec<u32> = (0..shape.n_vertices())
            .map(|v| 2 * (v as u32 / offset) + u32::from(v % 4 >= 2))
            .collect();
        let mass = vec![1.0 / shape.n_vertices() as f64; shape.n_vertices()];
        let m = region_distance_matrix(&shape, &mass, &labels, 4, 1.0);
        // Within a piece: columns {0, 1} to {2, 3} is 1.5 on average either way; the
        // largest finite vertex distance (a half to the far column) is 2.
        assert!((m[(0, 1)] - 1.5).abs() < 1e-12, "{}", m[(0, 1)]);
        assert!((m[(2, 3)] - 1.5).abs() < 1e-12, "{}", m[(2, 3)]);
        for r in 0..4 {
            for q in 0..4 {
                if r / 2 != q / 2 {
                    assert_eq!(m[(r, q)], UNREACHABLE_FACTOR * 2.0, "({r}, {q})");
                }
            }
        }
    }

    #[test]
    fn region_matrix_is_symmetric_with_zero_diagonal_and_grows_along_a_strip() {
        // A 40 by 2 strip cut into 8 blocks of 5 columns along x.
        let (vertices, triangles) = grid(40, 2, 0.25);
        let shape = Shape::mesh(vertices.clone(), &triangles).unwrap();
        let labels: Vec<u32> = vertices
            .iter()
            .map(|p| ((p[0] / 0.25).round() as u32 / 5).min(7))
            .collect();
        let mass: Vec<f64> = vertices
            .iter()
            .map(|p| if p[1] == 0.0 { 1.0 } else { 0.5 })
            .collect();
        let m = region_distance_matrix(&shape, &mass, &labels, 8, 1.0);
        for r in 0..8 {
            assert_eq!(m[(r, r)], 0.0);
            for q in 0..8 {
                assert_eq!(m[(r, q)], m[(q, r)]);
                if q > r + 1 {
                    assert!(m[(r, q)] > m[(r, q - 1)], "({r}, {q})");
                }
            }
        }
        // Neighbouring blocks: d_R over the next block is 0.25, ..., 1.25 in every row.
        assert!((m[(2, 3)] - 0.75).abs() < 1e-12, "{}", m[(2, 3)]);
        // Deterministic, whatever the threads.
        let again = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| region_distance_matrix(&shape, &mass, &labels, 8, 1.0));
        assert_eq!(m, again);
    }

    #[test]
    fn entry_ordering_pops_smallest_distance_then_smallest_vertex() {
        let mut heap = BinaryHeap::new();
        for (distance, vertex) in [(2.0, 1), (1.0, 5), (1.0, 3), (0.5, 9)] {
            heap.push(Entry { distance, vertex });
        }
        let order: Vec<u32> = std::iter::from_fn(|| heap.pop().map(|e| e.vertex)).collect();
        assert_eq!(order, vec![9, 3, 5, 1]);
    }
}
