//! Per-corner data (texture coordinates) carried from A's triangles to B's, seams kept
//! (docs/transfer.md, "Texture coordinates per corner").
//!
//! A seam of A is an edge whose two triangles carry different values at its corners. Every
//! corner of B is located on A by the [`SurfaceMap`] (a triangle of A and weights) and takes
//! the weighted corner values of that triangle. Within one triangle of B all three corners
//! must read one chart of A: from the triangle one corner landed in, A's triangles are
//! walked across edges that are no seam, up to [`CHART_STEPS`] steps; a corner that landed
//! outside that walk (across a seam) is re-located to the closest point of the walked
//! triangles. The corner whose walk reaches most of the others leads (the first on a tie).
//! So B's seam runs along B's edges nearest A's seam, and no triangle of B spans a seam
//! (which would smear it across the texture).

use std::collections::{HashMap, HashSet};

use crate::maps::surface::SurfaceMap;
use crate::shape::surface_point::closest_on_triangle;
use crate::shape::{Shape, ShapeKind};
use crate::{Error, Result};

/// Corner values closer than this are the same value (an edge between them is no seam).
const SAME_VALUE: f64 = 1e-6;

/// Most steps across A's edges walked from a triangle of B's leading corner to find its
/// other corners' triangles in the same chart. Not tuned: a triangle of B as coarse as four
/// of A's rings is still read in one chart; a coarser one is clamped to them.
const CHART_STEPS: usize = 8;

/// A's triangles as the caller gave them, with their corner values and the edges that are
/// no seam.
struct Charts<'a> {
    a: &'a Shape,
    faces: &'a [[u32; 3]],
    values: &'a [f64],
    channels: usize,
    /// For every triangle, its neighbours across edges that are no seam.
    smooth_neighbors: Vec<Vec<u32>>,
    /// A's triangles by the sorted representatives of their corners.
    by_corners: HashMap<[u32; 3], u32>,
    /// A's triangles around every representative vertex.
    around: Vec<Vec<u32>>,
}

/// Where a corner of B lands: a triangle of A and the weights of its three corners.
#[derive(Clone, Copy)]
struct Landing {
    face: u32,
    weights: [f64; 3],
}

impl SurfaceMap {
    /// Per-corner values of A's triangles `faces_a` (3 corners a triangle, `channels`
    /// values a corner, row-major: `faces_a.len() * 3 * channels` values) carried to the
    /// corners of B's triangles `faces_b`, seams kept as the module docs say. `faces_a`
    /// must be the triangles `a` was made from (in any order; a polygon mesh triangulated as
    /// it was given). Errors on wrong sizes, vertex indices out of range, values that are
    /// not finite.
    pub fn transfer_corners(
        &self,
        (a, faces_a): (&Shape, &[[u32; 3]]),
        corner_values_a: &[f64],
        faces_b: &[[u32; 3]],
        channels: usize,
    ) -> Result<Vec<f64>> {
        check(self, (a, faces_a), corner_values_a, faces_b, channels)?;
        let charts = Charts::new(a, faces_a, corner_values_a, channels);
        let mut out = Vec::with_capacity(faces_b.len() * 3 * channels);
        for face in faces_b {
            let landings = face.map(|v| charts.landing(self, v as usize));
            for (corner, landing) in face.iter().zip(charts.in_one_chart(landings)) {
                match landing {
                    Some(l) => out.extend(charts.value_at(l)),
                    // A point of A on no triangle of `faces_a`: its vertex's first corner.
                    None => out.extend(charts.value_of_vertex(self, *corner as usize)),
                }
            }
        }
        Ok(out)
    }
}

impl<'a> Charts<'a> {
    fn new(a: &'a Shape, faces: &'a [[u32; 3]], values: &'a [f64], channels: usize) -> Self {
        let representative = a.representative();
        let rep = |v: u32| representative[v as usize];
        let corner = |f: usize, i: usize| &values[(3 * f + i) * channels..][..channels];
        let same = |x: &[f64], y: &[f64]| x.iter().zip(y).all(|(p, q)| (p - q).abs() <= SAME_VALUE);
        let mut smooth_neighbors = vec![Vec::new(); faces.len()];
        let mut edges: HashMap<(u32, u32), (usize, usize, usize)> = HashMap::new();
        let mut by_corners = HashMap::new();
        let mut around = vec![Vec::new(); a.n_vertices()];
        for (f, t) in faces.iter().enumerate() {
            let mut key = t.map(rep);
            key.sort_unstable();
            by_corners.entry(key).or_insert(f as u32);
            for i in 0..3 {
                around[rep(t[i]) as usize].push(f as u32);
                let j = (i + 1) % 3;
                let (p, q) = (rep(t[i]), rep(t[j]));
                let edge = (p.min(q), p.max(q));
                // The corners of this triangle at the edge's smaller and larger end.
                let (small, large) = if p < q { (i, j) } else { (j, i) };
                match edges.get(&edge) {
                    Some(&(g, g_small, g_large)) => {
                        if same(corner(f, small), corner(g, g_small))
                            && same(corner(f, large), corner(g, g_large))
                        {
                            smooth_neighbors[f].push(g as u32);
                            smooth_neighbors[g].push(f as u32);
                        }
                    }
                    None => {
                        edges.insert(edge, (f, small, large));
                    }
                }
            }
        }
        Charts {
            a,
            faces,
            values,
            channels,
            smooth_neighbors,
            by_corners,
            around,
        }
    }

    /// Where vertex `v` of B lands, as a triangle of `faces` and its corners' weights.
    fn landing(&self, map: &SurfaceMap, v: usize) -> Option<Landing> {
        let point = map.points[v];
        let mut key = point.vertices;
        key.sort_unstable();
        let face = *self.by_corners.get(&key)?;
        let representative = self.a.representative();
        let t = self.faces[face as usize];
        let mut weights = [0.0; 3];
        for (&vertex, &w) in point.vertices.iter().zip(&point.weights) {
            let i = (0..3).find(|&i| representative[t[i] as usize] == vertex)?;
            weights[i] += w;
        }
        Some(Landing { face, weights })
    }

    /// The triangles reached from `start` in at most [`CHART_STEPS`] steps across edges
    /// that are no seam, `start` first; the walk ends early once every one of `targets` is
    /// reached (the usual case: a triangle of B lands on one or two neighbouring triangles).
    fn chart_around(&self, start: u32, targets: &[u32]) -> Vec<u32> {
        let mut reached = vec![start];
        let mut frontier = 0;
        for _ in 0..CHART_STEPS {
            if targets.iter().all(|t| reached.contains(t)) {
                break;
            }
            let end = reached.len();
            for k in frontier..end {
                for &g in &self.smooth_neighbors[reached[k] as usize] {
                    if !reached.contains(&g) {
                        reached.push(g);
                    }
                }
            }
            frontier = end;
        }
        reached
    }

    /// The three landings of a triangle of B read in one chart: the leading corner's walk
    /// (module docs) keeps the corners it reaches and re-locates the others onto it.
    fn in_one_chart(&self, landings: [Option<Landing>; 3]) -> [Option<Landing>; 3] {
        let targets: Vec<u32> = landings.iter().flatten().map(|l| l.face).collect();
        let mut best: Option<(usize, Vec<u32>)> = None;
        for &lead in &targets {
            let chart = self.chart_around(lead, &targets);
            let reached = targets.iter().filter(|t| chart.contains(t)).count();
            if best.as_ref().is_none_or(|(n, _)| reached > *n) {
                best = Some((reached, chart));
            }
        }
        let Some((_, chart)) = best else {
            return landings;
        };
        landings.map(|landing| {
            landing.map(|l| {
                if chart.contains(&l.face) {
                    l
                } else {
                    self.relocated(l, &chart)
                }
            })
        })
    }

    /// The point of A a landing stands for.
    fn point(&self, landing: &Landing) -> [f64; 3] {
        let vertices = self.a.vertices();
        let t = self.faces[landing.face as usize];
        [0, 1, 2].map(|c| {
            (0..3)
                .map(|i| landing.weights[i] * vertices[t[i] as usize][c])
                .sum::<f64>()
        })
    }

    /// `landing` moved to the closest point of the triangles `chart` (in space).
    fn relocated(&self, landing: Landing, chart: &[u32]) -> Landing {
        let vertices = self.a.vertices();
        let point = self.point(&landing);
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        for &f in chart {
            let corners = self.faces[f as usize].map(|u| vertices[u as usize]);
            let (d2, weights) = closest_on_triangle(&point, &corners);
            if best.is_none_or(|(d, g, _)| d2 < d || (d2 == d && f < g)) {
                best = Some((d2, f, weights));
            }
        }
        best.map_or(landing, |(_, face, weights)| Landing { face, weights })
    }

    fn value_at(&self, landing: Landing) -> Vec<f64> {
        let f = landing.face as usize;
        (0..self.channels)
            .map(|c| {
                (0..3)
                    .map(|i| landing.weights[i] * self.values[(3 * f + i) * self.channels + c])
                    .sum()
            })
            .collect()
    }

    /// The values of the first corner of `faces` at the heaviest vertex of B's point.
    fn value_of_vertex(&self, map: &SurfaceMap, v: usize) -> Vec<f64> {
        let vertex = map.points[v].nearest() as usize;
        let representative = self.a.representative();
        for &f in self.around.get(vertex).into_iter().flatten() {
            let t = self.faces[f as usize];
            if let Some(i) = (0..3).find(|&i| representative[t[i] as usize] as usize == vertex) {
                let mut weights = [0.0; 3];
                weights[i] = 1.0;
                return self.value_at(Landing { face: f, weights });
            }
        }
        vec![0.0; self.channels]
    }
}

fn check(
    map: &SurfaceMap,
    (a, faces_a): (&Shape, &[[u32; 3]]),
    values: &[f64],
    faces_b: &[[u32; 3]],
    channels: usize,
) -> Result<()> {
    let invalid = |name: &'static str, reason: String| Error::InvalidParameter { name, reason };
    if channels == 0 {
        return Err(invalid("channels", "must be at least 1".into()));
    }
    if a.n_vertices() != map.n_vertices_a {
        return Err(invalid(
            "a",
            format!(
                "has {} vertices, the map was made for {}",
                a.n_vertices(),
                map.n_vertices_a
            ),
        ));
    }
    if a.fingerprint() != map.fingerprint_a {
        return Err(invalid(
            "a",
            "is not the shape A the surface map was made from (same vertex count, other \
             positions or faces)"
                .into(),
        ));
    }
    if a.kind() == ShapeKind::PointCloud {
        return Err(invalid(
            "a",
            "is a point cloud: per-corner values need A's triangles (carry per-vertex values \
             with transfer)"
                .into(),
        ));
    }
    if let Some(t) = faces_a
        .iter()
        .find(|t| t.iter().any(|&v| v as usize >= a.n_vertices()))
    {
        return Err(invalid(
            "faces_a",
            format!(
                "triangle {t:?} has a vertex A does not have ({})",
                a.n_vertices()
            ),
        ));
    }
    check_faces_of(a, faces_a)?;
    let n_b = map.points.len();
    if let Some(t) = faces_b
        .iter()
        .find(|t| t.iter().any(|&v| v as usize >= n_b))
    {
        return Err(invalid(
            "faces_b",
            format!("triangle {t:?} has a vertex B does not have ({n_b})"),
        ));
    }
    if Some(values.len()) != faces_a.len().checked_mul(3 * channels) {
        return Err(invalid(
            "corner_values_a",
            format!(
                "has {} values, A has {} triangles x 3 corners x {channels} channels",
                values.len(),
                faces_a.len()
            ),
        ));
    }
    if let Some(i) = values.iter().position(|x| !x.is_finite()) {
        let corner = i / channels;
        return Err(invalid(
            "corner_values_a",
            format!(
                "triangle {} corner {} channel {} is {} (values must be finite)",
                corner / 3,
                corner % 3,
                i % channels,
                values[i]
            ),
        ));
    }
    Ok(())
}

/// `faces_a` must be the triangles `a` was made from: every one of them (by its corners'
/// representatives, in any order and orientation), and no other. A face with a repeated
/// corner is passed over, as the shape dropped it.
fn check_faces_of(a: &Shape, faces_a: &[[u32; 3]]) -> Result<()> {
    let invalid = |reason: String| Error::InvalidParameter {
        name: "faces_a",
        reason,
    };
    if faces_a.is_empty() {
        return Err(invalid(
            "is empty: give the triangles `a` was made from, with their corner values".into(),
        ));
    }
    let representative = a.representative();
    let key = |t: &[u32; 3]| -> Option<[u32; 3]> {
        let mut k = t.map(|v| representative[v as usize]);
        k.sort_unstable();
        (k[0] != k[1] && k[1] != k[2]).then_some(k)
    };
    let own: HashSet<[u32; 3]> = a.triangles().iter().filter_map(key).collect();
    let mut seen = HashSet::with_capacity(own.len());
    for (i, t) in faces_a.iter().enumerate() {
        let Some(k) = key(t) else { continue };
        if !own.contains(&k) {
            return Err(invalid(format!(
                "triangle {i} {t:?} is not a triangle of `a`: give the triangles `a` was made from"
            )));
        }
        seen.insert(k);
    }
    if seen.len() != own.len() {
        return Err(invalid(format!(
            "holds {} of the {} triangles of `a`: give every triangle `a` was made from",
            seen.len(),
            own.len()
        )));
    }
    Ok(())
}
