//! The Laplace-Beltrami operator as a stiffness matrix `L` and a lumped mass `M`, on the
//! unit-area shape (docs/design.md, step 3).
//!
//! * Meshes: cotangent stiffness with barycentric lumped mass, computed from edge lengths
//!   after *intrinsic mollification* (Sharp and Crane 2020, "A Laplacian for Nonmanifold
//!   Triangle Meshes", section 4.5): every edge length grows by the same small epsilon so
//!   that every triangle satisfies the triangle inequality with a margin, which makes needle
//!   and zero-area triangles harmless.
//! * Point clouds: the same construction on a triangle soup made of the local Delaunay
//!   triangles around every point, in its tangent plane (Sharp and Crane 2020, section 5.7;
//!   the point-cloud Laplacian of `robust_laplacian`). Each soup triangle is made up to three
//!   times (once per corner), so stiffness and mass are divided by 3. This is better
//!   conditioned than the Gaussian kNN Laplacian of the paper and its spectrum follows the
//!   mesh's (tested: first 20 eigenvalues within 5%).
//!
//! Scaling a shape by `s` leaves cotangent weights unchanged and multiplies the mass by
//! `s^2`, so unit total area is reached by dividing the mass by the total area.
//!
//! Matrices are indexed by the shape's *active* vertices ([`Shape::active_vertices`]).

use sprs::{CsMat, TriMat};

use crate::shape::neighbors::{local_delaunay_around, PointTree};
use crate::shape::{distance, Shape, ShapeKind};
use crate::{Error, Result};

/// Mollification margin as a fraction of the mean edge length (robust_laplacian's default).
pub const MOLLIFY_FACTOR: f64 = 1e-5;

/// Neighbours used for every point's local Delaunay triangulation (robust_laplacian's
/// default for point clouds).
pub const POINT_CLOUD_NEIGHBORS: usize = 30;

/// Smallest lumped mass relative to the mean, so that the mass matrix stays positive
/// definite when a point ends up in no local triangle (isolated outliers).
const MASS_FLOOR: f64 = 1e-6;

/// Stiffness and mass of the unit-area shape, on its active vertices.
#[derive(Debug, Clone)]
pub struct Laplacian {
    /// Cotangent stiffness `L` (symmetric positive semi-definite, rows sum to zero), in
    /// compressed sparse column form with both triangles stored.
    pub stiffness: CsMat<f64>,
    /// Lumped mass `M` per active vertex; it sums to 1 (unit total area).
    pub mass: Vec<f64>,
    /// Area of the shape in the caller's units: the mesh area, or for a point cloud the
    /// area estimated by the local triangulations.
    pub input_area: f64,
}

impl Laplacian {
    /// Builds the Laplacian of a mesh or point cloud.
    pub fn new(shape: &Shape) -> Result<Laplacian> {
        Laplacian::from_triangulation(&triangulation(shape))
    }

    /// The Laplacian of a triangulation made by [`triangulation`] (so that callers that
    /// also need the triangles and their lengths build them once).
    pub(crate) fn from_triangulation(t: &Triangulation) -> Result<Laplacian> {
        // Cotangent weights do not change with scale and the mass scales by s^2, so a shape
        // far from unit size (1e-100: its areas underflow) is computed with its lengths
        // divided by a power of two (exact) and its area scaled back (docs/decisions.md,
        // "Shapes far from unit size").
        let longest = t.lengths.iter().flatten().fold(0.0f64, |m, l| m.max(*l));
        let scale = if (1e-50..1e50).contains(&longest) {
            1.0
        } else {
            crate::shape::power_of_two_near(longest)
        };
        let scaled: Vec<[f64; 3]>;
        let lengths = if scale == 1.0 {
            &t.lengths
        } else {
            scaled = t.lengths.iter().map(|l| l.map(|x| x / scale)).collect();
            &scaled
        };
        let (stiffness, mut mass) =
            cotan_from_lengths(t.positions.len(), &t.triangles, lengths, t.weight);
        let input_area: f64 = mass.iter().sum::<f64>() * scale * scale;
        if !(input_area > 0.0 && input_area.is_finite()) {
            return Err(Error::ZeroArea {
                detail: format!("the Laplacian's total mass is {input_area}"),
            });
        }
        let scaled_area = input_area / (scale * scale);
        let floor = MASS_FLOOR * scaled_area / mass.len() as f64;
        for m in &mut mass {
            *m = m.max(floor) / scaled_area;
        }
        Ok(Laplacian {
            stiffness,
            mass,
            input_area,
        })
    }

    /// Number of rows (active vertices).
    pub fn len(&self) -> usize {
        self.mass.len()
    }

    /// True when the operator has no rows (never for a validated shape).
    pub fn is_empty(&self) -> bool {
        self.mass.is_empty()
    }
}

/// The triangles a Laplacian is built on, over the active vertices.
pub(crate) struct Triangulation {
    /// `positions[i]` is active vertex `i`.
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// Mollified edge lengths per triangle, `lengths[t][k]` opposite corner `k`.
    pub lengths: Vec<[f64; 3]>,
    /// The weight each triangle counts with: 1 for a mesh's own triangles, 1/3 for a point
    /// cloud's local Delaunay triangles (each point's neighbourhood is triangulated once,
    /// so every area is counted about three times).
    pub weight: f64,
}

/// The triangulation of a shape's active vertices: a mesh's own triangles and the bridges
/// that join its pieces ([`Shape::bridges`]), or a point cloud's local Delaunay triangles,
/// with mollified edge lengths.
pub(crate) fn triangulation(shape: &Shape) -> Triangulation {
    let positions: Vec<[f64; 3]> = shape
        .active_vertices()
        .iter()
        .map(|&v| shape.vertices()[v as usize])
        .collect();
    let (triangles, weight) = match shape.kind() {
        ShapeKind::Mesh => {
            let mut compact = vec![u32::MAX; shape.n_vertices()];
            for (i, &v) in shape.active_vertices().iter().enumerate() {
                compact[v as usize] = i as u32;
            }
            let triangles: Vec<[u32; 3]> = shape
                .triangles()
                .iter()
                .map(|t| t.map(|v| compact[v as usize]))
                .collect();
            (triangles, 1.0)
        }
        ShapeKind::PointCloud => (
            local_delaunay_soup(&positions, POINT_CLOUD_NEIGHBORS),
            1.0 / 3.0,
        ),
    };
    let mut triangles = triangles;
    let mut lengths = mollified_edge_lengths(&positions, &triangles);
    if shape.intrinsic_delaunay() {
        // Flipped at about unit size (a power of two: exact), as the Laplacian is built.
        let longest = lengths.iter().flatten().fold(0.0f64, |m, l| m.max(*l));
        let scale = crate::shape::power_of_two_near(longest);
        for l in lengths.iter_mut().flatten() {
            *l /= scale;
        }
        flip_to_intrinsic_delaunay(&mut triangles, &mut lengths);
        for l in lengths.iter_mut().flatten() {
            *l *= scale;
        }
    }
    if !shape.bridges().is_empty() {
        // The bridges after the flips: they join pieces, they are not part of a surface.
        let mut compact = vec![u32::MAX; shape.n_vertices()];
        for (i, &v) in shape.active_vertices().iter().enumerate() {
            compact[v as usize] = i as u32;
        }
        let bridges: Vec<[u32; 3]> = (shape.bridges().iter())
            .map(|t| t.map(|v| compact[v as usize]))
            .collect();
        lengths.extend(mollified_edge_lengths(&positions, &bridges));
        triangles.extend(bridges);
    }
    Triangulation {
        positions,
        triangles,
        lengths,
        weight,
    }
}

/// Cotangent stiffness and barycentric mass of a triangle soup, each triangle counted with
/// `weight`: `L_ij = -weight/2 (cot a_ij + cot b_ij)`, `L_ii = -sum_j L_ij`,
/// `M_ii = weight * sum of area/3 over the triangles at i`. Edge lengths are mollified first.
pub fn cotan_laplacian(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    weight: f64,
) -> (CsMat<f64>, Vec<f64>) {
    let lengths = mollified_edge_lengths(positions, triangles);
    cotan_from_lengths(positions.len(), triangles, &lengths, weight)
}

/// [`cotan_laplacian`] from (mollified) edge lengths, `lengths[t][k]` opposite corner `k`.
fn cotan_from_lengths(
    n: usize,
    triangles: &[[u32; 3]],
    lengths: &[[f64; 3]],
    weight: f64,
) -> (CsMat<f64>, Vec<f64>) {
    let mut mass = vec![0.0; n];
    let mut entries = TriMat::with_capacity((n, n), 12 * triangles.len() + n);
    let mut diagonal = vec![0.0; n];
    for (t, l) in triangles.iter().zip(lengths) {
        // l[k] is the length of the edge opposite corner k.
        let area = heron_area(l[0], l[1], l[2]);
        if area <= 0.0 {
            continue;
        }
        for k in 0..3 {
            let (i, j) = (t[(k + 1) % 3] as usize, t[(k + 2) % 3] as usize);
            let (a, b, c) = (l[k], l[(k + 1) % 3], l[(k + 2) % 3]);
            let cot = (b * b + c * c - a * a) / (4.0 * area);
            let w = 0.5 * weight * cot;
            entries.add_triplet(i, j, -w);
            entries.add_triplet(j, i, -w);
            diagonal[i] += w;
            diagonal[j] += w;
            mass[t[k] as usize] += weight * area / 3.0;
        }
    }
    for (i, d) in diagonal.into_iter().enumerate() {
        entries.add_triplet(i, i, d);
    }
    (entries.to_csc(), mass)
}

/// Edge lengths per triangle (entry k opposite corner k), all grown by the smallest epsilon
/// that gives every triangle a margin of `MOLLIFY_FACTOR * mean edge length` in its triangle
/// inequalities.
fn mollified_edge_lengths(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut lengths: Vec<[f64; 3]> = triangles
        .iter()
        .map(|t| {
            let p = t.map(|v| positions[v as usize]);
            [
                distance(&p[1], &p[2]),
                distance(&p[2], &p[0]),
                distance(&p[0], &p[1]),
            ]
        })
        .collect();
    if lengths.is_empty() {
        return lengths;
    }
    let mean = lengths.iter().flatten().sum::<f64>() / (3 * lengths.len()) as f64;
    let delta = MOLLIFY_FACTOR * mean;
    let mut epsilon: f64 = 0.0;
    for l in &lengths {
        for k in 0..3 {
            let slack = l[(k + 1) % 3] + l[(k + 2) % 3] - l[k];
            epsilon = epsilon.max(delta - slack);
        }
    }
    if epsilon > 0.0 {
        for l in &mut lengths {
            for x in l.iter_mut() {
                *x += epsilon;
            }
        }
    }
    lengths
}

/// Sums of opposite cotangents below minus this are flipped (round-off of a Delaunay edge).
const DELAUNAY_TOLERANCE: f64 = 1e-10;

/// Flips per edge at most (the flip algorithm terminates in exact arithmetic; this bounds
/// it under round-off). Not tuned.
const FLIPS_PER_EDGE: usize = 8;

/// The cotangent of the angle at corner `k` of a triangle of edge lengths `l` (0 for a
/// degenerate one).
fn cot_at(l: &[f64; 3], k: usize) -> f64 {
    let area = heron_area(l[0], l[1], l[2]);
    if area <= 0.0 {
        return 0.0;
    }
    let (a, b, c) = (l[k], l[(k + 1) % 3], l[(k + 2) % 3]);
    (b * b + c * c - a * a) / (4.0 * area)
}

/// Flips the triangulation to its intrinsic Delaunay triangulation (Fisher et al. 2007, "An
/// algorithm for the construction of intrinsic Delaunay triangulations"; Sharp and Crane
/// 2020, section 4.3): an edge of two triangles whose opposite angles sum above pi (negative
/// cotangent weight) is replaced by the other diagonal of their quad, its length found by
/// laying the quad flat, until none is left. The surface and its vertices are unchanged.
/// Edges of one or of more than two triangles stay; so does a flip that would make an edge
/// that exists. Returns the number of flips; deterministic (a stack in triangle order).
pub(crate) fn flip_to_intrinsic_delaunay(
    triangles: &mut [[u32; 3]],
    lengths: &mut [[f64; 3]],
) -> usize {
    let key = |u: u32, v: u32| (u.min(v), u.max(v));
    let mut edges: std::collections::HashMap<(u32, u32), Vec<(usize, usize)>> =
        std::collections::HashMap::with_capacity(3 * triangles.len() / 2);
    let mut stack = Vec::with_capacity(3 * triangles.len() / 2);
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let e = key(tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let around = edges.entry(e).or_default();
            if around.is_empty() {
                stack.push(e);
            }
            around.push((t, k));
        }
    }
    stack.reverse();
    let limit = FLIPS_PER_EDGE * stack.len();
    let mut flips = 0;
    while let Some(e) = stack.pop() {
        if flips >= limit {
            break;
        }
        let Some(&[(t1, k1), (t2, k2)]) = edges.get(&e).map(Vec::as_slice) else {
            continue;
        };
        if cot_at(&lengths[t1], k1) + cot_at(&lengths[t2], k2) >= -DELAUNAY_TOLERANCE {
            continue;
        }
        let (a, b) = (triangles[t1][k1], triangles[t2][k2]);
        if a == b || edges.contains_key(&key(a, b)) {
            continue;
        }
        let (i, j) = e;
        // The length of the edge of triangle t from v's opposite corner's view: the edge
        // opposite the corner that is `v`.
        let opposite = |t: usize, v: u32| {
            let c = triangles[t].iter().position(|&x| x == v).unwrap_or(0);
            lengths[t][c]
        };
        let (ai, aj, bi, bj) = (
            opposite(t1, j),
            opposite(t1, i),
            opposite(t2, j),
            opposite(t2, i),
        );
        // The quad laid flat: i at the origin, j on the x axis, a above, b below.
        let ij = lengths[t1][k1];
        let x = |to_i: f64, to_j: f64| (to_i * to_i - to_j * to_j + ij * ij) / (2.0 * ij);
        let (xa, xb) = (x(ai, aj), x(bi, bj));
        let (ya, yb) = (
            (ai * ai - xa * xa).max(0.0).sqrt(),
            (bi * bi - xb * xb).max(0.0).sqrt(),
        );
        let ab = ((xa - xb).powi(2) + (ya + yb).powi(2)).sqrt();
        let new = ([bi, ab, ai], [aj, ab, bj]);
        if heron_area(new.0[0], new.0[1], new.0[2]) <= 0.0
            || heron_area(new.1[0], new.1[1], new.1[2]) <= 0.0
        {
            continue;
        }
        triangles[t1] = [a, i, b];
        lengths[t1] = new.0;
        triangles[t2] = [b, j, a];
        lengths[t2] = new.1;
        edges.remove(&e);
        edges.insert(key(a, b), vec![(t1, 1), (t2, 1)]);
        for (edge, from, to) in [
            (key(a, i), t1, (t1, 2)),
            (key(a, j), t1, (t2, 0)),
            (key(b, i), t2, (t1, 0)),
            (key(b, j), t2, (t2, 2)),
        ] {
            if let Some(around) = edges.get_mut(&edge) {
                if let Some(slot) = around.iter_mut().find(|(t, _)| *t == from) {
                    *slot = to;
                }
            }
            stack.push(edge);
        }
        flips += 1;
    }
    flips
}

/// Triangle area from its edge lengths, by Kahan's numerically stable form of Heron's formula.
pub(crate) fn heron_area(a: f64, b: f64, c: f64) -> f64 {
    let mut s = [a, b, c];
    s.sort_by(|x, y| y.total_cmp(x));
    let [a, b, c] = s;
    let product = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
    0.25 * product.max(0.0).sqrt()
}

/// The triangles around every point in the Delaunay triangulation of its `k` nearest
/// neighbours projected on its tangent plane (normal by PCA), as one soup.
pub fn local_delaunay_soup(points: &[[f64; 3]], k: usize) -> Vec<[u32; 3]> {
    let tree = PointTree::new(points);
    let mut soup = Vec::with_capacity(6 * points.len());
    for (i, p) in points.iter().enumerate() {
        let neighbors = tree.nearest_k(p, k + 1);
        soup.extend(local_delaunay_around(points, i, &neighbors));
    }
    soup
}
