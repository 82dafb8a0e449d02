//! A figure cut into rigid pieces, as a robot or a game character is modelled: every
//! triangle goes to the bone that moves it most (its corners' summed skinning weights),
//! each bone's triangles are cut into slabs across their longest direction, and every piece
//! is its own connected part (its vertices duplicated where pieces meet), optionally shrunk
//! about its centre to leave a gap. Every vertex remembers the figure's vertex it copies:
//! the ground truth.

use std::collections::BTreeMap;

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use super::{invalid, Rig};
use crate::Result;

/// A figure in pieces.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecesMesh {
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles, oriented as the figure's.
    pub triangles: Vec<[u32; 3]>,
    /// For every vertex, the figure's vertex it copies.
    pub original: Vec<u32>,
    /// Number of pieces.
    pub n_pieces: usize,
}

/// The figure `vertices` (the rig's rest mesh posed: the same triangles) cut into pieces:
/// one per bone, each cut into `slabs` slabs along its rest triangles' principal direction,
/// each shrunk about its centroid by the fraction `gap` (0: pieces meet exactly).
///
/// Errors with [`crate::Error::InvalidParameter`] when `vertices` is not the rig's size,
/// `slabs` is 0 or `gap` is outside [0, 0.5).
pub fn cut_into_pieces(
    rig: &Rig,
    vertices: &[[f64; 3]],
    slabs: usize,
    gap: f64,
) -> Result<PiecesMesh> {
    let rest = &rig.rest;
    if vertices.len() != rest.vertices.len() {
        return Err(invalid(
            "vertices",
            format!(
                "{} given, the rig has {}",
                vertices.len(),
                rest.vertices.len()
            ),
        ));
    }
    if slabs == 0 || !(0.0..0.5).contains(&gap) {
        return Err(invalid(
            "pieces",
            format!("slabs {slabs} must be positive and gap {gap} in [0, 0.5)"),
        ));
    }
    let bone_of = |t: &[u32; 3]| -> usize {
        let weight = |b: usize| -> f64 {
            t.iter()
                .map(|&v| rig.weights[v as usize * rig.n_bones + b])
                .sum()
        };
        (0..rig.n_bones)
            .max_by(|&x, &y| weight(x).total_cmp(&weight(y)).then(y.cmp(&x)))
            .unwrap_or(0)
    };
    let centroid = |t: &[u32; 3]| -> [f64; 3] {
        std::array::from_fn(|c| t.iter().map(|&v| rest.vertices[v as usize][c]).sum::<f64>() / 3.0)
    };
    let mut by_bone: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (f, t) in rest.triangles.iter().enumerate() {
        by_bone.entry(bone_of(t)).or_default().push(f);
    }
    let mut piece_of = vec![(0usize, 0usize); rest.triangles.len()];
    for (&bone, faces) in &by_bone {
        let points: Vec<[f64; 3]> = faces
            .iter()
            .map(|&f| centroid(&rest.triangles[f]))
            .collect();
        let axis = principal_direction(&points);
        let along: Vec<f64> = points.iter().map(|p| dot(p, &axis)).collect();
        let (lo, hi) = along
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
                (l.min(x), h.max(x))
            });
        for (&f, &x) in faces.iter().zip(&along) {
            let slab = (((x - lo) / (hi - lo).max(1e-300)) * slabs as f64) as usize;
            piece_of[f] = (bone, slab.min(slabs - 1));
        }
    }
    let mut pieces: BTreeMap<(usize, usize), Vec<usize>> = BTreeMap::new();
    for (f, &p) in piece_of.iter().enumerate() {
        pieces.entry(p).or_default().push(f);
    }
    let mut out = PiecesMesh {
        vertices: Vec::new(),
        triangles: Vec::new(),
        original: Vec::new(),
        n_pieces: pieces.len(),
    };
    for faces in pieces.values() {
        let first = out.vertices.len();
        let mut index: BTreeMap<u32, u32> = BTreeMap::new();
        for &f in faces {
            let t = rest.triangles[f].map(|v| {
                *index.entry(v).or_insert_with(|| {
                    out.vertices.push(vertices[v as usize]);
                    out.original.push(v);
                    (out.vertices.len() - 1) as u32
                })
            });
            out.triangles.push(t);
        }
        let part = &mut out.vertices[first..];
        let n = part.len() as f64;
        let centre: [f64; 3] = std::array::from_fn(|c| part.iter().map(|p| p[c]).sum::<f64>() / n);
        for p in part.iter_mut() {
            *p = std::array::from_fn(|c| centre[c] + (1.0 - gap) * (p[c] - centre[c]));
        }
    }
    Ok(out)
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The direction of largest spread of `points` (the covariance's leading eigenvector).
fn principal_direction(points: &[[f64; 3]]) -> [f64; 3] {
    let n = points.len().max(1) as f64;
    let mean = points
        .iter()
        .map(|p| Vector3::from(*p))
        .sum::<Vector3<f64>>()
        / n;
    let covariance = points
        .iter()
        .map(|p| {
            let d = Vector3::from(*p) - mean;
            d * d.transpose()
        })
        .sum::<Matrix3<f64>>();
    let eigen = SymmetricEigen::new(covariance);
    let leading = eigen.eigenvalues.imax();
    let axis = eigen.eigenvectors.column(leading);
    [axis.x, axis.y, axis.z]
}
