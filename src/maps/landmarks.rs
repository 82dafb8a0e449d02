//! Landmarks: pairs of vertices the user knows to correspond (docs/placement.md). Each
//! pair adds a descriptor to the functional map (the geodesic distance from the landmark
//! on either shape), the hypotheses are judged by how near their maps carry B's landmarks
//! to their partners ([`crate::maps::hypotheses::Verdict::apply_landmarks`]), and every
//! landmark of B maps to its partner in the answer. Two pairs on one side of a body settle
//! every symmetric choice.

use faer::MatRef;

use crate::maps::fmap::embedding_through;

use crate::shape::Shape;
use crate::{Error, Result};

/// A landmark: a vertex of A and the vertex of B that corresponds to it.
pub type Landmark = [u32; 2];

/// Most landmark pairs accepted: each adds a descriptor pair to every functional map.
pub const MAX_LANDMARKS: usize = 100;

/// Checks landmarks against the shapes they are given for: at most [`MAX_LANDMARKS`], each
/// vertex within its shape and used by the computation (not left out by the repairs: an
/// unreferenced vertex or a removed piece), and no vertex paired with two different
/// partners.
pub fn check_landmarks(landmarks: &[Landmark], a: &Shape, b: &Shape) -> Result<()> {
    let bad = |reason: String| {
        Err(Error::InvalidParameter {
            name: "landmarks",
            reason,
        })
    };
    if landmarks.len() > MAX_LANDMARKS {
        return bad(format!(
            "{} pairs given, at most {MAX_LANDMARKS} are accepted",
            landmarks.len()
        ));
    }
    for (i, pair) in landmarks.iter().enumerate() {
        for (side, (shape, &v)) in ["A", "B"].iter().zip([a, b].into_iter().zip(pair)) {
            if v as usize >= shape.n_vertices() {
                return bad(format!(
                    "pair {} ({}, {}): vertex {v} is not a vertex of {side} (it has {} vertices; \
                     indices start at 0)",
                    i + 1,
                    pair[0],
                    pair[1],
                    shape.n_vertices()
                ));
            }
            if shape.active_vertices().binary_search(&v).is_err() {
                return bad(format!(
                    "pair {} ({}, {}): vertex {v} of {side} is not used by the computation (the \
                     repairs left it out: a vertex no face uses, a duplicate, or a piece removed); \
                     choose a vertex on the surface",
                    i + 1,
                    pair[0],
                    pair[1]
                ));
            }
        }
        for (j, other) in landmarks[..i].iter().enumerate() {
            let same_a = other[0] == pair[0] && other[1] != pair[1];
            let same_b = other[1] == pair[1] && other[0] != pair[0];
            if same_a || same_b {
                return bad(format!(
                    "pairs {} ({}, {}) and {} ({}, {}) contradict each other: one vertex has two \
                     partners",
                    j + 1,
                    other[0],
                    other[1],
                    i + 1,
                    pair[0],
                    pair[1]
                ));
            }
        }
    }
    Ok(())
}

/// Mean distance, on A scaled by `scale` (to unit area), between the image of each
/// landmark of B under the functional map `fmap_ab` (`k_b x k_a`; as
/// [`crate::maps::fmap::fmap_to_p2p`] converts it: the vertex of A whose row of
/// `phi_a C^T` is nearest B's row) and its partner.
pub fn landmark_error(
    landmarks: &[Landmark],
    fmap_ab: MatRef<'_, f64>,
    (phi_a, phi_b): (MatRef<'_, f64>, MatRef<'_, f64>),
    (vertices_a, scale): (&[[f64; 3]], f64),
) -> Option<f64> {
    if landmarks.is_empty() {
        return None;
    }
    let k_b = fmap_ab.nrows();
    let embedding_a = embedding_through(fmap_ab, phi_a);
    let mut sum = 0.0;
    for &[la, lb] in landmarks {
        let image = (0..embedding_a.nrows())
            .map(|v| {
                let d: f64 = (0..k_b)
                    .map(|i| (embedding_a[(v, i)] - phi_b[(lb as usize, i)]).powi(2))
                    .sum();
                (d, v)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)))
            .map_or(la as usize, |(_, v)| v);
        let (p, q) = (vertices_a[image], vertices_a[la as usize]);
        sum += ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
    }
    Some(sum * scale / landmarks.len() as f64)
}
