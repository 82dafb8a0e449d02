//! Per-corner data (texture coordinates) carried from A's triangles to B's, seams kept
//! (issue 21).
//!
//! A's triangles fall into islands: two triangles sharing an edge are in one island when
//! their corners on that edge carry the same values (a UV seam is an edge where they do
//! not). Every corner of B is located on A by the [`SurfaceMap`] (a triangle of A and
//! weights) and takes the weighted corner values of that triangle. A triangle of B whose
//! corners land in different islands straddles A's seam: all its corners are put in the
//! island most of them landed in (the first corner's on a tie), the others re-located on
//! that island's triangles around their own landing triangle (the closest point in space).
//! So B's seam runs along B's edges nearest A's seam, and no triangle of B spans two
//! islands (which would smear it across the texture).

use std::collections::HashMap;

use crate::maps::surface::SurfaceMap;
use crate::shape::surface_point::closest_on_triangle;
use crate::shape::{DisjointSets, Shape};
use crate::{Error, Result};

/// Corner values closer than this are the same value (an edge between them is no seam).
const SAME_VALUE: f64 = 1e-6;

/// A's triangles as the caller gave them, with their corner values and islands.
struct Islands<'a> {
    a: &'a Shape,
    faces: &'a [[u32; 3]],
    values: &'a [f64],
    channels: usize,
    island: Vec<usize>,
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
        let islands = Islands::new(a, faces_a, corner_values_a, channels);
        let mut out = Vec::with_capacity(faces_b.len() * 3 * channels);
        for face in faces_b {
            let mut landings = face.map(|v| islands.landing(self, v as usize));
            let island_of = landings.map(|l| l.map(|l| islands.island[l.face as usize]));
            if let Some(chosen) = majority(island_of) {
                for (landing, island) in landings.iter_mut().zip(island_of) {
                    if let (Some(l), Some(i)) = (landing.as_mut(), island) {
                        if i != chosen {
                            *l = islands.relocated(*l, chosen);
                        }
                    }
                }
            }
            for (corner, landing) in face.iter().zip(landings) {
                match landing {
                    Some(l) => out.extend(islands.value_at(l)),
                    // A point of A on no triangle of `faces_a`: its vertex's first corner.
                    None => out.extend(islands.value_of_vertex(self, *corner as usize)),
                }
            }
        }
        Ok(out)
    }
}

impl<'a> Islands<'a> {
    fn new(a: &'a Shape, faces: &'a [[u32; 3]], values: &'a [f64], channels: usize) -> Self {
        let representative = a.representative();
        let rep = |v: u32| representative[v as usize];
        let corner = |f: usize, i: usize| &values[(3 * f + i) * channels..][..channels];
        let same = |x: &[f64], y: &[f64]| x.iter().zip(y).all(|(p, q)| (p - q).abs() <= SAME_VALUE);
        let mut sets = DisjointSets::new(faces.len());
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
                            sets.union(f, g);
                        }
                    }
                    None => {
                        edges.insert(edge, (f, small, large));
                    }
                }
            }
        }
        let island = (0..faces.len()).map(|f| sets.find(f)).collect();
        Islands {
            a,
            faces,
            values,
            channels,
            island,
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

    /// `landing` moved to the closest point of island `island`'s triangles around its own
    /// triangle's corners (unchanged when there is none).
    fn relocated(&self, landing: Landing, island: usize) -> Landing {
        let vertices = self.a.vertices();
        let t = self.faces[landing.face as usize];
        let point = [0, 1, 2].map(|c| {
            (0..3)
                .map(|i| landing.weights[i] * vertices[t[i] as usize][c])
                .sum::<f64>()
        });
        let representative = self.a.representative();
        let mut best: Option<(f64, u32, [f64; 3])> = None;
        for &v in &t {
            for &f in &self.around[representative[v as usize] as usize] {
                if self.island[f as usize] != island {
                    continue;
                }
                let corners = self.faces[f as usize].map(|u| vertices[u as usize]);
                let (d2, weights) = closest_on_triangle(&point, &corners);
                if best.is_none_or(|(d, g, _)| d2 < d || (d2 == d && f < g)) {
                    best = Some((d2, f, weights));
                }
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

/// The island most of the three corners landed in (the first corner's on a tie); None when
/// none landed.
fn majority(islands: [Option<usize>; 3]) -> Option<usize> {
    let landed: Vec<usize> = islands.iter().flatten().copied().collect();
    let count = |i: usize| landed.iter().filter(|&&j| j == i).count();
    let mut best = *landed.first()?;
    for &i in &landed {
        if count(i) > count(best) {
            best = i;
        }
    }
    Some(best)
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
