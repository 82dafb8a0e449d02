//! Repairs of what real files contain (docs/decisions.md, "Repairs"): vertices split along
//! UV seams or never welded (triangle soups), scan debris (small loose pieces), far
//! vertices and outlier points.
//!
//! Every repair keeps the caller's vertex order: a repaired-away vertex becomes inactive and
//! takes the values of an active one ([`super::Shape::representative`]): a welded duplicate
//! those of the vertex it was welded to, a dropped one those of the nearest kept vertex. Each
//! repair is reported as a [`super::Warning`] and can be switched off ([`Repairs`]).
//! Tolerances measured on every shape of `../shared/data` (docs/decisions.md, "Repairs").
//! The repairs look at a [`Cancel`] every few thousand elements of their loops
//! (docs/decisions.md, "Dense shapes: limits"); `&Cancel::default()` runs them to the end.

use std::collections::HashMap;

use super::neighbors::{local_delaunay_around, PointTree};
use super::{distance, DisjointSets};
use crate::progress::Cancel;
use crate::Result;

/// Which repairs [`super::Shape`] construction makes, and their tolerances.
#[derive(Debug, Clone, PartialEq)]
pub struct Repairs {
    /// Vertices closer than this fraction of the shape's size ([`robust_size`]) are welded
    /// into one; 0 switches welding off. Exporters write seam duplicates bit-identical or
    /// within float rounding (1e-7 of the size); no shape of the benchmarks has two distinct
    /// vertices within 1e-6 of its size.
    pub weld_tolerance: f64,
    /// Connected pieces holding less than this fraction of the area (a point cloud: of the
    /// points) are dropped as debris, when a larger piece remains; 0 switches it off.
    pub debris_fraction: f64,
    /// Pieces of a mesh that come closer than this fraction of the shape's size
    /// ([`robust_size`]), or than [`JOIN_SPACINGS`] local edge lengths, are joined by bridge
    /// triangles ([`bridges_between_pieces`]): one figure modelled in pieces (a robot, a
    /// character with separate head, hands and clothes) is one shape for the spectral
    /// stages, and the debris rule weighs joined pieces together. 0 switches it off.
    pub join_gap: f64,
    /// Drop far vertices (beyond [`FAR_FACTOR`] times the shape's robust radius) and, in a
    /// point cloud, isolated points (local-density test, [`OUTLIER_SPACING_FACTOR`]).
    pub outliers: bool,
    /// Keeps the struct open to new fields: build it with `..Default::default()`.
    #[doc(hidden)]
    pub non_exhaustive: crate::NonExhaustive,
}

impl Default for Repairs {
    fn default() -> Self {
        Repairs {
            weld_tolerance: 1e-6,
            debris_fraction: 0.01,
            join_gap: JOIN_GAP,
            outliers: true,
            non_exhaustive: crate::NonExhaustive(()),
        }
    }
}

impl Repairs {
    /// No repair at all: the shape is used as given.
    pub fn none() -> Repairs {
        Repairs {
            weld_tolerance: 0.0,
            debris_fraction: 0.0,
            join_gap: 0.0,
            outliers: false,
            ..Default::default()
        }
    }
}

/// Default [`Repairs::join_gap`]: 1% of the size, about 2 cm on a person. Not tuned on a
/// benchmark (no benchmark shape has two pieces): a gap a modeller leaves between a part
/// and what it rests on (armour on a body, a head on a neck) is a few millimetres to a
/// centimetre; a prop beside a figure is usually further.
pub const JOIN_GAP: f64 = 0.01;

/// Pieces whose vertices come within this many local edge lengths (the mean length of the
/// edges at either vertex) are joined whatever [`Repairs::join_gap`] says: touching pieces
/// of a coarse mesh have no coincident vertices, their nearest vertices lie about one edge
/// apart.
pub const JOIN_SPACINGS: f64 = 2.0;

/// Neighbours looked at per vertex when joining pieces (and triangulated into bridges).
const JOIN_NEIGHBOURS: usize = 16;

/// Pieces of fewer triangles are never joined: scan debris is specks of a few triangles
/// (`../shared/reliability`'s is single triangles), which the debris rule leaves out; a
/// modelled part, even a bolt or a button, has tens.
pub const MIN_JOINED_TRIANGLES: usize = 10;

/// A vertex farther from the shape's centre than this many robust radii is dropped.
pub const FAR_FACTOR: f64 = 10.0;

/// Quantile of the distances to the centre that defines the robust radius.
const RADIUS_QUANTILE: f64 = 0.95;

/// A point whose distance to its [`OUTLIER_NEIGHBOUR`]-th nearest neighbour exceeds this many
/// times the median of that distance is an outlier.
pub const OUTLIER_SPACING_FACTOR: f64 = 8.0;

/// The neighbour the local-density test measures the distance to.
const OUTLIER_NEIGHBOUR: usize = 6;

/// The coordinate-wise median of `points` (of those listed in `of`) and the
/// [`RADIUS_QUANTILE`] quantile of their distances to it: a centre and a radius that a few
/// far vertices cannot move.
pub fn robust_centre_and_radius(points: &[[f64; 3]], of: &[u32]) -> ([f64; 3], f64) {
    let centre: [f64; 3] =
        std::array::from_fn(|c| median(of.iter().map(|&v| points[v as usize][c]).collect()));
    let mut radii: Vec<f64> = of
        .iter()
        .map(|&v| distance(&points[v as usize], &centre))
        .collect();
    radii.sort_by(f64::total_cmp);
    let at = ((radii.len() as f64 * RADIUS_QUANTILE) as usize).min(radii.len() - 1);
    (centre, radii[at])
}

/// Twice the robust radius: the size tolerances are relative to.
pub fn robust_size(points: &[[f64; 3]], of: &[u32]) -> f64 {
    2.0 * robust_centre_and_radius(points, of).1
}

/// Of the vertices `of`, those beyond [`FAR_FACTOR`] robust radii from the robust centre.
pub fn far_vertices(points: &[[f64; 3]], of: &[u32]) -> Vec<u32> {
    let (centre, radius) = robust_centre_and_radius(points, of);
    of.iter()
        .copied()
        .filter(|&v| distance(&points[v as usize], &centre) > FAR_FACTOR * radius)
        .collect()
}

/// For every vertex, the vertex it is welded to: the lowest index among the vertices of
/// `of` chained to it by distances at most `tolerance` (itself when none; vertices not in
/// `of` are left alone). Found on a grid of cells of the tolerance's size.
pub fn weld(points: &[[f64; 3]], of: &[u32], tolerance: f64, cancel: &Cancel) -> Result<Vec<u32>> {
    let mut root: Vec<u32> = (0..points.len() as u32).collect();
    if !(tolerance > 0.0) || of.is_empty() {
        return Ok(root);
    }
    let (centre, _) = robust_centre_and_radius(points, of);
    let cell = |p: &[f64; 3]| -> [i64; 3] {
        std::array::from_fn(|c| ((p[c] - centre[c]) / tolerance).floor() as i64)
    };
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::with_capacity(of.len());
    for (i, &v) in of.iter().enumerate() {
        cancel.check_every(i)?;
        grid.entry(cell(&points[v as usize])).or_default().push(v);
    }
    let mut sets = DisjointSets::new(points.len());
    for (i, &v) in of.iter().enumerate() {
        cancel.check_every(i)?;
        let p = &points[v as usize];
        let [x, y, z] = cell(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    // A point far beyond the tolerance saturates its cell at i64::MIN/MAX,
                    // which has no neighbour past it.
                    let (Some(a), Some(b), Some(c)) =
                        (x.checked_add(dx), y.checked_add(dy), z.checked_add(dz))
                    else {
                        continue;
                    };
                    let Some(others) = grid.get(&[a, b, c]) else {
                        continue;
                    };
                    for &w in others {
                        if w > v && distance(p, &points[w as usize]) <= tolerance {
                            sets.union(v as usize, w as usize);
                        }
                    }
                }
            }
        }
    }
    for (i, &v) in of.iter().enumerate() {
        cancel.check_every(i)?;
        root[v as usize] = sets.find(v as usize) as u32;
    }
    Ok(root)
}

/// What the repairs do with a connected piece of a shape (pieces joined by
/// [`bridges_between_pieces`] count as one).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PieceRole {
    /// The figure: the largest piece (all pieces when none is larger than debris).
    Kept,
    /// A small loose piece (less than [`Repairs::debris_fraction`] of the shape): left out.
    Debris,
    /// A piece as large as a part but not joined to the largest one (a prop, a base, a
    /// second object beside the figure): left out. The spectral stages need one connected
    /// surface: two pieces have two constant eigenfunctions, which a refinement sample
    /// cannot tell apart (docs/scans.md, "Props").
    Separate,
}

/// Every piece's role from its size (`sizes[p]`: area or point count), with `fraction`
/// the debris fraction (0: nothing left out).
fn piece_roles(sizes: &[f64], fraction: f64) -> Vec<PieceRole> {
    let total: f64 = sizes.iter().sum();
    let large = |s: f64| s >= fraction * total;
    if !(fraction > 0.0) || !sizes.iter().any(|&s| large(s)) {
        return vec![PieceRole::Kept; sizes.len()];
    }
    // The first of equal largest pieces, so that the choice does not depend on the order.
    let largest = (0..sizes.len())
        .max_by(|&i, &j| sizes[i].total_cmp(&sizes[j]).then(j.cmp(&i)))
        .unwrap_or(0);
    (0..sizes.len())
        .map(|p| match p {
            p if p == largest => PieceRole::Kept,
            p if large(sizes[p]) => PieceRole::Separate,
            _ => PieceRole::Debris,
        })
        .collect()
}

/// Every triangle's piece role ([`PieceRole`]): pieces holding less than `fraction` of the
/// area are debris, the largest piece is kept, the others are separate objects; pieces
/// joined by `bridges` ([`bridges_between_pieces`]) count as one.
pub fn piece_roles_of_triangles(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    bridges: &[[u32; 3]],
    fraction: f64,
    cancel: &Cancel,
) -> Result<Vec<PieceRole>> {
    let mut sets = DisjointSets::new(vertices.len());
    for (i, t) in triangles.iter().chain(bridges).enumerate() {
        cancel.check_every(i)?;
        sets.union(t[0] as usize, t[1] as usize);
        sets.union(t[1] as usize, t[2] as usize);
    }
    // Pieces numbered in the order of their first triangle.
    let mut piece_of_root: HashMap<usize, usize> = HashMap::new();
    let mut piece: Vec<usize> = Vec::with_capacity(triangles.len());
    let mut area: Vec<f64> = Vec::new();
    for (i, t) in triangles.iter().enumerate() {
        cancel.check_every(i)?;
        let root = sets.find(t[0] as usize);
        let next = piece_of_root.len();
        let p = *piece_of_root.entry(root).or_insert(next);
        if p == area.len() {
            area.push(0.0);
        }
        area[p] += super::triangle_area(vertices, t);
        piece.push(p);
    }
    let roles = piece_roles(&area, fraction);
    Ok(piece.iter().map(|&p| roles[p]).collect())
}

/// Triangles that join the connected pieces of a mesh (of at least
/// [`MIN_JOINED_TRIANGLES`] triangles) where they come close: around every
/// vertex with a vertex of another piece within its reach (`gap`, or [`JOIN_SPACINGS`]
/// times the mean length of the edges at either vertex), the local Delaunay triangles of
/// its [`JOIN_NEIGHBOURS`] nearest vertices in its tangent plane (the point-cloud
/// Laplacian's construction, [`local_delaunay_around`]) that span two pieces and whose
/// edges stay within twice the reach. Sorted, without repeats; empty for one piece.
pub fn bridges_between_pieces(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    gap: f64,
    cancel: &Cancel,
) -> Result<Vec<[u32; 3]>> {
    let n = vertices.len();
    let mut sets = DisjointSets::new(n);
    let mut spacing_sum = vec![0.0f64; n];
    let mut spacing_count = vec![0u32; n];
    for (i, t) in triangles.iter().enumerate() {
        cancel.check_every(i)?;
        sets.union(t[0] as usize, t[1] as usize);
        sets.union(t[1] as usize, t[2] as usize);
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let length = distance(&vertices[a], &vertices[b]);
            for v in [a, b] {
                spacing_sum[v] += length;
                spacing_count[v] += 1;
            }
        }
    }
    let mut piece_triangles: HashMap<usize, usize> = HashMap::new();
    for t in triangles {
        *piece_triangles.entry(sets.find(t[0] as usize)).or_default() += 1;
    }
    let used: Vec<u32> = (0..n as u32)
        .filter(|&v| {
            spacing_count[v as usize] > 0
                && piece_triangles[&sets.find(v as usize)] >= MIN_JOINED_TRIANGLES
        })
        .collect();
    let piece: Vec<usize> = used.iter().map(|&v| sets.find(v as usize)).collect();
    if piece.windows(2).all(|w| w[0] == w[1]) {
        return Ok(Vec::new());
    }
    let points: Vec<[f64; 3]> = used.iter().map(|&v| vertices[v as usize]).collect();
    let reach: Vec<f64> = used
        .iter()
        .map(|&v| {
            let spacing = spacing_sum[v as usize] / spacing_count[v as usize] as f64;
            gap.max(JOIN_SPACINGS * spacing)
        })
        .collect();
    let tree = PointTree::new(&points);
    let mut bridges = Vec::new();
    for (i, p) in points.iter().enumerate() {
        cancel.check_every(i)?;
        let neighbours = tree.nearest_k(p, JOIN_NEIGHBOURS + 1);
        let near_other = neighbours
            .iter()
            .any(|&(j, d2)| piece[j] != piece[i] && d2.sqrt() <= reach[i].max(reach[j]));
        if !near_other {
            continue;
        }
        let limit = 2.0 * reach[i];
        let local: Vec<(usize, f64)> = neighbours
            .into_iter()
            .filter(|&(_, d2)| d2.sqrt() <= limit)
            .collect();
        for t in local_delaunay_around(&points, i, &local) {
            let [a, b, c] = t.map(|k| k as usize);
            let spans = piece[a] != piece[b] || piece[b] != piece[c];
            let short = [(a, b), (b, c), (c, a)]
                .iter()
                .all(|&(x, y)| distance(&points[x], &points[y]) <= limit);
            if spans && short {
                let mut corners = t.map(|k| used[k as usize]);
                corners.sort_unstable();
                bridges.push(corners);
            }
        }
    }
    bridges.sort_unstable();
    bridges.dedup();
    Ok(bridges)
}

/// Two points of a cloud are in one piece when a chain of points joins them, each step at
/// most this many times the larger of its two ends' spacings ([`CloudNeighbourhoods`]).
/// Relative to each point's own spacing, because the benchmarks' vertex sets vary in
/// density by 10x and more (TOSCA's david): a global spacing split 9,000 of david's 52,565
/// vertices off as "debris", and the k-nearest-neighbour graph itself splits the dense
/// patches of FAUST's vertices off as pieces of 30 to 60 points.
pub const PIECE_LINK_SPACINGS: f64 = 5.0;

/// Nearest neighbours looked at for the links of [`PIECE_LINK_SPACINGS`].
const LINK_NEIGHBOURS: usize = 32;

/// Every point's nearest neighbours and its spacing (the distance to its
/// [`OUTLIER_NEIGHBOUR`]-th nearest other point), for the point-cloud repairs.
struct CloudNeighbourhoods {
    /// Per point (position in `of`): its [`LINK_NEIGHBOURS`] nearest others, with distances.
    near: Vec<Vec<(usize, f64)>>,
    spacing: Vec<f64>,
}

impl CloudNeighbourhoods {
    fn new(points: &[[f64; 3]], of: &[u32], cancel: &Cancel) -> Result<Self> {
        let subset: Vec<[f64; 3]> = of.iter().map(|&v| points[v as usize]).collect();
        let tree = PointTree::new(&subset);
        // nearest_k returns squared distances and includes the point itself.
        let mut near: Vec<Vec<(usize, f64)>> = Vec::with_capacity(subset.len());
        for (i, p) in subset.iter().enumerate() {
            cancel.check_every(i)?;
            near.push(
                tree.nearest_k(p, LINK_NEIGHBOURS + 1)
                    .into_iter()
                    .filter(|&(j, _)| j != i)
                    .map(|(j, d2)| (j, d2.sqrt()))
                    .collect(),
            );
        }
        let spacing = near
            .iter()
            .map(|list| list.get(OUTLIER_NEIGHBOUR - 1).map_or(0.0, |&(_, d)| d))
            .collect();
        Ok(CloudNeighbourhoods { near, spacing })
    }
}

/// A point cloud's points `of` that are kept ([`PieceRole`]: pieces linked by
/// [`PIECE_LINK_SPACINGS`], those under `fraction` of the points are debris, the largest is
/// kept, the others are separate objects), and how many debris and separate pieces were
/// left out with how many points.
pub fn keep_cloud_figure(
    points: &[[f64; 3]],
    of: &[u32],
    fraction: f64,
    cancel: &Cancel,
) -> Result<(Vec<u32>, LeftOut)> {
    if !(fraction > 0.0) || of.len() <= LINK_NEIGHBOURS {
        return Ok((of.to_vec(), LeftOut::default()));
    }
    let hood = CloudNeighbourhoods::new(points, of, cancel)?;
    let mut sets = DisjointSets::new(of.len());
    for (i, list) in hood.near.iter().enumerate() {
        cancel.check_every(i)?;
        for &(j, d) in list {
            if d <= PIECE_LINK_SPACINGS * hood.spacing[i].max(hood.spacing[j]) {
                sets.union(i, j);
            }
        }
    }
    let mut piece_of_root: HashMap<usize, usize> = HashMap::new();
    let mut count: Vec<f64> = Vec::new();
    let piece: Vec<usize> = (0..of.len())
        .map(|i| {
            let next = piece_of_root.len();
            let p = *piece_of_root.entry(sets.find(i)).or_insert(next);
            if p == count.len() {
                count.push(0.0);
            }
            count[p] += 1.0;
            p
        })
        .collect();
    let roles = piece_roles(&count, fraction);
    let mut left_out = LeftOut::default();
    for (p, role) in roles.iter().enumerate() {
        left_out.add(*role, count[p] as usize);
    }
    let kept = of
        .iter()
        .zip(&piece)
        .filter(|(_, &p)| roles[p] == PieceRole::Kept)
        .map(|(&v, _)| v)
        .collect();
    Ok((kept, left_out))
}

/// The pieces the repairs left out, and their vertices, by role.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LeftOut {
    /// Debris pieces and their vertices.
    pub debris: (usize, usize),
    /// Separate objects and their vertices.
    pub separate: (usize, usize),
}

impl LeftOut {
    /// Counts a piece of `vertices` vertices with its role.
    pub fn add(&mut self, role: PieceRole, vertices: usize) {
        let slot = match role {
            PieceRole::Kept => return,
            PieceRole::Debris => &mut self.debris,
            PieceRole::Separate => &mut self.separate,
        };
        slot.0 += 1;
        slot.1 += vertices;
    }
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// Of a point cloud's points `of`, those that pass the local-density test: a point's spacing
/// at most [`OUTLIER_SPACING_FACTOR`] times the median spacing of its
/// [`OUTLIER_NEIGHBOUR`] nearest neighbours (a local outlier factor, so that the density may
/// vary across the cloud).
pub fn dense_points(points: &[[f64; 3]], of: &[u32], cancel: &Cancel) -> Result<Vec<u32>> {
    if of.len() <= LINK_NEIGHBOURS {
        return Ok(of.to_vec());
    }
    let hood = CloudNeighbourhoods::new(points, of, cancel)?;
    cancel.check()?;
    Ok(of
        .iter()
        .enumerate()
        .filter(|&(i, _)| {
            let around = median(
                hood.near[i][..OUTLIER_NEIGHBOUR]
                    .iter()
                    .map(|&(j, _)| hood.spacing[j])
                    .collect(),
            );
            hood.spacing[i] <= OUTLIER_SPACING_FACTOR * around
        })
        .map(|(_, &v)| v)
        .collect())
}
