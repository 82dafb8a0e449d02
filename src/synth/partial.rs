//! Parts of a figure, as scanners give them: a plane cut, holes, the side one camera sees.
//! A part keeps, for each of its vertices, the vertex of the whole it is, so a part matched
//! to the whole (or to another pose of it) has exact truth.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::geom::{cross, dot, normalize, sub};
use super::FigureMesh;

/// The largest depth buffer side of [`seen_from`] (128 MiB of depths).
pub const MAX_RESOLUTION: usize = 4_096;

/// A part of a figure's mesh.
#[derive(Debug, Clone)]
pub struct Part {
    /// The part's faces, their vertices renumbered in the whole's order.
    pub mesh: FigureMesh,
    /// `whole_vertex[i]`: the vertex of the whole that the part's vertex `i` is.
    pub whole_vertex: Vec<u32>,
}

/// The triangles of `whole` that `keep` accepts, with the vertices they use.
fn keep_triangles(whole: &FigureMesh, keep: impl Fn(&[u32; 3]) -> bool) -> Part {
    let mut new_index = vec![u32::MAX; whole.vertices.len()];
    let kept: Vec<[u32; 3]> = whole.triangles.iter().copied().filter(keep).collect();
    for t in &kept {
        for &v in t {
            new_index[v as usize] = 0;
        }
    }
    let mut whole_vertex = Vec::new();
    for (v, slot) in new_index.iter_mut().enumerate() {
        if *slot == 0 {
            *slot = whole_vertex.len() as u32;
            whole_vertex.push(v as u32);
        }
    }
    Part {
        mesh: FigureMesh {
            vertices: whole_vertex
                .iter()
                .map(|&v| whole.vertices[v as usize])
                .collect(),
            triangles: kept
                .iter()
                .map(|t| t.map(|v| new_index[v as usize]))
                .collect(),
        },
        whole_vertex,
    }
}

/// The faces of `whole` whose corners all lie on the side of the plane `normal . p >=
/// offset` (the rest cut away).
pub fn cut_by_plane(whole: &FigureMesh, normal: [f64; 3], offset: f64) -> Part {
    keep_triangles(whole, |t| {
        t.iter()
            .all(|&v| dot(normal, whole.vertices[v as usize]) >= offset)
    })
}

/// `whole` with its lowest `share` of its height cut away (y up), as a scanner's field of
/// view cuts the feet off.
pub fn cut_below(whole: &FigureMesh, share: f64) -> Part {
    let (lo, hi) = extent_along(&whole.vertices, [0.0, 1.0, 0.0]);
    cut_by_plane(whole, [0.0, 1.0, 0.0], lo + share * (hi - lo))
}

/// `whole` without its outermost extremity: the vertex farthest from the centroid sets a
/// direction, and what lies beyond `1 - share` of the reach along it is cut away (a hand,
/// a foot or the head, whichever reaches farthest).
pub fn cut_extremity(whole: &FigureMesh, share: f64) -> Part {
    let n = whole.vertices.len().max(1) as f64;
    let centre: [f64; 3] =
        std::array::from_fn(|i| whole.vertices.iter().map(|p| p[i]).sum::<f64>() / n);
    let far = whole
        .vertices
        .iter()
        .map(|p| std::array::from_fn::<f64, 3, _>(|i| p[i] - centre[i]))
        .max_by(|&a, &b| dot(a, a).total_cmp(&dot(b, b)))
        .unwrap_or([0.0, 1.0, 0.0]);
    let reach = dot(far, far).sqrt().max(f64::MIN_POSITIVE);
    let away = far.map(|x| -x / reach);
    // Keep `away . p >= away . centre - (1 - share) * reach`.
    cut_by_plane(whole, away, dot(away, centre) - (1.0 - share) * reach)
}

/// `whole` with `count` holes: the faces with a corner within `radius` x the height of
/// one of `count` vertices drawn at random (seeded) are removed.
pub fn with_holes(whole: &FigureMesh, count: usize, radius: f64, seed: u64) -> Part {
    let (lo, hi) = extent_along(&whole.vertices, [0.0, 1.0, 0.0]);
    let reach2 = (radius * (hi - lo)).powi(2);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let centres: Vec<[f64; 3]> = match whole.vertices.len() {
        0 => Vec::new(),
        n => (0..count)
            .map(|_| whole.vertices[rng.random_range(0..n)])
            .collect(),
    };
    let near = |p: &[f64; 3]| {
        centres
            .iter()
            .any(|c| (0..3).map(|i| (p[i] - c[i]).powi(2)).sum::<f64>() <= reach2)
    };
    let hit: Vec<bool> = whole.vertices.iter().map(near).collect();
    keep_triangles(whole, |t| !t.iter().any(|&v| hit[v as usize]))
}

/// The faces of `whole` that a camera far along `view` sees (an orthographic depth buffer
/// of `resolution` x `resolution` cells over the figure, at most [`MAX_RESOLUTION`]): faces
/// turned towards the camera whose corners are not behind a nearer surface, as a
/// single-view scan holds them.
pub fn seen_from(whole: &FigureMesh, view: [f64; 3], resolution: usize) -> Part {
    let w = normalize(view);
    let helper = if w[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = normalize(cross(helper, w));
    let v = cross(w, u);
    // Image coordinates and depth (larger is nearer the camera).
    let image: Vec<[f64; 3]> = whole
        .vertices
        .iter()
        .map(|&p| [dot(p, u), dot(p, v), dot(p, w)])
        .collect();
    let (lo_u, hi_u) = extent_along(&whole.vertices, u);
    let (lo_v, hi_v) = extent_along(&whole.vertices, v);
    let (lo_w, hi_w) = extent_along(&whole.vertices, w);
    let cells = resolution.clamp(2, MAX_RESOLUTION);
    let size = (hi_u - lo_u).max(hi_v - lo_v).max(f64::MIN_POSITIVE) / (cells - 1) as f64;
    let cell_of = |x: f64, lo: f64| (((x - lo) / size).round().max(0.0) as usize).min(cells - 1);
    let mut depth = vec![f64::NEG_INFINITY; cells * cells];
    for t in &whole.triangles {
        let [a, b, c] = t.map(|k| image[k as usize]);
        let (u0, u1) = (a[0].min(b[0]).min(c[0]), a[0].max(b[0]).max(c[0]));
        let (v0, v1) = (a[1].min(b[1]).min(c[1]), a[1].max(b[1]).max(c[1]));
        let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        if det.abs() < 1e-300 {
            continue;
        }
        for i in cell_of(u0, lo_u)..=cell_of(u1, lo_u) {
            for j in cell_of(v0, lo_v)..=cell_of(v1, lo_v) {
                let (x, y) = (lo_u + i as f64 * size, lo_v + j as f64 * size);
                let s = ((x - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (y - a[1])) / det;
                let r = ((b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1])) / det;
                if s >= 0.0 && r >= 0.0 && s + r <= 1.0 {
                    let z = a[2] + s * (b[2] - a[2]) + r * (c[2] - a[2]);
                    let cell = &mut depth[i * cells + j];
                    *cell = cell.max(z);
                }
            }
        }
    }
    // A corner is seen when no surface in its cell or the cells around it is nearer by
    // more than a cell and a hundredth of the depth range.
    let slack = size + 0.01 * (hi_w - lo_w);
    let seen: Vec<bool> = image
        .iter()
        .map(|p| {
            let (i, j) = (cell_of(p[0], lo_u), cell_of(p[1], lo_v));
            let nearest = (i.saturating_sub(1)..=(i + 1).min(cells - 1))
                .flat_map(|a| (j.saturating_sub(1)..=(j + 1).min(cells - 1)).map(move |b| (a, b)))
                .map(|(a, b)| depth[a * cells + b])
                .filter(|d| d.is_finite())
                .fold(f64::INFINITY, f64::min);
            !nearest.is_finite() || p[2] >= nearest - slack
        })
        .collect();
    keep_triangles(whole, |t| {
        let [a, b, c] = t.map(|k| whole.vertices[k as usize]);
        let facing = dot(cross(sub(b, a), sub(c, a)), w) > 0.0;
        facing && t.iter().all(|&k| seen[k as usize])
    })
}

fn extent_along(points: &[[f64; 3]], axis: [f64; 3]) -> (f64, f64) {
    points
        .iter()
        .map(|&p| dot(p, axis))
        .fold((f64::MAX, f64::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::{figure, FigureKind, FigureSpec};

    fn humanoid() -> FigureMesh {
        figure(&FigureSpec {
            kind: FigureKind::Humanoid,
            target_vertices: 3_000,
            ..Default::default()
        })
        .unwrap()
    }

    /// Every part vertex sits where its whole vertex does, and the part's faces are the
    /// whole's faces renumbered.
    fn assert_exact_truth(whole: &FigureMesh, part: &Part) {
        assert_eq!(part.mesh.vertices.len(), part.whole_vertex.len());
        for (i, &w) in part.whole_vertex.iter().enumerate() {
            assert_eq!(part.mesh.vertices[i], whole.vertices[w as usize]);
        }
        let whole_faces: std::collections::HashSet<[u32; 3]> =
            whole.triangles.iter().copied().collect();
        for t in &part.mesh.triangles {
            assert!(whole_faces.contains(&t.map(|k| part.whole_vertex[k as usize])));
        }
    }

    #[test]
    fn a_cut_below_keeps_the_upper_faces_with_exact_truth() {
        let whole = humanoid();
        let part = cut_below(&whole, 1.0 / 3.0);
        assert_exact_truth(&whole, &part);
        let (lo, hi) = extent_along(&whole.vertices, [0.0, 1.0, 0.0]);
        let level = lo + (hi - lo) / 3.0;
        assert!(part.mesh.vertices.iter().all(|p| p[1] >= level));
        let share = part.mesh.area() / whole.area();
        assert!((0.5..0.9).contains(&share), "area kept {share}");
    }

    #[test]
    fn an_extremity_cut_and_holes_remove_some_of_the_area() {
        let whole = humanoid();
        let limb = cut_extremity(&whole, 0.3);
        assert_exact_truth(&whole, &limb);
        let share = limb.mesh.area() / whole.area();
        assert!((0.6..0.99).contains(&share), "area kept {share}");
        let holes = with_holes(&whole, 4, 0.05, 7);
        assert_exact_truth(&whole, &holes);
        let share = holes.mesh.area() / whole.area();
        assert!((0.7..0.99).contains(&share), "area kept {share}");
        assert_eq!(
            with_holes(&whole, 4, 0.05, 7).whole_vertex,
            holes.whole_vertex
        );
    }

    #[test]
    fn one_view_sees_the_side_turned_to_it_and_not_what_is_behind() {
        let whole = humanoid();
        let front = seen_from(&whole, [0.0, 0.0, 1.0], 256);
        assert_exact_truth(&whole, &front);
        let share = front.mesh.area() / whole.area();
        assert!((0.3..0.6).contains(&share), "area seen {share}");
        // The figure faces +z: what the camera in front sees lies in front.
        let mean_z =
            |m: &FigureMesh| m.vertices.iter().map(|p| p[2]).sum::<f64>() / m.vertices.len() as f64;
        let back = seen_from(&whole, [0.0, 0.0, -1.0], 256);
        assert!(mean_z(&front.mesh) > mean_z(&whole) && mean_z(&back.mesh) < mean_z(&whole));
        // From the side, the near arm and leg hide part of the far ones: fewer faces are
        // seen than are turned towards the camera.
        let side = [1.0, 0.0, 0.0];
        let seen = seen_from(&whole, side, 256).mesh.area();
        let turned = keep_triangles(&whole, |t| {
            let [a, b, c] = t.map(|k| whole.vertices[k as usize]);
            dot(cross(sub(b, a), sub(c, a)), side) > 0.0
        })
        .mesh
        .area();
        assert!(seen < 0.9 * turned, "seen {seen}, turned {turned}");
    }
}
